#!/usr/bin/env bash
# What the PyMeshLab build needs (idempotent; after .ci/setup-debian.sh):
#  - MeshLab 2025.07's sources (headers and the matching vcglib), from Debian's source package of
#    MeshLab 2025.07 (in Debian's development suite, 'sid'), into build/deps2025/meshlab-2025.07.
#    apt runs with a private list and state folder under build/deps2025/apt: the machine's own apt
#    configuration is not changed. The entry is derived from the machine's own apt sources (same
#    URI and keyring as its Debian entry, suite 'sid'); no host name is written anywhere.
#  - a virtual environment build/venv-pymeshlab with pymeshlab==2025.7.post1 from PyPI, and
#    PyQt5-Qt5==5.15.2 for its Qt platform plugins (OpenGL under xvfb-run: docs/pymeshlab.md#opengl).
# Nothing of MeshLab, vcglib or the wheel is ever committed: all of it lives in the ignored build tree.
# Exit status 0 when both are in place, 2 (with the reason on stderr) when one cannot be had
# (no network, no Debian source URI): callers then skip the PyMeshLab tests.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
DEPS="$ROOT/build/deps2025"
SRC="$DEPS/meshlab-2025.07"
VENV="$ROOT/build/venv-pymeshlab"
PYMESHLAB_VERSION=2025.7.post1
# Qt's platform plugins of the wheel's Qt (5.15.2), for OpenGL under a display or xvfb-run: the wheel
# carries none, and Debian's (5.15.8) are refused by an older Qt.
QT_PLATFORM_VERSION=5.15.2
MESHLAB_ORIG=meshlab_2025.07~dfsg.orig.tar.xz

# The URI and keyring of this machine's Debian archive entry (deb822 or one-line), "URI KEYRING".
debian_archive_entry() {
  local codename f
  codename=$(. /etc/os-release && echo "${VERSION_CODENAME:-}")
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] || continue
    awk -v cn="$codename" 'BEGIN { RS = "" } {
        uri = ""; key = ""; keep = 0; n = split($0, L, "\n")
        for (i = 1; i <= n; i++) {
          if (L[i] ~ /^Types:/ && L[i] !~ /[ \t]deb([ \t]|$)/) next
          if (L[i] ~ /^URIs:/) { split(L[i], W, /[ \t]+/); uri = W[2] }
          if (L[i] ~ /^Signed-By:/) { split(L[i], W, /[ \t]+/); key = W[2] }
          if (L[i] ~ /^Suites:/) { m = split(L[i], W, /[ \t]+/); for (j = 2; j <= m; j++) if (W[j] == cn) keep = 1 }
        }
        if (keep && uri != "") { print uri, key; exit }
      }' "$f"
  done | head -n1
  for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
    [ -f "$f" ] || continue
    awk -v cn="$codename" '$1 == "deb" {
        key = ""; i = 2
        if ($2 ~ /^\[/) { for (; i <= NF; i++) { if ($i ~ /signed-by=/) { key = $i; sub(/.*signed-by=/, "", key); sub(/\]$/, "", key) } if ($i ~ /\]$/) break } i++ }
        if ($(i + 1) == cn) { print $i, key; exit }
      }' "$f"
  done | head -n1
}

fetch_meshlab_sources() {
  [ -f "$SRC/src/common/plugins/interfaces/filter_plugin.h" ] && [ -f "$SRC/src/vcglib/vcg/complex/complex.h" ] && return 0
  local entry uri key apt_dir opts
  entry=$(debian_archive_entry | head -n1)
  uri=${entry%% *}; key=${entry#* }
  if [ -z "$uri" ]; then
    echo "setup-pymeshlab: no Debian archive entry in this machine's apt sources to fetch MeshLab 2025.07's source package from." >&2
    return 2
  fi
  apt_dir="$DEPS/apt"
  mkdir -p "$apt_dir/lists/partial" "$apt_dir/archives/partial"
  printf 'deb-src %s %s sid main\n' "${key:+[signed-by=$key]}" "$uri" > "$apt_dir/sources.list"
  opts=(-o Dir::Etc::sourcelist="$apt_dir/sources.list" -o Dir::Etc::sourceparts=/nonexistent
        -o Dir::State::Lists="$apt_dir/lists" -o Dir::Cache::archives="$apt_dir/archives" -o APT::Sandbox::User=root)
  echo "setup-pymeshlab: fetching MeshLab 2025.07's Debian source package into $DEPS"
  if ! apt-get "${opts[@]}" update -qq >/dev/null 2>&1; then
    echo "setup-pymeshlab: cannot read the Debian source index (no network?)." >&2
    return 2
  fi
  # Only the upstream tarball (headers and vcglib); apt checks it against the signed index.
  (cd "$DEPS" && apt-get "${opts[@]}" source -qq --download-only --tar-only meshlab) >/dev/null 2>&1 || true
  if [ ! -f "$DEPS/$MESHLAB_ORIG" ]; then
    echo "setup-pymeshlab: $MESHLAB_ORIG not offered by the Debian archive (its MeshLab is no longer 2025.07?)." >&2
    return 2
  fi
  rm -rf "$SRC" "$DEPS/unpack" && mkdir -p "$DEPS/unpack"
  tar -xJf "$DEPS/$MESHLAB_ORIG" -C "$DEPS/unpack"
  mv "$DEPS"/unpack/meshlab-* "$SRC" && rmdir "$DEPS/unpack"
  rm -f "$DEPS/$MESHLAB_ORIG"
  grep -qx '2025.07' "$SRC/ML_VERSION" || { echo "setup-pymeshlab: $SRC is not MeshLab 2025.07" >&2; return 2; }
}

make_venv() {
  if [ -x "$VENV/bin/python" ] && "$VENV/bin/python" -c "import importlib.metadata as m; assert m.version('pymeshlab') == '$PYMESHLAB_VERSION' and m.version('PyQt5-Qt5') == '$QT_PLATFORM_VERSION'" 2>/dev/null; then
    return 0
  fi
  local python
  python=$(command -v python3)
  "$python" -m venv "$VENV" || { echo "setup-pymeshlab: '$python -m venv' failed (Debian: apt-get install python3-venv)." >&2; return 2; }
  if ! "$VENV/bin/pip" install -q --disable-pip-version-check --retries 2 --timeout 30 "pymeshlab==$PYMESHLAB_VERSION" numpy \
       "PyQt5-Qt5==$QT_PLATFORM_VERSION"; then
    echo "setup-pymeshlab: cannot install pymeshlab==$PYMESHLAB_VERSION from PyPI (no network?)." >&2
    return 2
  fi
}

rc=0
fetch_meshlab_sources || rc=$?
[ $rc = 0 ] && { make_venv || rc=$?; }
[ $rc = 0 ] && echo "setup-pymeshlab: ok (MeshLab 2025.07 sources in $SRC, pymeshlab $PYMESHLAB_VERSION in $VENV)"
exit $rc
