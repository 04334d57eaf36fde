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
bash "$ROOT/.ci/setup-debian.sh" "$ROOT/build/deps"
cmake -S "$ROOT" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMESHLAB_SOURCE_DIR="$ROOT/build/deps/meshlab"
cmake --build "$BUILD" -j"$(nproc)"
bash "$ROOT/.ci/run_sample.sh" "$BUILD" "$SAMPLE" "$OUT"
