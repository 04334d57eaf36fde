#!/bin/sh
# Whole-surface relighting evaluation against per-pixel RTI baselines.
# For each scene of <shared>/scenes: fit the training project (16-bit linear photos, colour
# correction off) with vbrdf_fit, then score the result on the held-out photos with vbrdf_eval
# over the ground-truth-visible vertices, beside PTM and Relight-style RBF fitted per pixel on the
# same training photos and scored on the same samples.
#   tests/benchmark/whole_surface_eval.sh [BUILD_DIR] [WORK_DIR] [EXTRA vbrdf_eval OPTIONS...]
#     BUILD_DIR  default build/release (holding tests/benchmark/vbrdf_fit and vbrdf_eval)
#     WORK_DIR   default $BUILD_DIR/whole_surface_eval (fit results and logs)
#   environment: VBRDF_SHARED_DIR (default <repo>/../shared; VBRDF_SHARED is also read), SCENES (default the three below),
#                VBRDF_FIT_OPTIONS (extra vbrdf_fit options, e.g. "--visibility cpu"),
#                LIGHT_POSITIONS (default on: a scene with lights_world.json, i.e. point lights, is fitted and
#                scored with those positions; off: with the directions of its lights.lp, as an RTI user would)
#   e.g. extra options "--below-baselines" make a scene fail unless the product beats both baselines.
# Skips (exit 0, with a message) when the shared scenes are absent (a plain clone has none).
# Exit status: 0 all scenes ran (and met any bound given), 1 a scene failed.
set -u
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$repo/build/release}
work=${2:-$build/whole_surface_eval}
[ $# -ge 2 ] && shift 2 || shift $#
shared=${VBRDF_SHARED_DIR:-${VBRDF_SHARED:-$repo/../shared}}
scenes=${SCENES:-"spot_dir24 bunny_two_materials_dir32 teapot_dir16 teapot_point16"}
fit=$build/tests/benchmark/vbrdf_fit
eval_tool=$build/tests/benchmark/vbrdf_eval

if [ ! -d "$shared/scenes" ]; then
  echo "SKIP: $shared/scenes not found (set VBRDF_SHARED_DIR to the folder holding scenes/)"
  exit 0
fi
for t in "$fit" "$eval_tool"; do
  [ -x "$t" ] || { echo "error: $t not built (ninja -C $build vbrdf_fit vbrdf_eval)"; exit 2; }
done
mkdir -p "$work"
status=0
for scene in $scenes; do
  s=$shared/scenes/$scene
  if [ ! -f "$s/project.mlp" ]; then
    echo "SKIP: $scene (no $s/project.mlp)"
    continue
  fi
  out=$work/$scene
  mkdir -p "$out"
  fit_lights=""
  eval_lights=""
  # A lights_world.json of directional lights ("type": "directional") is the .lp's twin: the .lp is used.
  if [ -f "$s/lights_world.json" ] && [ "${LIGHT_POSITIONS:-on}" != off ] &&
     ! grep -q '"type": *"directional"' "$s/lights_world.json"; then
    fit_lights="--lp $s/lights_world.json"
    eval_lights="--lp $s/heldout/lights_world.json --training-lp $s/lights_world.json"
    echo "== $scene (point lights at the positions of lights_world.json)"
  else
    echo "== $scene"
  fi
  # shellcheck disable=SC2086
  if ! "$fit" "$s/project.mlp" --photo-dir "$s/linear" --color-correction off --out "$out/fit.ply" $fit_lights \
       ${VBRDF_FIT_OPTIONS:-} > "$out/fit.log" 2>&1; then
    echo "FAIL: vbrdf_fit on $scene (see $out/fit.log)"
    status=1
    continue
  fi
  # Ground-truth lit flags (gt_vertex.npz heldout_lit) as the text file vbrdf_eval --gt-lit reads;
  # without numpy the evaluation falls back to our own shadow passes (and says so).
  lit_opt=""
  if /usr/bin/python3 - "$s/gt_vertex.npz" "$out/gt_lit.txt" <<'PY' 2>/dev/null; then lit_opt="--gt-lit $out/gt_lit.txt"; fi
import sys
import numpy as np
lit = np.load(sys.argv[1])["heldout_lit"].astype(bool)
with open(sys.argv[2], "w") as f:
    f.write(f"{lit.shape[0]} {lit.shape[1]}\n")
    for row in lit:
        f.write("".join("1" if b else "0" for b in row) + "\n")
PY
  # shellcheck disable=SC2086
  "$eval_tool" --result "$out/fit.ply" --project "$s/heldout/project.mlp" --photo-dir "$s/heldout/linear" \
      --training "$s/project.mlp" --training-photo-dir "$s/linear" --gt-visible "$s/gt_vertex.ply" $lit_opt $eval_lights "$@" \
      > "$out/eval.log" 2>&1
  rc=$?
  cat "$out/eval.log"
  if [ $rc -ne 0 ]; then
    echo "FAIL: vbrdf_eval on $scene (exit $rc)"
    status=1
  fi
done
exit $status
