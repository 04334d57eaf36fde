#!/bin/sh
# Fitted on one camera, scored on another (issue 16): the spot pair of <shared>/scenes
# (spot_dir24 and spot_dir24_view2: one mesh and vertex order, two cameras 45 degrees apart, each
# with its own training and held-out photos). Each camera's project is fitted alone (16-bit linear
# photos, colour correction off, the .lp's directions); every fit is then scored at each camera's
# held-out photos with vbrdf_eval (RBF/PTM of the scored camera's own training photos beside it),
#   (a) over the ground-truth-visible vertices of the scored camera ("all"), and
#   (b) over those that both fits model ("common": fit_status != 0 in both), the issue's protocol.
#   tests/benchmark/cross_camera_eval.sh [BUILD_DIR] [WORK_DIR] [EXTRA vbrdf_fit OPTIONS...]
#   environment: VBRDF_SHARED_DIR (default <repo>/../shared), CAMERAS (default "spot_dir24 spot_dir24_view2")
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
for c in cams:
    _, v, _ = split(f"{work}/{c}/fit.ply")
    m = v['fit_status'] != 0
    modelled = m if modelled is None else modelled & m
for c in cams:
    head, v, rest = split(f"{scenes}/{c}/gt_vertex.ply")
    v['visible'] = (v['visible'] != 0) & modelled
    open(f"{work}/{c}/gt_common.ply", 'wb').write(head + v.tobytes() + rest)
PY
for f in $cameras; do
  for c in $cameras; do
    s=$shared/scenes/$c
    for set in all common; do
      gt=$s/gt_vertex.ply
      [ $set = common ] && gt=$work/$c/gt_common.ply
      log=$work/eval_${f}_at_${c}_$set.log
      "$eval_tool" --result "$work/$f/fit.ply" --project "$s/heldout/project.mlp" --photo-dir "$s/heldout/linear" \
          --training "$s/project.mlp" --training-photo-dir "$s/linear" --gt-visible "$gt" --gt-lit "$work/$c/gt_lit.txt" \
          > "$log" 2>&1
      whole=$(grep "whole surface: product" "$log" | awk '{print $(NF-2) " / " $NF}')
      clean=$(grep "clean pixels, modelled vertices only" "$log" | awk '{print $(NF-2) " / " $NF}')
      rbf=$(grep "same samples: RBF" "$log" | awk '{print $(NF-2) " / " $NF}')
      echo "fit $f scored at $c ($set): whole $whole; clean pixels of modelled vertices $clean; RBF of $c $rbf"
    done
  done
done
