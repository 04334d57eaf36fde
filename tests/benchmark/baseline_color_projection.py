#!/usr/bin/env python3
"""Baseline comparison: MeshLab's "Project active rasters color to current mesh" against our diffuse
colour, both run by Debian's meshlabserver on the same projects and photos, both scored against the
ground-truth albedo with CIEDE2000 after one global scale (neither method knows the absolute
irradiance and exposure; the scale is fitted per method by least squares in linear RGB).

  baseline_color_projection.py --bench <build>/tests/benchmark/vbrdf_bench
                               --wrapper <build>/meshlab_run/run_meshlabserver.sh --work DIR

Projects: the shared scenes (their 16-bit linear photos converted to 8-bit sRGB, i.e. without the
images/ colour cast, so that one scale is a fair map) and the sample projects synth_basic,
synth_two_views and synth_linear16 (the last converted the same way). Scored vertices: those the
ground truth marks visible and the method coloured; both methods are also scored on the vertices
both coloured. Writes DIR/baseline.csv and DIR/baseline.md. Needs numpy (tests/e2e helpers).
"""
import argparse
import json
import os
import subprocess
import sys
import time

sys.dont_write_bytecode = True
HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(REPO, "tests", "e2e"))

import numpy as np  # noqa: E402

import e2e_lib as lib  # noqa: E402

SHARED = os.environ.get("VBRDF_SHARED_DIR", os.path.normpath(os.path.join(REPO, "..", "shared")))
SHARED_SCENES = ["spot_dir24", "bunny_two_materials_dir32", "teapot_dir16", "teapot_point16"]
SAMPLES = ["synth_basic", "synth_two_views", "synth_linear16"]
FIT_MLX = os.path.join(REPO, "sample_projects", "synth_basic", "fit.mlx")
BASELINE_MLX = os.path.join(HERE, "color_projection.mlx")
BLANK = (255, 0, 255)  # blankColor of color_projection.mlx


def log(msg):
    print(msg, flush=True)


def run(cmd, log_path):
    start = time.time()
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=1200)
    seconds = time.time() - start
    text = proc.stdout.decode("utf-8", "replace")
    with open(log_path, "w", encoding="utf-8") as f:
        f.write(text)
    if proc.returncode != 0:
        raise RuntimeError(f"failed ({proc.returncode}): {' '.join(cmd)}; log {log_path}\n{text[-2000:]}")
    return seconds


def is_16bit_png(path):
    with open(path, "rb") as f:
        head = f.read(26)
    return head[:8] == b"\x89PNG\r\n\x1a\n" and head[24] == 16


def first_photo(mlp):
    import xml.etree.ElementTree as ET
    plane = next(ET.parse(mlp).getroot().iter("Plane"))
    return os.path.join(os.path.dirname(os.path.abspath(mlp)), plane.get("fileName"))


class Case:
    def __init__(self, name, mlp, lp, gt, photo_dir=None, factors=None):
        self.name, self.mlp, self.lp, self.gt, self.photo_dir, self.factors = name, mlp, lp, gt, photo_dir, factors


def cases():
    out = []
    for name in SHARED_SCENES:
        src = os.path.join(SHARED, "scenes", name)
        if not os.path.isfile(os.path.join(src, "project.mlp")):
            log(f"{name}: not found, skipped")
            continue
        with open(os.path.join(src, "gt_scene.json"), encoding="utf-8") as f:
            factors = [m.get("diffuse_factor_normal", 1.0) for m in json.load(f)["materials"]]
        out.append(Case(name, os.path.join(src, "project.mlp"), os.path.join(src, "lights.lp"),
                        os.path.join(src, "gt_vertex.ply"), os.path.join(src, "linear"), factors))
    for name in SAMPLES:
        src = os.path.join(REPO, "sample_projects", name)
        mlp = os.path.join(src, "project.mlp")
        photo_dir = os.path.dirname(first_photo(mlp)) if is_16bit_png(first_photo(mlp)) else None
        out.append(Case(name, mlp, os.path.join(src, "lights.lp"), os.path.join(src, "ground_truth", "gt_vertex.ply"),
                        photo_dir))
    return out


def prepare(case, bench, work):
    """The project as both methods see it: absolute paths, 8-bit sRGB photos."""
    mlp = os.path.join(work, "project.mlp")
    if case.photo_dir:
        photos = os.path.join(work, "photos_srgb8")
        subprocess.run([bench, "srgb8", "--in-dir", case.photo_dir, "--out-dir", photos], check=True,
                       stdout=subprocess.DEVNULL)
        lib.rewrite_mlp(case.mlp, mlp, photo_dir=photos)
    else:
        lib.rewrite_mlp(case.mlp, mlp)
    return mlp


def albedo_truth(case):
    g = lib.read_ply(case.gt).vertex
    albedo = np.stack([g["albedo_r"], g["albedo_g"], g["albedo_b"]], 1).astype(np.float64)
    if case.factors and "material_id" in g.dtype.names:  # Lambertian-equivalent albedo of coated materials
        albedo *= np.asarray(case.factors)[np.clip(g["material_id"].astype(int), 0, len(case.factors) - 1)][:, None]
    vis_name = next(n for n in ("visible", "visible_any") if n in g.dtype.names)
    return albedo, g[vis_name] > 0.5


def scaled_de(est, gt):
    e = lib.colour_errors(est, gt, "scalar")
    return e["mean_de2000"], e["p95_de2000"], float(e["map"][0, 0])


def evaluate(case, baseline_ply, ours_ply):
    albedo, visible = albedo_truth(case)
    b = lib.read_ply(baseline_ply).vertex
    rgb8 = np.stack([b["red"], b["green"], b["blue"]], 1).astype(np.int64)
    base_col = ~np.all(rgb8 == np.array(BLANK), axis=1)
    base_lin = lib.srgb_to_linear(rgb8 / 255.0)
    o = lib.read_ply(ours_ply).vertex
    ours_col = o["coloured"] > 0.5
    ours_lin = np.stack([o["diffuse_r"], o["diffuse_g"], o["diffuse_b"]], 1).astype(np.float64)
    r = {"scene": case.name, "gt_visible": int(visible.sum())}
    both = visible & base_col & ours_col
    for tag, col, est in (("baseline", base_col, base_lin), ("ours", ours_col, ours_lin)):
        sel = visible & col
        r[f"{tag}_coverage"] = float(sel.sum() / max(1, visible.sum()))
        r[f"{tag}_de_mean"], r[f"{tag}_de_p95"], r[f"{tag}_scale"] = scaled_de(est[sel], albedo[sel])
        r[f"{tag}_common_de_mean"], r[f"{tag}_common_de_p95"], _ = scaled_de(est[both], albedo[both])
    r["common_vertices"] = int(both.sum())
    return r


def run_case(case, a):
    work = os.path.join(a.work, case.name)
    os.makedirs(work, exist_ok=True)
    mlp = prepare(case, a.bench, work)
    baseline_ply = os.path.join(work, "baseline.ply")
    t_base = run([a.wrapper, "-p", mlp, "-s", BASELINE_MLX, "-o", baseline_ply, "-m", "vc"],
                 os.path.join(work, "baseline.log"))
    fit_mlx = os.path.join(work, "fit.mlx")
    ours_ply = os.path.join(work, "ours.ply")
    lib.write_mlx(FIT_MLX, fit_mlx, {"lightFile": case.lp, "outputPly": ours_ply})
    t_ours = run([a.wrapper, "-p", mlp, "-s", fit_mlx], os.path.join(work, "ours.log"))
    r = evaluate(case, baseline_ply, ours_ply)
    r.update(baseline_seconds=t_base, ours_seconds=t_ours)
    return r


COLUMNS = ["scene", "gt_visible", "baseline_coverage", "baseline_de_mean", "baseline_de_p95", "ours_coverage",
           "ours_de_mean", "ours_de_p95", "common_vertices", "baseline_common_de_mean", "ours_common_de_mean",
           "baseline_seconds", "ours_seconds"]


def write_outputs(rows, work):
    with open(os.path.join(work, "baseline.csv"), "w", encoding="utf-8") as f:
        f.write(",".join(COLUMNS) + "\n")
        for r in rows:
            f.write(",".join(f"{r[c]:.4g}" if isinstance(r[c], float) else str(r[c]) for c in COLUMNS) + "\n")
    lines = ["| scene | GT-visible | baseline coverage | baseline dE mean / p95 | ours coverage | ours dE mean / p95 "
             "| both coloured: baseline / ours dE mean | meshlabserver s: baseline / ours |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['gt_visible']} | {r['baseline_coverage']:.3f} | "
                     f"{r['baseline_de_mean']:.2f} / {r['baseline_de_p95']:.2f} | {r['ours_coverage']:.3f} | "
                     f"{r['ours_de_mean']:.2f} / {r['ours_de_p95']:.2f} | "
                     f"{r['baseline_common_de_mean']:.2f} / {r['ours_common_de_mean']:.2f} | "
                     f"{r['baseline_seconds']:.1f} / {r['ours_seconds']:.1f} |")
    with open(os.path.join(work, "baseline.md"), "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bench", required=True)
    ap.add_argument("--wrapper", required=True, help="<build>/meshlab_run/run_meshlabserver.sh")
    ap.add_argument("--work", required=True)
    ap.add_argument("--synth", help="unused (accepted so that the CMake targets can share arguments)")
    ap.add_argument("--only", default="")
    a = ap.parse_args(argv)
    a.work = os.path.abspath(a.work)  # the fit resolves relative paths against the project folder
    os.makedirs(a.work, exist_ok=True)
    rows = []
    for case in cases():
        if a.only not in case.name:
            continue
        r = run_case(case, a)
        rows.append(r)
        log(f"{case.name:26s} baseline dE {r['baseline_de_mean']:.2f} (cov {r['baseline_coverage']:.2f}) | "
            f"ours dE {r['ours_de_mean']:.2f} (cov {r['ours_coverage']:.2f})")
    log(write_outputs(rows, a.work))
    return 0


if __name__ == "__main__":
    sys.exit(main())
