#!/usr/bin/env bash
# Idempotent set-up of a Debian 12 machine (as root) for building and testing filter_vertex_brdf.
#  - installs the build/test dependencies from Debian's packages (incl. Debian's own meshlab);
#  - adds a deb-src entry (if none) and fetches MeshLab 2020.09's source package, whose headers
#    (src/common, vcglib) the plugin builds against, into $1 (default: build/deps).
# Nothing of MeshLab or vcglib is ever committed: it lives in the (ignored) build tree.
set -euo pipefail
DEPS_DIR=${1:-"$(cd "$(dirname "$0")/.." && pwd)/build/deps"}
export DEBIAN_FRONTEND=noninteractive

PKGS=(build-essential cmake ninja-build pkg-config dpkg-dev
      qtbase5-dev libqt5opengl5-dev libqt5xmlpatterns5-dev
      libgl-dev libglu1-mesa-dev libglew-dev libeigen3-dev libglm-dev
      libopencv-dev libopencv-contrib-dev libosmesa6-dev
      googletest libgtest-dev xvfb xauth meshlab python3 python3-numpy)

missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

src_list=/etc/apt/sources.list.d/filter-vertex-brdf-src.sources
need_update=0
if ! grep -rqs '^Types:.*deb-src\|^deb-src ' /etc/apt/sources.list /etc/apt/sources.list.d/; then
  # Same URIs/suites as the binary entries, as deb-src.
  if [ -f /etc/apt/sources.list.d/debian.sources ]; then
    sed 's/^Types: deb$/Types: deb-src/' /etc/apt/sources.list.d/debian.sources > "$src_list"
  else
    echo "deb-src http://deb.debian.org/debian bookworm main" > /etc/apt/sources.list.d/filter-vertex-brdf-src.list
  fi
  need_update=1
fi
if [ ${#missing[@]} -gt 0 ] || [ $need_update = 1 ] || [ ! -d "$DEPS_DIR/meshlab" ]; then
  apt-get update -qq
fi
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

if [ ! -f "$DEPS_DIR/meshlab/src/common/interfaces.h" ]; then
  echo "setup: fetching MeshLab's Debian source package into $DEPS_DIR"
  rm -rf "$DEPS_DIR" && mkdir -p "$DEPS_DIR"
  (cd "$DEPS_DIR" && apt-get source -qq --download-only meshlab \
     && dpkg-source --no-check -x meshlab_*.dsc meshlab-src >/dev/null)
  mv "$DEPS_DIR/meshlab-src" "$DEPS_DIR/meshlab"
  rm -f "$DEPS_DIR"/meshlab_*
fi
test -f "$DEPS_DIR/meshlab/src/common/interfaces.h" || { echo "setup: MeshLab headers missing in $DEPS_DIR/meshlab" >&2; exit 1; }
test -f "$DEPS_DIR/meshlab/vcglib/vcg/complex/complex.h" || { echo "setup: vcglib missing in $DEPS_DIR/meshlab/vcglib" >&2; exit 1; }
echo "setup: ok (MeshLab headers in $DEPS_DIR/meshlab)"
