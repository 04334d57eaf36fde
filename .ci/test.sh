#!/usr/bin/env bash
# The README's second command: set up (idempotent), build, and run the whole test suite (ctest:
# unit tests in OSMesa, end-to-end tests through headless meshlabserver under xvfb-run).
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="${VBRDF_BUILD_DIR:-$ROOT/build/release}"
bash "$ROOT/.ci/setup-debian.sh" "$ROOT/build/deps"
cmake -S "$ROOT" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMESHLAB_SOURCE_DIR="$ROOT/build/deps/meshlab"
cmake --build "$BUILD" -j"$(nproc)"
cd "$BUILD"
ctest --output-on-failure -j"$(nproc)" "$@"
