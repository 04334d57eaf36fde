#!/usr/bin/env bash
# The README's first command: set up a fresh Debian 12 machine (as root), build, and run the main
# filter on the bundled sample project through headless meshlabserver (Debian's, loading the
# plugin just built). Leaves the result PLY and its report in build/quickstart/.
#   bash .ci/quickstart.sh [SAMPLE_PROJECT_DIR]     (default: sample_projects/synth_basic)
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="${VBRDF_BUILD_DIR:-$ROOT/build/release}"
SAMPLE="$(cd "${1:-$ROOT/sample_projects/synth_basic}" && pwd)"
OUT="$ROOT/build/quickstart"
NAME="$(basename "$SAMPLE")"
bash "$ROOT/.ci/setup-debian.sh" "$ROOT/build/deps"
cmake -S "$ROOT" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMESHLAB_SOURCE_DIR="$ROOT/build/deps/meshlab"
cmake --build "$BUILD" -j"$(nproc)"
mkdir -p "$OUT"
# The sample's script with the output redirected into build/quickstart (the sample stays untouched).
sed "s|name=\"outputPly\" type=\"RichSaveFile\" value=\"[^\"]*\"|name=\"outputPly\" type=\"RichSaveFile\" value=\"$OUT/${NAME}_brdf.ply\"|" \
  "$SAMPLE/fit.mlx" > "$OUT/fit.mlx"
"$BUILD/meshlab_run/run_meshlabserver.sh" -p "$SAMPLE/project.mlp" -s "$OUT/fit.mlx" > "$OUT/meshlabserver.log" 2>&1 \
  || { tail -40 "$OUT/meshlabserver.log"; echo "meshlabserver failed: see $OUT/meshlabserver.log" >&2; exit 1; }
grep "^Vertex BRDF: " "$OUT/meshlabserver.log" | grep -v "%)" || true
echo
cat "$OUT/${NAME}_brdf_report.txt"
echo
echo "Result: $OUT/${NAME}_brdf.ply (open it in MeshLab; per-vertex kd, ks, shininess, color_r/g/b, dq, sq, ...)"
