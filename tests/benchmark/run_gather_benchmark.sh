#!/usr/bin/env bash
# Sample-gathering benchmark: 100k vertices x 32 photos at 1024x768, GL
# (llvmpipe) and CPU back ends, and how the time grows with photos and vertices.
# Usage: tests/benchmark/run_gather_benchmark.sh BUILD_DIR [OUT_CSV]
set -euo pipefail
BUILD=${1:?build dir}
OUT=${2:-$BUILD/benchmark/gather.csv}
WORK=$BUILD/benchmark/scenes
mkdir -p "$WORK" "$(dirname "$OUT")"
synth=$BUILD/tests/tools/synthesize_scene
bench=$BUILD/tests/benchmark/bench_gather
for v in 10000 30000 100000; do
  [ -f "$WORK/v$v/project.mlp" ] || "$synth" --out "$WORK/v$v" --vertices $v --width 1024 --height 768 --lights 32 --heldout 0 --ss 1 --quiet
done
"$bench" "$WORK/v100000/project.mlp" --backend both --photos 4,8,16,32 --csv-header | tee "$OUT"
for v in 10000 30000; do "$bench" "$WORK/v$v/project.mlp" --backend both --photos 32 | tee -a "$OUT"; done
# One camera pass (1024x768) and one light pass on 100k vertices.
"$bench" "$WORK/v100000/project.mlp" --backend both --passes --csv-header | tee "${OUT%.csv}_passes.csv"
