#!/usr/bin/env bash
# Regenerates sample_projects/synth_* with the built synthesizer (deterministic: the same bytes on
# every run) and copies the public-domain part of the shared Mitsuba scene spot_dir24.
#
#   tests/tools/make_sample_projects.sh [path/to/synthesize_scene]
#
# Default synthesizer: the newest build/*/tests/tools/synthesize_scene. Only generated files are
# replaced: other files in a project folder (e.g. fit.mlx) stay, and keys added by hand to
# expected.txt are kept (the generated keys are rewritten). Each project is then verified with
# synth_selfcheck when it was built beside the synthesizer.
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/../.." && pwd)
OUT="$ROOT/sample_projects"
SHARED=${VBRDF_SHARED_DIR:-"$ROOT/../shared"}
SYNTH=${1:-}
if [ -z "$SYNTH" ]; then  # the most recently built one
  SYNTH=$(ls -t "$ROOT"/build/*/tests/tools/synthesize_scene 2>/dev/null | head -n 1 || true)
fi
[ -n "$SYNTH" ] && [ -x "$SYNTH" ] || { echo "synthesize_scene not found: build it or pass its path" >&2; exit 1; }
CHECK="$(dirname "$SYNTH")/synth_selfcheck"
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

# Keeps the lines of OLD whose key the generator does not write (hand-added figures).
merge_expected() {  # NEW OLD > merged
  awk 'NR == FNR { print; seen[$0] = 1
                   if ($0 !~ /^#/ && index($0, ":")) gen[substr($0, 1, index($0, ":") - 1)] = 1
                   next }
       seen[$0] { next }
       $0 !~ /^#/ && index($0, ":") && (substr($0, 1, index($0, ":") - 1) in gen) { next }
       { print }' "$1" "$2"
}

generate() {  # NAME SYNTH_ARGS...
  local name=$1; shift
  local start=$SECONDS dest="$OUT/$name" new="$TMP/$name"
  "$SYNTH" --quiet --out "$new" "$@"
  mkdir -p "$dest"
  rm -rf "$dest/images" "$dest/heldout" "$dest/ground_truth" "$dest/project.mlp" "$dest/mesh.ply" \
         "$dest/lights.lp" "$dest/lights.json" "$dest/lights_world.json" "$dest/README.md"
  if [ -f "$dest/expected.txt" ]; then
    merge_expected "$new/expected.txt" "$dest/expected.txt" > "$TMP/expected.txt"
    mv "$TMP/expected.txt" "$new/expected.txt"
  fi
  cp -r "$new/." "$dest/"
  if [ -x "$CHECK" ]; then "$CHECK" "$dest" > "$TMP/check.log" || { cat "$TMP/check.log" >&2; exit 1; }; fi
  echo "$name: $(grep -E '^(vertices|photos|heldout_photos):' "$dest/expected.txt" | tr '\n' ' ')" \
       "$(du -sh "$dest" | cut -f1), $((SECONDS - start)) s"
}

copy_spot() {
  local src="$SHARED/scenes/spot_dir24" dest="$OUT/spot_dir24"
  [ -d "$src" ] || { echo "spot_dir24: $src not found, skipped" >&2; return; }
  rm -rf "$dest"
  mkdir -p "$dest/heldout"
  # Only what the plugin and the tests read: no exr/, linear/, gt_vertex.npz (size).
  cp "$src"/{project.mlp,mesh.ply,lights.lp,gt_vertex.ply,README.md,gt_scene.json} "$dest/"
  cp -r "$src/images" "$dest/"
  cp -r "$src/heldout/images" "$dest/heldout/"
  cp "$src"/heldout/{lights.lp,project.mlp,lights_world.json} "$dest/heldout/"
  chmod -R u+w "$dest"
  cat > "$dest/LICENSE.md" <<'EOF'
# spot_dir24: provenance and licence

* Model: "Spot" the cow by Keenan Crane, public domain (Keenan Crane's 3D model repository,
  https://www.cs.cmu.edu/~kmcrane/Projects/ModelRepository/).
* Photos and ground truth: rendered with Mitsuba 3 for this project's shared test scenes
  (`shared/scenes/spot_dir24`, marked public domain there: the one shared scene that may be
  copied into the repository).
* This folder is a subset of the shared scene, copied by `tests/tools/make_sample_projects.sh`:
  `project.mlp`, `mesh.ply`, `images/`, `lights.lp`, `gt_vertex.ply`, `gt_scene.json`,
  `README.md` and `heldout/` (`images/`, `lights.lp`, `project.mlp`, `lights_world.json`).
  Left out for size: `exr/`, `linear/`, `heldout/exr/`, `heldout/linear/`, `gt_vertex.npz`,
  `lights_world.json`, `config.json` (README.md still describes them).
EOF
  echo "spot_dir24: copied, $(du -sh "$dest" | cut -f1)"
}

start=$SECONDS
mkdir -p "$OUT"
generate synth_basic --size small --lights 16 --heldout 4
generate synth_two_views --size small --views 2 --lights 8 --heldout 2
generate synth_linear16 --size small --lights 8 --heldout 2 --linear16 --width 480 --height 360
generate synth_near_lights --size small --lights 16 --heldout 4 --light-distance 3
copy_spot
echo "sample_projects: $(du -sh "$OUT" | cut -f1) in total, $((SECONDS - start)) s"
