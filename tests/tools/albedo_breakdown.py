#!/usr/bin/python3
"""Where the albedo error of a fit comes from (the acceptance figure "albedo over all visible
vertices").

    tests/tools/albedo_breakdown.py FIT.ply SCENE_DIR [--ior X] [--max-mean M] [--max-p95 P]
    tests/tools/albedo_breakdown.py --fit-tool vbrdf_fit --work DIR SCENE_DIR [...]

FIT.ply: a fit of SCENE_DIR/project.mlp (vbrdf_fit or the filter); SCENE_DIR: a shared scene
folder holding gt_vertex.npz and gt_scene.json (camera origin, materials). Score: the fit's
diffuse_r/g/b against the ground truth's albedo_effective_normal over the ground-truth-visible
vertices, after one per-channel gain (e2e_lib.colour_errors 'diag'), CIEDE2000 mean / p95.

Prints, besides the score:
  - the same by `coloured` (1 clean pixels, 2 rim pixels only);
  - the luminance ratio fit / truth (after the gain) by material and by N.E (cosine of the exit
    angle towards the camera): separates background mixing at silhouettes (would darken the
    Lambertian material's rims too) from grazing exitance through a dielectric coating;
  - the albedo-edge floor: clean vertices whose ground-truth albedo jumps by >= 3 CIEDE2000 to a
    mesh neighbour (a pixel integrates both sides of such an edge);
  - what-ifs that bound a fix: rims perfect; rims 6 % brighter (what removing background mixing
    can give); albedo-edge vertices perfect; glossy vertices
    divided by the coating's Fresnel transmission at their exit angle, T(theta_o) / T(0) (N.E
    clipped at 0.15) with the ground-truth material (an oracle) and with coated vertices chosen
    from the fit's specular evidence (coated_from_fit).
--fit-tool / --work: fit SCENE_DIR/project.mlp first (its photos, colour correction Auto: the
acceptance protocol, "colour correction Auto where a chart is in view"; the fit's other defaults)
into DIR/fit.ply. --max-mean / --max-p95: bounds on the acceptance figure (the albedo acceptance
bounds over all visible vertices: 2.5 and 8).
Only the standard library and numpy. Exit status 0, 1 when a bound is exceeded or the fit fails,
2 on bad arguments.
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "e2e"))
import e2e_lib as lib  # noqa: E402


def neighbour_jump(faces, lab):
    """Per vertex, the largest CIEDE2000 between its colour and a mesh neighbour's."""
    i = np.concatenate([faces[:, 0], faces[:, 1], faces[:, 2], faces[:, 1], faces[:, 2], faces[:, 0]])
    j = np.concatenate([faces[:, 1], faces[:, 2], faces[:, 0], faces[:, 0], faces[:, 1], faces[:, 2]])
    de = lib.ciede2000(lab[i], lab[j])
    jump = np.zeros(len(lab))
    np.maximum.at(jump, i, de)
    return jump


def coated_from_fit(v, faces, rings):
    """Vertices judged coated from the fit's own evidence: a fitted lobe (fit_status 2) with
    k_s > 0.03 and shininess > 5 votes coated, any other lobe votes not; votes are averaged over
    `rings` mesh rings; majority decides, no vote within reach means not coated."""
    lobe = v["fit_status"] == 2
    vote = (lobe & (v["ks"] > 0.03) & (v["shininess"] > 5)).astype(float)
    weight = lobe.astype(float)
    i = np.concatenate([faces[:, 0], faces[:, 1], faces[:, 2], faces[:, 1], faces[:, 2], faces[:, 0]])
    j = np.concatenate([faces[:, 1], faces[:, 2], faces[:, 0], faces[:, 0], faces[:, 1], faces[:, 2]])
    num, den = vote * weight, weight.copy()
    for _ in range(rings):
        num2, den2 = num.copy(), den.copy()
        np.add.at(num2, i, num[j])
        np.add.at(den2, i, den[j])
        num, den = num2, den2
    return (den > 0) & (num > 0.5 * den)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("paths", nargs="+", help="FIT.ply SCENE_DIR, or SCENE_DIR with --fit-tool")
    ap.add_argument("--ior", type=float, default=None, help="coating IOR (default: the scene's roughplastic int_ior)")
    ap.add_argument("--fit-tool", help="vbrdf_fit: fit SCENE_DIR/project.mlp first (colour correction auto)")
    ap.add_argument("--work", help="with --fit-tool: the folder for fit.ply and fit.log")
    ap.add_argument("--max-mean", type=float, default=None)
    ap.add_argument("--max-p95", type=float, default=None)
    a = ap.parse_args(argv)
    if a.fit_tool:
        if len(a.paths) != 1 or not a.work:
            ap.error("--fit-tool takes --work DIR and one SCENE_DIR")
        a.scene = a.paths[0]
        os.makedirs(a.work, exist_ok=True)
        a.fit = os.path.join(a.work, "fit.ply")
        with open(os.path.join(a.work, "fit.log"), "w") as log:
            run = subprocess.run([a.fit_tool, os.path.join(a.scene, "project.mlp"), "--color-correction", "auto",
                                  "--out", a.fit], stdout=log, stderr=subprocess.STDOUT)
        if run.returncode != 0:
            print(f"FAIL: {a.fit_tool} exit {run.returncode} (see {a.work}/fit.log)")
            return 1
    elif len(a.paths) == 2:
        a.fit, a.scene = a.paths
    else:
        ap.error("give FIT.ply SCENE_DIR, or --fit-tool with one SCENE_DIR")
    gt_npz = os.path.join(a.scene, "gt_vertex.npz")
    if not os.path.isfile(gt_npz) or not os.path.isfile(a.fit):
        print(f"error: need {a.fit} and {gt_npz}", file=sys.stderr)
        return 2
    g = np.load(gt_npz)
    v = lib.read_ply(a.fit).vertex
    scene = json.load(open(os.path.join(a.scene, "gt_scene.json")))
    ior = a.ior
    if ior is None:
        iors = [m.get("int_ior") for m in scene.get("materials", []) if isinstance(m, dict) and m.get("int_ior")]
        ior = float(iors[0]) if iors else 1.5
    vis = g["visible"].astype(bool)
    gt = g["albedo_effective_normal"].astype(float)
    est = np.stack([v["diffuse_r"], v["diffuse_g"], v["diffuse_b"]], 1).astype(float)
    col = v["coloured"]
    clean, rim = vis & (col == 1), vis & (col == 2)

    def score(e, label, sel=vis):
        r = lib.colour_errors(e[sel], gt[sel], "diag")
        print(f"  {label:<58s} mean {r['mean_de2000']:5.2f}  p95 {r['p95_de2000']:5.2f}")
        return r

    print(f"{a.fit}: {vis.sum()} visible vertices, {clean.sum()} coloured=1, {rim.sum()} coloured=2")
    acceptance = score(est, "all visible (the acceptance figure)")
    failures = []
    if a.max_mean is not None and not acceptance["mean_de2000"] < a.max_mean:
        failures.append(f"mean {acceptance['mean_de2000']:.2f} not below {a.max_mean}")
    if a.max_p95 is not None and not acceptance["p95_de2000"] < a.max_p95:
        failures.append(f"p95 {acceptance['p95_de2000']:.2f} not below {a.max_p95}")
    score(est, "clean-pixel vertices (coloured 1), own gain", clean)

    gain = lib.fit_colour_map(est[vis], gt[vis], "diag")
    lab_gt = lib.linear_rgb_to_lab(gt)
    de = lib.ciede2000(lib.linear_rgb_to_lab(est @ gain.T), lab_gt)
    share = lambda s: de[s].sum() / de[vis].sum()
    for name, s in (("coloured 1", clean), ("coloured 2 (rim)", rim)):
        if s.any():
            print(f"  {name:<18s} n={s.sum():5d} mean {de[s].mean():5.2f} p95 {np.percentile(de[s], 95):5.2f} share of error {share(s):.2f}")

    # Luminance ratio by material and exit angle (gain from the clean vertices).
    gain_c = lib.fit_colour_map(est[clean], gt[clean], "diag")
    lum = lambda x: x @ np.array([0.2126, 0.7152, 0.0722])
    ratio = lum(est @ gain_c.T) / np.maximum(lum(gt), 1e-6)
    origin = np.array(scene["camera"]["origin_world"], float)
    n = np.stack([v["nx"], v["ny"], v["nz"]], 1).astype(float)
    e_dir = origin[None] - g["positions"]
    e_dir /= np.linalg.norm(e_dir, axis=1)[:, None]
    n_dot_e = (n * e_dir).sum(1)
    mat, glossy = g["material_id"], g["is_glossy"].astype(bool)
    print("  luminance fit/truth (median; gain from clean vertices) by N.E:")
    bins = ((-1.0, 0.1), (0.1, 0.2), (0.2, 0.3), (0.3, 0.5), (0.5, 0.7), (0.7, 1.01))
    for mid in np.unique(mat[vis]):
        kind = "glossy" if glossy[mat == mid].any() else "Lambertian"
        cells = []
        for lo, hi in bins:
            s = vis & (mat == mid) & (n_dot_e >= lo) & (n_dot_e < hi)
            cells.append(f"[{lo:.1f},{min(hi, 1):.1f}) {np.median(ratio[s]):.2f}" if s.sum() >= 5 else f"[{lo:.1f},{min(hi, 1):.1f})  -- ")
        s_rim, s_cl = rim & (mat == mid), clean & (mat == mid)
        print(f"    material {mid} ({kind}): " + "  ".join(cells))
        if s_rim.any():
            print(f"      rims {np.median(ratio[s_rim]):.2f} (median N.E {np.median(n_dot_e[s_rim]):.2f}), "
                  f"clean {np.median(ratio[s_cl]):.2f} (median N.E {np.median(n_dot_e[s_cl]):.2f})")

    jump = neighbour_jump(g["faces"].astype(np.int64), lab_gt)
    edge = jump >= 3.0
    print(f"  clean vertices at an albedo edge (neighbour jump >= 3): {(clean & edge).sum()} "
          f"({(clean & edge).sum() / max(clean.sum(), 1):.0%}), mean {de[clean & edge].mean():.2f}; "
          f"elsewhere mean {de[clean & ~edge].mean():.2f} p95 {np.percentile(de[clean & ~edge], 95):.2f}")

    print("  what-ifs (all visible):")
    ref = np.median(est[clean] / np.maximum(gt[clean], 1e-4), 0)
    e1 = est.copy(); e1[rim] = gt[rim] * ref
    score(e1, "rims perfect")
    e1b = est.copy(); e1b[rim] *= 1.06
    score(e1b, "rims x 1.06 (the Lambertian rims' deficit: background mixing)")
    e2 = est.copy(); e2[edge] = gt[edge] * ref
    score(e2, "albedo-edge vertices perfect")
    t_rel = (1 - lib.fresnel_dielectric(np.clip(n_dot_e, 0.15, 1.0), ior)) / (1 - lib.fresnel_dielectric(np.ones(1), ior))
    e3 = est.copy(); e3[glossy] /= t_rel[glossy, None]
    score(e3, f"glossy (truth) / T(theta_o)/T(0), IOR {ior:g}, N.E >= 0.15")
    e4 = est / t_rel[:, None]
    score(e4, "every vertex / T(theta_o)/T(0)")
    coated = coated_from_fit(v, g["faces"].astype(np.int64), rings=16)
    e5 = est.copy(); e5[coated] /= t_rel[coated, None]
    agree = (coated[vis] == glossy[vis]).mean()
    score(e5, f"same, coated chosen from the fit (16 rings; {agree:.0%} right)")
    if failures:
        print("FAIL: albedo over all visible vertices: " + "; ".join(failures))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
