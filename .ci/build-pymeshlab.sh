#!/usr/bin/env bash
# Builds the plugin for PyMeshLab 2025.7.post1 (MeshLab 2025.07) into build/pymeshlab (after
# .ci/setup-debian.sh): fetches what it needs (.ci/setup-pymeshlab.sh), then configures with
# VBRDF_MESHLAB=2025.07 against the wheel's libraries. The 2020.09 build (build/release) is not
# touched. Exit status 2, with the reason, when the sources or the wheel cannot be had.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="${VBRDF_PYMESHLAB_BUILD_DIR:-$ROOT/build/pymeshlab}"
bash "$ROOT/.ci/setup-pymeshlab.sh"
site=$("$ROOT/build/venv-pymeshlab/bin/python" -c "import sysconfig; print(sysconfig.get_paths()['purelib'])")
cmake -S "$ROOT" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVBRDF_MESHLAB=2025.07 \
      -DMESHLAB_SOURCE_DIR="$ROOT/build/deps2025/meshlab-2025.07" -DPYMESHLAB_DIR="$site/pymeshlab" >/dev/null
cmake --build "$BUILD" -j"$(nproc)"
echo "build-pymeshlab: ok ($BUILD/filter_vertex_brdf/plugin/libfilter_vertex_brdf.so)"
