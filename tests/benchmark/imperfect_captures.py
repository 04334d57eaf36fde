#!/usr/bin/env python3
"""Relighting with the inputs a real capture gives: each shared scene fitted from a copy of its
project whose cameras are off (perturb_cameras.py: principal point shifted by 1 and 2 px, camera
turned 0.2 deg) or whose mesh normals are smoothed as a scan's are (vbrdf_perturb_mesh: 1-ring
averaging until they are 3.5 deg off in median) or decimated to half its vertices (vbrdf_perturb_mesh
--decimate 0.5: every vertex moved onto the decimated surface, its normal interpolated there), with the step that corrects it (registration
refinement, shading normals from the photos) off and on, and scored on the held-out photos with the
exact cameras over the whole visible surface (vbrdf_eval, the RTI protocol), beside per-pixel PTM and
RBF fitted on the same training photos (per pixel: no camera and no mesh, so neither error).

  imperfect_captures.py [--build build/release] [--work DIR] [--scenes spot_dir24 ...] [--csv FILE]
                        [--captures exact "shift 1 px" ...] [--max-ratio 1.10]

Prints one row per scene x capture x correction: relit CIEDE2000 mean / p95, PTM and RBF on the
same samples, the misregistration the fit measured (camera captures) or how far the normals moved
(median degrees), the fit's run time, and how far the input mesh's normals and the result's shading
normals are from the renderer's own (median / p95 degrees over the vertices the truth sees and the
fit models). The exact capture runs with both steps on (the product). The last capture has both
errors at once (normals smoothed and cameras shifted by 1 px), registration off and on.
Environment: VBRDF_FIT_OPTIONS, further vbrdf_fit options for every fit (e.g. "--deconvolve off").
--max-ratio: exit 1 unless every perturbed capture with one error and its correction on is within
that ratio of the exact capture's mean and p95 and below PTM and RBF in both, and the refined normals
of every smoothed mesh closer to the truth than the mesh's in median and p95. Skips (exit 0) without the shared
scenes.
"""
import argparse
import csv
import os
import re
import shlex
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
COMBINED = "smoothed, shift 1 px"
CAPTURES = [  # name, perturb_cameras.py arguments, vbrdf_perturb_mesh arguments, the step that corrects it
    ("exact", [], [], None),
    ("shift 1 px", ["--shift", "0.8", "-0.6"], [], "registration"),
    ("shift 2 px", ["--shift", "1.6", "1.2"], [], "registration"),
    ("yaw 0.2 deg", ["--rotate", "y", "0.2"], [], "registration"),
    ("roll 0.2 deg", ["--rotate", "z", "0.2"], [], "registration"),
    ("normals smoothed", [], ["--smooth-normals", "3", "--target-median", "3.5"], "shading-normals"),
    ("decimated half", [], ["--decimate", "0.5"], "shading-normals"),
    # A scan as it comes: smoother than the surface and registered a pixel off; shading normals on.
    # Reported beside the others, not held to --max-ratio (two errors at once: docs/benchmark.md).
    (COMBINED, ["--shift", "0.8", "-0.6"], ["--smooth-normals", "3", "--target-median", "3.5"],
     "registration"),
]
STEP_DEFAULTS = {"registration": "off", "shading-normals": "on"}  # the other step, as the product runs


def run(cmd, log):
    with open(log, "w") as f:
        t = time.time()
        rc = subprocess.call(cmd, stdout=f, stderr=subprocess.STDOUT)
        return rc, time.time() - t


GT_LIT = """
import sys
import numpy as np
lit = np.load(sys.argv[1])["heldout_lit"].astype(bool)
with open(sys.argv[2], "w") as f:
    f.write(f"{lit.shape[0]} {lit.shape[1]}\\n")
    for row in lit:
        f.write("".join("1" if b else "0" for b in row) + "\\n")
"""


def run_with_numpy(script, args):
    """Runs `script` with this interpreter or, failing that, Debian's (which has numpy); its standard
    output, or None when neither ran it."""
    for python in (sys.executable, "/usr/bin/python3"):
        p = subprocess.run([python, "-c", script] + args, capture_output=True, text=True)
        if p.returncode == 0:
            return p.stdout
    return None


def gt_lit(scene_dir, out):
    """The ground truth's held-out lit flags as vbrdf_eval --gt-lit reads them (as whole_surface_eval.sh
    does), with Debian's numpy; without it the evaluation uses its own shadow passes and says so."""
    return ["--gt-lit", out] if run_with_numpy(GT_LIT, [os.path.join(scene_dir, "gt_vertex.npz"), out]) is not None else []


NORMALS_VS_TRUTH = """
import sys
import numpy as np
sys.path.insert(0, sys.argv[4])
import e2e_lib
def unit(a):
    return a / np.maximum(np.linalg.norm(a, axis=1, keepdims=True), 1e-12)
fit = e2e_lib.read_ply(sys.argv[1]).vertex
mesh = e2e_lib.read_ply(sys.argv[2]).vertex
gt = np.load(sys.argv[3])
truth = unit(gt["normals"].astype(np.float64))
if len(fit) != len(truth) or len(mesh) != len(truth):
    sys.exit(0)
keep = gt["visible"].astype(bool) & (fit["fit_status"] != 0)
def angles(v):
    n = unit(np.stack([v["nx"], v["ny"], v["nz"]], axis=1).astype(np.float64))
    a = np.degrees(np.arccos(np.clip(np.sum(n * truth, axis=1), -1, 1)))[keep]
    return np.median(a), np.percentile(a, 95)
m, f = angles(mesh), angles(fit)
print(f"{m[0]:.2f} {m[1]:.2f} {f[0]:.2f} {f[1]:.2f}")
"""


def normals_vs_truth(result, mesh, scene_dir):
    """Median and p95 angle (degrees) of the input mesh's normals and of the result's shading normals
    from the renderer's own normals, over the vertices the ground truth sees and the fit models;
    None without numpy or without a vertex-for-vertex correspondence."""
    out = run_with_numpy(NORMALS_VS_TRUTH, [result, mesh, os.path.join(scene_dir, "gt_vertex.npz"),
                                            os.path.join(REPO, "tests", "e2e")])
    v = out.split() if out is not None else []
    return tuple(float(x) for x in v) if len(v) == 4 else None


def parse_eval(text):
    def row(label):
        m = re.search(re.escape(label) + r"\s+(\d+)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)", text)
        return (float(m.group(2)), float(m.group(4))) if m else (float("nan"), float("nan"))
    return {"product": row("whole surface: product"), "ptm": row("same samples: PTM (per pixel)"),
            "rbf": row("same samples: RBF (per pixel, Relight-style)")}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(REPO, "build", "release"))
    ap.add_argument("--work", default=None)
    ap.add_argument("--scenes", nargs="+", default=["spot_dir24", "bunny_two_materials_dir32", "teapot_dir16"])
    ap.add_argument("--captures", nargs="+", default=None, help="subset of: " + ", ".join(c[0] for c in CAPTURES))
    ap.add_argument("--csv", default=None)
    ap.add_argument("--max-ratio", type=float, default=None)
    args = ap.parse_args()
    shared = os.environ.get("VBRDF_SHARED_DIR", os.path.join(REPO, "..", "shared"))
    if not os.path.isdir(os.path.join(shared, "scenes")):
        print(f"SKIP: shared test data not found: {os.path.join(shared, 'scenes')}")
        return 0
    fit = os.path.join(args.build, "tests", "benchmark", "vbrdf_fit")
    ev = os.path.join(args.build, "tests", "benchmark", "vbrdf_eval")
    work = args.work or os.path.join(args.build, "imperfect_captures")
    os.makedirs(work, exist_ok=True)
    captures = [c for c in CAPTURES if not args.captures or c[0] in args.captures]
    extra_fit_options = shlex.split(os.environ.get("VBRDF_FIT_OPTIONS", ""))
    rows, failures = [], []
    print(f"{'scene':28} {'capture':16} {'correction':19} {'mean':>6} {'p95':>6}   {'PTM':>13} {'RBF':>13}  {'measured':>14}  fit s"
          "  normals from the truth, mesh -> result (median/p95 deg)")
    for scene in args.scenes:
        s = os.path.join(shared, "scenes", scene)
        lit = gt_lit(s, os.path.join(work, scene + "_gt_lit.txt"))
        exact = None
        for name, perturb, mesh_args, step in captures:
            tag = scene + "_" + name.replace(" ", "_").replace(".", "")
            project = os.path.join(s, "project.mlp")
            moved_mesh = ""
            if mesh_args:
                mesh = os.path.join(work, tag + ".ply")
                out = subprocess.run([os.path.join(args.build, "tests", "benchmark", "vbrdf_perturb_mesh"),
                                      os.path.join(s, "mesh.ply"), mesh] + mesh_args,
                                     check=True, capture_output=True, text=True).stdout
                m = re.search(r"median ([\d.]+) deg, p95 ([\d.]+) deg", out)
                moved_mesh = f"{m.group(1)}/{m.group(2)} deg" if m else ""
                perturb = perturb + ["--mesh", mesh]
            if perturb:
                project = os.path.join(work, tag + ".mlp")
                subprocess.check_call([sys.executable, os.path.join(HERE, "perturb_cameras.py"),
                                       os.path.join(s, "project.mlp"), project] + perturb)
            for setting in (["on"] if not step else ["off", "on"]):
                steps = dict(STEP_DEFAULTS, registration="on") if not step else dict(STEP_DEFAULTS, **{step: setting})
                out = os.path.join(work, f"{tag}_{step or 'both'}{setting}.ply")
                rc, secs = run([fit, project, "--lp", os.path.join(s, "lights.lp"), "--photo-dir", os.path.join(s, "linear"),
                                "--color-correction", "off", "--registration", steps["registration"],
                                "--shading-normals", steps["shading-normals"], "--out", out] + extra_fit_options,
                               out + ".fit.log")
                if rc != 0:
                    failures.append(f"{scene} {name}: vbrdf_fit failed (see {out}.fit.log)")
                    continue
                log = open(out + ".fit.log").read()
                m = re.search(r"misregistration ([\d.]+) px", log)
                measured = m.group(1) + " px" if m and step != "shading-normals" else ""
                m = re.search(r"Shading normals: refined .*?median ([\d.]+) deg, p95 ([\d.]+) deg", log)
                if step == "shading-normals" and m and setting == "on":
                    measured = f"{m.group(1)}/{m.group(2)} deg"
                rc, _ = run([ev, "--result", out, "--project", os.path.join(s, "heldout", "project.mlp"),
                             "--photo-dir", os.path.join(s, "heldout", "linear"), "--training", os.path.join(s, "project.mlp"),
                             "--training-photo-dir", os.path.join(s, "linear"), "--gt-visible", os.path.join(s, "gt_vertex.ply")] + lit,
                            out + ".eval.log")
                e = parse_eval(open(out + ".eval.log").read())
                label = "both on" if not step else f"{step} {setting}"
                truth = normals_vs_truth(out, mesh if mesh_args else os.path.join(s, "mesh.ply"), s)
                truth_text = f"{truth[0]:.2f}/{truth[1]:.2f} -> {truth[2]:.2f}/{truth[3]:.2f}" if truth else ""
                r = dict(scene=scene, capture=name, correction=label, mean=e["product"][0], p95=e["product"][1],
                         ptm_mean=e["ptm"][0], ptm_p95=e["ptm"][1], rbf_mean=e["rbf"][0], rbf_p95=e["rbf"][1],
                         measured=measured, mesh_normals_off=moved_mesh, normals_vs_truth=truth_text,
                         fit_seconds=round(secs, 2))
                rows.append(r)
                print(f"{scene:28} {name:16} {label:19} {r['mean']:6.3f} {r['p95']:6.3f}   {r['ptm_mean']:5.3f} / {r['ptm_p95']:5.3f}"
                      f" {r['rbf_mean']:5.3f} / {r['rbf_p95']:5.3f}  {measured:>14}  {secs:5.1f}  {truth_text}", flush=True)
                if not step:
                    exact = r
                elif setting == "on" and args.max_ratio and exact and name != COMBINED:
                    for k in ("mean", "p95"):
                        if r[k] > args.max_ratio * exact[k]:
                            failures.append(f"{scene} {name}: {k} {r[k]:.3f} above {args.max_ratio} x exact {exact[k]:.3f}")
                        if r[k] >= min(r["ptm_" + k], r["rbf_" + k]):
                            failures.append(f"{scene} {name}: {k} {r[k]:.3f} not below PTM / RBF")
                    if "--smooth-normals" in mesh_args and truth and (truth[2] >= truth[0] or truth[3] >= truth[1]):
                        failures.append(f"{scene} {name}: the refined normals are not closer to the truth than the mesh's "
                                        f"(median / p95 {truth_text} deg)")
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
            w.writeheader()
            w.writerows(rows)
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
