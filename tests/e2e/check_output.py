#!/usr/bin/env python3
"""Checks the PLY written by "Vertex BRDF: fit per-vertex reflectance" against its input mesh and
a ground truth, prints the figures and fails (exit 1) when a check or threshold fails.

Checks: the named per-vertex properties exist; every float is finite; geometry and faces equal the
input's; vertices without an estimate (coloured = 0, in particular n_visible = 0) kept their input
colour; display colours are sRGB of diffuse_*; the diffuse colour of the coloured vertices against
the ground-truth albedo after a least-squares colour map:
  scalar  one global scale (absolute light intensity and exposure are unknown): the default;
  diag    one scale per channel (white balance);
  matrix  a 3x3 matrix (camera colour matrix; e.g. scenes whose 8-bit photos carry a colour cast,
          such as shared/scenes/*/images/, where scalar errors would mostly measure the cast).
All three are reported; thresholds apply to the one chosen with --fit.
"""
import argparse
import json
import sys

sys.dont_write_bytecode = True  # never write __pycache__ into the source tree

import numpy as np

import e2e_lib as lib

REQUIRED = ["x", "y", "z", "nx", "ny", "nz", "red", "green", "blue", "alpha",
            "diffuse_r", "diffuse_g", "diffuse_b", "n_visible", "n_diffuse", "n_specular", "coloured"]
GT_ALBEDO = ["albedo_r", "albedo_g", "albedo_b"]


def input_colours(mesh):
    """RGBA8 the filter saw: the mesh's colours, or MeshLab's default white when it has none."""
    v = mesh.vertex
    rgba = np.full((len(v), 4), 255, np.int64)
    for i, name in enumerate(["red", "green", "blue", "alpha"]):
        if name in v.dtype.names:
            rgba[:, i] = v[name]
    return rgba


def check(out_path, input_mesh_path, gt_path, fit="scalar", max_rel=None, max_de=None, min_coverage=None,
          max_de_all=None):
    failures = []
    out, mesh, gt = lib.read_ply(out_path), lib.read_ply(input_mesh_path), lib.read_ply(gt_path)
    v = out.vertex
    missing = [p for p in REQUIRED if p not in v.dtype.names]
    if missing:
        return {"failures": [f"output lacks vertex properties {missing} (has {list(v.dtype.names)})"]}
    n = len(v)
    if n != len(mesh.vertex) or n != len(gt.vertex):
        return {"failures": [f"vertex counts differ: output {n}, input {len(mesh.vertex)}, ground truth {len(gt.vertex)}"]}

    for name in v.dtype.names:
        if v.dtype[name].kind == "f" and not np.all(np.isfinite(v[name])):
            failures.append(f"property {name}: {int(np.sum(~np.isfinite(v[name])))} non-finite values")

    pos = np.stack([v[c] for c in "xyz"], 1).astype(np.float64)
    pos_in = np.stack([mesh.vertex[c] for c in "xyz"], 1).astype(np.float64)
    diag = float(np.linalg.norm(pos_in.max(0) - pos_in.min(0))) if n else 1.0
    if np.abs(pos - pos_in).max(initial=0) > 1e-6 * diag:
        failures.append("vertex positions differ from the input mesh")
    if out.faces.shape != mesh.faces.shape or not np.array_equal(out.faces, mesh.faces):
        failures.append(f"faces differ from the input mesh ({out.faces.shape} vs {mesh.faces.shape})")

    rgba = np.stack([v[c] for c in ["red", "green", "blue", "alpha"]], 1).astype(np.int64)
    coloured = v["coloured"] > 0.5
    unseen = v["n_visible"] == 0
    kept = np.all(rgba == input_colours(mesh), axis=1)
    if np.any(coloured & unseen):
        failures.append(f"{int(np.sum(coloured & unseen))} vertices coloured although no photo sees them")
    if not np.all(kept[~coloured]):
        failures.append(f"{int(np.sum(~kept & ~coloured))} vertices without estimate lost their input colour "
                        f"({int(np.sum(~kept & unseen))} of them seen by no photo)")
    est = np.stack([v["diffuse_r"], v["diffuse_g"], v["diffuse_b"]], 1).astype(np.float64)
    shown = np.round(255 * lib.linear_to_srgb(est))
    if coloured.any() and np.abs(shown[coloured] - rgba[coloured, :3]).max() > 1:
        failures.append("vertex colours of coloured vertices are not the sRGB encoding of diffuse_r/g/b")
    if np.any(est[coloured] < 0):
        failures.append("negative diffuse reflectance")
    if "fit_status" in v.dtype.names:
        # Every vertex a photo sees has a model, and one consistent output: the written
        # diffuse reflectance is the model's k_d C.
        modelled = v["fit_status"] > 0.5
        if np.any(~unseen & ~modelled):
            failures.append(f"{int(np.sum(~unseen & ~modelled))} vertices seen by a photo have no model "
                            f"(fit_status 0)")
        kd_c = v["kd"][:, None].astype(np.float64) * np.stack([v["color_r"], v["color_g"], v["color_b"]], 1)
        apart = modelled & (np.abs(kd_c - est).max(axis=1) > 1e-4 * np.maximum(1.0, est.max(axis=1)))
        if np.any(apart):
            failures.append(f"{int(apart.sum())} modelled vertices have diffuse_r/g/b different from k_d * color")
        if np.any(modelled & ~coloured):
            failures.append(f"{int(np.sum(modelled & ~coloured))} modelled vertices are not coloured")

    report = {"vertices": n, "coloured": int(coloured.sum()), "unseen": int(unseen.sum()),
              "seen_without_estimate": int((~coloured & ~unseen).sum()), "fit": fit}
    vis_name = next((c for c in ("visible", "visible_any") if c in gt.vertex.dtype.names), None)
    if vis_name:
        visible = gt.vertex[vis_name] > 0.5
        report["gt_visible"] = int(visible.sum())
        report["coverage_of_gt_visible"] = float((coloured & visible).sum() / max(1, visible.sum()))
        report["coloured_not_gt_visible"] = int((coloured & ~visible).sum())
        if min_coverage is not None and report["coverage_of_gt_visible"] < min_coverage:
            failures.append(f"coverage {report['coverage_of_gt_visible']:.3f} of GT-visible vertices < {min_coverage}")
    if not all(c in gt.vertex.dtype.names for c in GT_ALBEDO):
        failures.append(f"ground truth {gt_path} lacks {GT_ALBEDO}")
    elif not coloured.any():
        failures.append("no vertex was coloured")
    else:
        albedo = np.stack([gt.vertex[c] for c in GT_ALBEDO], 1).astype(np.float64)
        for mode in ("scalar", "diag", "matrix"):
            e = lib.colour_errors(est[coloured], albedo[coloured], mode)
            report[mode] = {k: (val.round(4).tolist() if isinstance(val, np.ndarray) else
                                (round(val, 5) if isinstance(val, float) else val))
                            for k, val in e.items()}
        if "material_boundary" in gt.vertex.dtype.names:  # photos blend materials across boundaries
            interior = coloured & (gt.vertex["material_boundary"] < 0.5)
            if interior.any():
                e = lib.colour_errors(est[interior], albedo[interior], fit)
                report["interior"] = {"vertices": int(interior.sum()), "mean_rel": round(e["mean_rel"], 5),
                                      "mean_de2000": round(e["mean_de2000"], 5)}
        # Vertices coloured from clean pixels only (coloured = 1) against those that fell back to
        # mixed silhouette/border/contact pixels (coloured = 2): thresholds apply to the clean ones,
        # `max_de_all` to all coloured vertices.
        clean = v["coloured"] > 0.5
        clean &= v["coloured"] < 1.5
        report["all_coloured"] = report[fit]
        if clean.any():
            e = lib.colour_errors(est[clean], albedo[clean], fit)
            report["clean"] = {k: (val.round(4).tolist() if isinstance(val, np.ndarray) else
                                   (round(val, 5) if isinstance(val, float) else val)) for k, val in e.items()}
            report["clean"]["vertices"] = int(clean.sum())
        if max_de_all is not None and report[fit]["mean_de2000"] > max_de_all:
            failures.append(f"mean CIEDE2000 over all coloured vertices {report[fit]['mean_de2000']:.3f} > {max_de_all}")
        chosen = report.get("clean", report[fit])
        if max_rel is not None and chosen["mean_rel"] > max_rel:
            failures.append(f"mean relative error {chosen['mean_rel']:.4f} > {max_rel} ({fit} fit)")
        if max_de is not None and chosen["mean_de2000"] > max_de:
            failures.append(f"mean CIEDE2000 {chosen['mean_de2000']:.3f} > {max_de} ({fit} fit)")
    params = parameter_errors(v, gt.vertex)
    if params:
        report["params"] = params
    report["failures"] = failures
    return report


def parameter_errors(v, g):
    """Phong parameter error against a synthetic ground truth (kd, ks, shininess, albedo_*), where
    both exist: rho = kd*C for every fitted vertex; ks and shininess on vertices with a full fit
    whose true ks > 0.2 (a visible specular term); false specular on truly diffuse vertices."""
    need_out = ["kd", "ks", "shininess", "fit_status", "color_r"]
    need_gt = ["kd", "ks", "shininess", "albedo_r"]
    if not all(n in v.dtype.names for n in need_out) or not all(n in g.dtype.names for n in need_gt):
        return None
    fitted = v["fit_status"] > 0.5
    rho = np.stack([v["kd"] * v[c] for c in ("color_r", "color_g", "color_b")], 1)
    rho_gt = np.stack([g[c] for c in ("albedo_r", "albedo_g", "albedo_b")], 1)
    r = {"fitted": int(fitted.sum())}
    if fitted.any():
        rel = np.abs(rho[fitted] - rho_gt[fitted]).sum(1) / np.maximum(rho_gt[fitted].sum(1), 0.02)
        r["rho_median_rel"] = float(np.median(rel))
    glossy = fitted & (g["ks"] > 0.2)
    full = glossy & (v["fit_status"] > 1.5)
    r["glossy_vertices"] = int(glossy.sum())
    r["glossy_with_full_fit"] = int(full.sum())
    # k_s and shininess are well determined with >= 2 clean highlight samples; fits freed by the
    # broad-lobe rule (samples with R.E > 0.5 only) render well but trade k_s against alpha.
    determined = full & (v["n_specular"] >= 2)
    r["glossy_well_determined"] = int(determined.sum())
    if determined.any():
        r["ks_median_rel"] = float(np.median(np.abs(v["ks"][determined] - g["ks"][determined]) / g["ks"][determined]))
        r["shininess_median_rel"] = float(np.median(np.abs(v["shininess"][determined] - g["shininess"][determined])
                                                    / g["shininess"][determined]))
    lobe_only = full & (v["n_specular"] < 2)
    if lobe_only.any():
        r["lobe_only_ks_median_rel"] = float(np.median(np.abs(v["ks"][lobe_only] - g["ks"][lobe_only]) / g["ks"][lobe_only]))
    diffuse = fitted & (g["ks"] == 0)
    if diffuse.any():
        r["false_specular_fraction"] = float(np.mean(v["ks"][diffuse] > 0.05))
    return r


def print_report(r, label=""):
    print(f"==== e2e figures {label}")
    for key in ("vertices", "coloured", "unseen", "seen_without_estimate", "gt_visible",
                "coverage_of_gt_visible", "coloured_not_gt_visible"):
        if key in r:
            print(f"  {key:26s} {r[key]}")
    for mode in ("scalar", "diag", "matrix"):
        if mode in r:
            e = r[mode]
            mark = "  (all coloured vertices)" if mode == r.get("fit") else ""
            print(f"  {mode:7s} fit: mean rel err {e['mean_rel']:.4f} (median {e['median_rel']:.4f}), "
                  f"mean CIEDE2000 {e['mean_de2000']:.3f} (p95 {e['p95_de2000']:.3f}){mark}")
    if "params" in r:
        p = r["params"]
        print("  Phong parameters vs ground truth: " + ", ".join(
            f"{k} {val:.4f}" if isinstance(val, float) else f"{k} {val}" for k, val in p.items()))
    if "clean" in r:
        e = r["clean"]
        print(f"  clean pixels only ({e['vertices']} vertices, {r.get('fit')} fit): mean rel err {e['mean_rel']:.4f} "
              f"(median {e['median_rel']:.4f}), mean CIEDE2000 {e['mean_de2000']:.3f} (p95 {e['p95_de2000']:.3f})  <= asserted")
    if "scalar" in r:
        print(f"  global scale (scalar fit): {r['scalar']['map'][0][0]:.4f}")
    if "interior" in r:
        i = r["interior"]
        print(f"  {r['fit']} fit away from material boundaries ({i['vertices']} vertices): mean rel err "
              f"{i['mean_rel']:.4f}, mean CIEDE2000 {i['mean_de2000']:.3f}")
    if "scalar" in r and r["scalar"]["dark_skipped"]:
        print(f"  (relative errors skip {r['scalar']['dark_skipped']} vertices with near-black ground truth)")
    for f in r["failures"]:
        print(f"  FAIL: {f}")
    print("  RESULT:", "FAILED" if r["failures"] else "ok")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("output_ply")
    ap.add_argument("input_mesh")
    ap.add_argument("ground_truth")
    ap.add_argument("--fit", choices=["scalar", "diag", "matrix"], default="scalar")
    ap.add_argument("--max-rel", type=float)
    ap.add_argument("--max-de", type=float)
    ap.add_argument("--max-de-all", type=float, help="bound on the mean CIEDE2000 over all coloured vertices")
    ap.add_argument("--min-coverage", type=float)
    ap.add_argument("--json", help="also write the figures here")
    a = ap.parse_args(argv)
    r = check(a.output_ply, a.input_mesh, a.ground_truth, a.fit, a.max_rel, a.max_de, a.min_coverage, a.max_de_all)
    print_report(r, a.output_ply)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(r, f, indent=1)
    return 1 if r["failures"] else 0


if __name__ == "__main__":
    sys.exit(main())
