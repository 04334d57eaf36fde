#!/usr/bin/env bash
# The README's first command: set up a fresh Debian 12 machine (as root), build, and run the main
# filter on the bundled sample project through headless meshlabserver. Leaves the result PLY and
# its report in build/quickstart/.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="${VBRDF_BUILD_DIR:-$ROOT/build/release}"
SAMPLE="${1:-$ROOT/sample_projects/synth_basic}"
OUT="$ROOT/build/quickstart"
bash "$ROOT/.ci/setup-debian.sh" "$ROOT/build/deps"
cmake -S "$ROOT" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMESHLAB_SOURCE_DIR="$ROOT/build/deps/meshlab"
cmake --build "$BUILD" -j"$(nproc)"
mkdir -p "$OUT"
# The sample's script writes to the path given in VBRDF_OUTPUT (see tests/e2e/run_filter.sh).
bash "$BUILD/tests/e2e/run_filter.sh" "$SAMPLE/project.mlp" "$OUT/$(basename "$SAMPLE")_brdf.ply"
echo
echo "Result: $OUT/$(basename "$SAMPLE")_brdf.ply"
cat "$OUT/$(basename "$SAMPLE")_brdf_report.txt"
