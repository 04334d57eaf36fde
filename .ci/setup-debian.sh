#!/usr/bin/env bash
# Idempotent set-up of a Debian 12 machine (as root) for building and testing filter_vertex_brdf.
#  - installs the build/test dependencies from Debian's packages (incl. Debian's own meshlab);
#  - adds a deb-src entry (if none), derived from the machine's own apt sources, and fetches MeshLab 2020.09's source package, whose headers
#    (src/common, vcglib) the plugin builds against, into $1 (default: build/deps).
# Nothing of MeshLab or vcglib is ever committed: it lives in the (ignored) build tree.
set -euo pipefail
DEPS_DIR=${1:-"$(cd "$(dirname "$0")/.." && pwd)/build/deps"}
export DEBIAN_FRONTEND=noninteractive

PKGS=(build-essential cmake ninja-build pkg-config dpkg-dev
      qtbase5-dev libqt5opengl5-dev libqt5xmlpatterns5-dev
      libgl-dev libglu1-mesa-dev libglew-dev libeigen3-dev libglm-dev
      libopencv-dev libopencv-contrib-dev libosmesa6-dev
      googletest libgtest-dev xvfb xauth meshlab python3 python3-numpy python3-venv
      libtinygltf-dev)

missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

# derive_deb_src APT_DIR CODENAME OUT_SOURCES OUT_LIST: deb-src entries made only from this
# machine's own binary entries (APT_DIR/sources.list, APT_DIR/sources.list.d/*.list and *.sources)
# whose suite is CODENAME or CODENAME-*: same URIs, suites, components and options, as deb-src.
# deb822 stanzas go to OUT_SOURCES, one-line entries to OUT_LIST (each written only when
# non-empty). No host name is ever written that the machine's sources do not already name.
# Returns 1 when no entry could be derived.
derive_deb_src() {
  local apt=$1 cn=$2 out_sources=$3 out_list=$4 f stanzas lines
  local -a sources=() lists=()
  for f in "$apt"/sources.list.d/*.sources; do
    [ -f "$f" ] && [ "$f" != "$out_sources" ] && sources+=("$f")
  done
  for f in "$apt"/sources.list "$apt"/sources.list.d/*.list; do
    [ -f "$f" ] && [ "$f" != "$out_list" ] && lists+=("$f")
  done
  stanzas=""
  if [ ${#sources[@]} -gt 0 ]; then
    stanzas=$(awk -v cn="$cn" '
      BEGIN { RS = "" }
      {
        n = split($0, L, "\n"); keep = 0
        for (i = 1; i <= n; i++) if (L[i] ~ /^Suites:/) {
          s = L[i]; sub(/^Suites:/, "", s); m = split(s, W, /[ \t]+/)
          for (j = 1; j <= m; j++) if (W[j] == cn || index(W[j], cn "-") == 1) keep = 1
        }
        if (!keep) next
        for (i = 1; i <= n; i++) print (L[i] ~ /^Types:/ ? "Types: deb-src" : L[i])
        print ""
      }' "${sources[@]}")
  fi
  lines=""
  if [ ${#lists[@]} -gt 0 ]; then
    lines=$(awk -v cn="$cn" '
      $1 == "deb" {
        i = 2
        if ($2 ~ /^\[/) { while (i <= NF && $i !~ /\]$/) i++; i++ }
        suite = $(i + 1)
        if (suite == cn || index(suite, cn "-") == 1) { sub(/^[ \t]*deb[ \t]+/, "deb-src "); print }
      }' "${lists[@]}")
  fi
  [ -n "$stanzas" ] && printf '%s\n' "$stanzas" > "$out_sources"
  [ -n "$lines" ] && printf '%s\n' "$lines" > "$out_list"
  [ -n "$stanzas$lines" ]
}

need_update=0
if ! grep -qs '^Types:.*deb-src\|^deb-src ' /etc/apt/sources.list /etc/apt/sources.list.d/*.list \
     /etc/apt/sources.list.d/*.sources; then
  codename=$(. /etc/os-release && echo "${VERSION_CODENAME:-}")
  if [ -z "$codename" ] || ! derive_deb_src /etc/apt "$codename" \
       /etc/apt/sources.list.d/filter-vertex-brdf-src.sources /etc/apt/sources.list.d/filter-vertex-brdf-src.list; then
    echo "setup: no deb-src entry, and none can be derived from this machine's apt sources for" \
         "'${codename:-unknown release}'. Add a deb-src entry for your Debian mirror, then run again." >&2
    exit 1
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
