#!/bin/sh
# Fitted on one camera, scored on another: the spot pair of <shared>/scenes
# (spot_dir24 and spot_dir24_view2: one mesh and vertex order, two cameras 45 degrees apart, each
# with its own training and held-out photos). Each camera's project is fitted alone (16-bit linear
# photos, colour correction off, the .lp's directions); every fit is then scored at each camera's
# held-out photos with vbrdf_eval (RBF/PTM of the scored camera's own training photos beside it;
# RTI cannot use another camera's photos at all). "both": one project holding every camera's
# training photos (tests/tools/merge_projects.py), fitted once and scored at each camera,
#   (a) over the ground-truth-visible vertices of the scored camera ("all"), and
#   (b) over those that every fit models ("common": fit_status != 0 in each), so that every fit is
#       scored on the same vertices.
#   tests/benchmark/cross_camera_eval.sh [BUILD_DIR] [WORK_DIR] [EXTRA vbrdf_fit OPTIONS...]
#   environment: VBRDF_SHARED_DIR (default <repo>/../shared), CAMERAS (default "spot_dir24 spot_dir24_view2"),
#   SETS (default "all common": the vertex sets scored), VBRDF_EVAL_OPTIONS (extra vbrdf_eval options,
#   e.g. "--footprint off" for fits made with --footprint off),
#   CHECK_TOLERANCE (e.g. 0.05): only the "common" rows of each camera's own fit and of "both" at
#   that camera are scored, and the script fails (exit 1) when "both" is worse than the camera's
#   own fit by more than that fraction (whole-surface mean): adding a camera's photos must not
#   raise the error at another camera (ctest two_cameras_add_up).
# Prints one line per (fit, scored camera, vertex set): whole-surface and clean-pixel mean / p95.
# Skips (exit 0) when the scenes are absent; needs /usr/bin/python3 with numpy for (b) and the lit flags.
set -u
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$repo/build/release}
work=${2:-$build/cross_camera_eval}
[ $# -ge 2 ] && shift 2 || shift $#
shared=${VBRDF_SHARED_DIR:-$repo/../shared}
cameras=${CAMERAS:-"spot_dir24 spot_dir24_view2"}
fit=$build/tests/benchmark/vbrdf_fit
eval_tool=$build/tests/benchmark/vbrdf_eval
for c in $cameras; do
  [ -f "$shared/scenes/$c/project.mlp" ] || { echo "SKIP: $shared/scenes/$c not found"; exit 0; }
done
mkdir -p "$work"
rm -f "$work/common_means.txt"
for c in $cameras; do
  s=$shared/scenes/$c
  mkdir -p "$work/$c"
  "$fit" "$s/project.mlp" --photo-dir "$s/linear" --color-correction off --lp "$s/lights.lp" --out "$work/$c/fit.ply" "$@" \
      > "$work/$c/fit.log" 2>&1 || { echo "FAIL: vbrdf_fit on $c (see $work/$c/fit.log)"; exit 1; }
  /usr/bin/python3 - "$s/gt_vertex.npz" "$work/$c/gt_lit.txt" <<'PY'
import sys
import numpy as np
lit = np.load(sys.argv[1])["heldout_lit"].astype(bool)
with open(sys.argv[2], "w") as f:
    f.write(f"{lit.shape[0]} {lit.shape[1]}\n")
    for row in lit:
        f.write("".join("1" if b else "0" for b in row) + "\n")
PY
done
# Every camera's photos in one project (photo names prefixed per camera), fitted once.
mkdir -p "$work/both"
projects=""
for c in $cameras; do projects="$projects $shared/scenes/$c/project.mlp"; done
/usr/bin/python3 "$repo/tests/tools/merge_projects.py" "$work/both/project" $projects > "$work/both/merge.log" 2>&1 ||
  { echo "FAIL: merge_projects (see $work/both/merge.log)"; exit 1; }
"$fit" "$work/both/project/project.mlp" --photo-dir "$work/both/project/linear" --color-correction off \
    --lp "$work/both/project/lights.lp" --out "$work/both/fit.ply" "$@" > "$work/both/fit.log" 2>&1 ||
  { echo "FAIL: vbrdf_fit on both (see $work/both/fit.log)"; exit 1; }
# gt_vertex.ply of each scored camera with `visible` restricted to vertices every fit models.
/usr/bin/python3 - "$work" "$shared/scenes" $cameras <<'PY'
import sys
import numpy as np
sys.path.insert(0, sys.argv[0])
work, scenes, cams = sys.argv[1], sys.argv[2], sys.argv[3:]
TYPES = {'float': '<f4', 'uchar': 'u1', 'int': '<i4', 'double': '<f8'}
def split(path):
    data = open(path, 'rb').read()
    end = data.index(b'end_header\n') + len(b'end_header\n')
    props, count, inv = [], 0, False
    for line in data[:end].decode('ascii').splitlines():
        t = line.split()
        if t and t[0] == 'element':
            inv = t[1] == 'vertex'
            if inv: count = int(t[2])
        elif t and t[0] == 'property' and inv:
            props.append((t[2], TYPES[t[1]]))
    dt = np.dtype(props)
    v = np.frombuffer(data, dt, count, end).copy()
    return data[:end], v, data[end + dt.itemsize * count:]
modelled = None
for c in cams + ["both"]:
    _, v, _ = split(f"{work}/{c}/fit.ply")
    m = v['fit_status'] != 0
    modelled = m if modelled is None else modelled & m
for c in cams:
    head, v, rest = split(f"{scenes}/{c}/gt_vertex.ply")
    v['visible'] = (v['visible'] != 0) & modelled
    open(f"{work}/{c}/gt_common.ply", 'wb').write(head + v.tobytes() + rest)
PY
check=${CHECK_TOLERANCE:-}
sets=${SETS:-"all common"}
[ -n "$check" ] && sets=common
status=0
for f in $cameras both; do
  for c in $cameras; do
    [ -n "$check" ] && [ "$f" != both ] && [ "$f" != "$c" ] && continue
    s=$shared/scenes/$c
    for set in $sets; do
      gt=$s/gt_vertex.ply
      [ $set = common ] && gt=$work/$c/gt_common.ply
      log=$work/eval_${f}_at_${c}_$set.log
      "$eval_tool" --result "$work/$f/fit.ply" --project "$s/heldout/project.mlp" --photo-dir "$s/heldout/linear" \
          --training "$s/project.mlp" --training-photo-dir "$s/linear" --gt-visible "$gt" --gt-lit "$work/$c/gt_lit.txt" \
          ${VBRDF_EVAL_OPTIONS:-} > "$log" 2>&1
      whole=$(grep "whole surface: product" "$log" | awk '{print $(NF-2) " / " $NF}')
      clean=$(grep "clean pixels, modelled vertices only" "$log" | awk '{print $(NF-2) " / " $NF}')
      rbf=$(grep "same samples: RBF" "$log" | awk '{print $(NF-2) " / " $NF}')
      echo "fit $f scored at $c ($set): whole $whole; clean pixels of modelled vertices $clean; RBF of $c $rbf"
      [ -z "$whole" ] && { echo "FAIL: no whole-surface figure in $log"; status=1; }
      [ "$set" = common ] && echo "$f $c ${whole%% *}" >> "$work/common_means.txt"
    done
  done
done
if [ -n "$check" ]; then
  for c in $cameras; do
    own=$(awk -v c="$c" '$1 == c && $2 == c {print $3}' "$work/common_means.txt" | tail -1)
    both=$(awk -v c="$c" '$1 == "both" && $2 == c {print $3}' "$work/common_means.txt" | tail -1)
    if awk -v o="$own" -v b="$both" -v t="$check" 'BEGIN {exit !(o != "" && b != "" && b <= o * (1 + t))}'; then
      echo "ok: at $c both cameras' fit $both, $c's own fit $own (tolerance $check)"
    else
      echo "FAIL: at $c both cameras' fit $both is worse than $c's own fit $own by more than $check"; status=1
    fi
  done
fi
exit $status
