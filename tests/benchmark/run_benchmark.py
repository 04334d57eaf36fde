#!/usr/bin/env python3
"""Benchmark: run time against error of the Vertex BRDF fit (tests/benchmark/RESULTS.md).

  run_benchmark.py --bench <build>/tests/benchmark/vbrdf_bench --synth <build>/tests/tools/synthesize_scene
                   --work DIR --out DIR [--smoke] [--only SUBSTRING]

Runs a grid of configurations with vbrdf_bench (the filter's pipeline without MeshLab, GL through
OSMesa = llvmpipe here) and writes into --out:
  results.csv              one row per configuration: wall time per stage and errors
  time_vs_error.png        the synthetic 100k-vertex scene: total time against held-out relit
                           CIEDE2000, Pareto front marked
  time_vs_error_scenes.png the shared scenes and sample projects, one front per scene
  summary.md               tables and the figures RESULTS.md quotes (knee, defaults, scaling)

Grid (a one-factor-at-a-time design around a reference, not the full product: that would take
hours on 2 cores). Reference: synthetic scene, mesh decimated to 100k vertices, 32 photos,
iteration cap 20. Around it: back end {gpu, cpu} x iteration cap {1,2,5,10,20,50,400}; photos
{4,8,16,32} x back end; mesh {10k, 100k, full = 300k} x back end; CPU visibility once. Synthetic
configurations run three times, in rounds over the whole grid, and keep the fastest run. Shared
scenes (16-bit linear photos, no colour cast) and the sample projects: photos {4,8,16,all}, caps
{1,5,20,50,400}, GPU at the defaults, mesh decimated to 10k. Every configuration is scored on the
held-out lights (photos never used by the fit).

Data (synthetic scene, decimated meshes) is generated once into --work and reused.
Standard library only.
"""
import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys
import time

sys.dont_write_bytecode = True

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
SHARED = os.environ.get("VBRDF_SHARED_DIR", os.path.normpath(os.path.join(REPO, "..", "shared")))

CAPS = [1, 2, 5, 10, 20, 50, 400]
REFERENCE_CAP = 20  # the filter's default when RESULTS.md was measured (the knee, 50, is in CAPS)
SYNTH_ARGS = ["--vertices", "300000", "--width", "1024", "--height", "768", "--lights", "32", "--heldout", "8"]
SMOKE_SYNTH_ARGS = ["--size", "tiny", "--width", "320", "--height", "240", "--lights", "6", "--heldout", "2"]
SHARED_SCENES = ["spot_dir24", "bunny_two_materials_dir32", "teapot_dir16", "teapot_point16"]
SAMPLE_PROJECTS = ["synth_basic", "synth_two_views", "synth_linear16"]

CSV_COLUMNS = ["scene", "axis", "mesh", "vertices", "photos", "backend", "iterations",
               "t_init", "t_prepare", "t_visibility", "t_gather", "t_fit", "t_output", "t_total",
               "t_total_max", "relit_mean", "relit_median", "relit_p95", "relit_psnr", "relit_pixels",
               "ws_mean", "ws_p95", "ws_unmodelled_vertices", "ptm_mean", "ptm_p95", "rbf_mean", "rbf_p95",
               "rho_de_mean", "rho_de_p95", "coverage",
               "ks_rel_median", "alpha_rel_median", "glossy_determined", "full_fits", "converged",
               "alpha_iterations", "samples", "repeats", "pareto"]


class Project:
    """One capture: training project, held-out project, ground truth and mesh variants."""

    def __init__(self, name, mlp, heldout, gt=None, photo_dir="", heldout_photo_dir="", factors="",
                 meshes=None, photos=0):
        self.name, self.mlp, self.heldout, self.gt = name, mlp, heldout, gt
        self.photo_dir, self.heldout_photo_dir, self.factors = photo_dir, heldout_photo_dir, factors
        self.meshes = meshes or {"full": ""}  # label -> mesh path ("" = the project's own)
        self.photos = photos                  # number of training photos


def log(msg):
    print(msg, flush=True)


def run(cmd, quiet=True):
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"command failed ({proc.returncode}): {' '.join(cmd)}\n{proc.stdout[-3000:]}")
    if not quiet:
        log(proc.stdout.strip())
    return proc.stdout


def count_rasters(mlp):
    with open(mlp, encoding="utf-8") as f:
        return f.read().count("<MLRaster")


def mlp_vertices(ply):
    with open(ply, "rb") as f:
        for raw in f:
            line = raw.decode("ascii", "replace").strip()
            if line.startswith("element vertex"):
                return int(line.split()[2])
            if line == "end_header":
                break
    return 0


# ---------------------------------------------------------------------------------------------
# Data

def synthesize(tools, out, args):
    """Renders a synthetic project once; a stamp with the options makes later runs reuse it."""
    stamp = os.path.join(out, ".bench_stamp")
    want = " ".join(args)
    if os.path.isfile(stamp) and open(stamp, encoding="utf-8").read() == want:
        return
    log(f"synthesizing {out} ({want}) ...")
    start = time.time()
    run([tools.synth, "--quiet", "--out", out] + args)
    with open(stamp, "w", encoding="utf-8") as f:
        f.write(want)
    log(f"  done in {time.time() - start:.0f} s")


def decimated(tools, mesh, out, vertices):
    if not os.path.isfile(out) or os.path.getmtime(out) < os.path.getmtime(mesh):
        os.makedirs(os.path.dirname(out), exist_ok=True)
        log(f"decimating {mesh} to {vertices} vertices ...")
        log("  " + run([tools.bench, "decimate", "--in", mesh, "--out", out, "--vertices", str(vertices)]).strip())
    return out


def synthetic_project(tools, work, smoke):
    out = os.path.join(work, "data", "synth_tiny" if smoke else "synth_300k")
    synthesize(tools, out, SMOKE_SYNTH_ARGS if smoke else SYNTH_ARGS)
    mesh = os.path.join(out, "mesh.ply")
    if smoke:
        meshes = {"full": "", "1k": decimated(tools, mesh, os.path.join(out, "mesh_1k.ply"), 1000)}
    else:
        meshes = {"full": "", "100k": decimated(tools, mesh, os.path.join(out, "mesh_100k.ply"), 100000),
                  "10k": decimated(tools, mesh, os.path.join(out, "mesh_10k.ply"), 10000)}
    return Project("synthetic", os.path.join(out, "project.mlp"), os.path.join(out, "heldout", "project.mlp"),
                   gt=os.path.join(out, "ground_truth", "gt_vertex.ply"), meshes=meshes,
                   photos=count_rasters(os.path.join(out, "project.mlp")))


def shared_project(tools, work, name):
    src = os.path.join(SHARED, "scenes", name)
    if not os.path.isfile(os.path.join(src, "project.mlp")):
        log(f"{name}: not found under {SHARED}/scenes, skipped")
        return None
    # The Lambertian-equivalent albedo of a coated material is albedo * diffuse_factor_normal.
    with open(os.path.join(src, "gt_scene.json"), encoding="utf-8") as f:
        factors = ",".join(str(m.get("diffuse_factor_normal", 1.0)) for m in json.load(f)["materials"])
    mesh10k = decimated(tools, os.path.join(src, "mesh.ply"), os.path.join(work, "data", name, "mesh_10k.ply"), 10000)
    return Project(name, os.path.join(src, "project.mlp"), os.path.join(src, "heldout", "project.mlp"),
                   gt=os.path.join(src, "gt_vertex.ply"), photo_dir=os.path.join(src, "linear"),
                   heldout_photo_dir=os.path.join(src, "heldout", "linear"), factors=factors,
                   meshes={"full": "", "10k": mesh10k}, photos=count_rasters(os.path.join(src, "project.mlp")))


def sample_project(name):
    src = os.path.join(REPO, "sample_projects", name)
    return Project(name, os.path.join(src, "project.mlp"), os.path.join(src, "heldout", "project.mlp"),
                   gt=os.path.join(src, "ground_truth", "gt_vertex.ply"),
                   photos=count_rasters(os.path.join(src, "project.mlp")))


# ---------------------------------------------------------------------------------------------
# Grid

class Config:
    def __init__(self, project, axis, mesh="full", backend="gpu", iterations=REFERENCE_CAP, photos=0, repeat=1):
        self.project, self.axis, self.mesh, self.backend = project, axis, mesh, backend
        self.iterations, self.photos, self.repeat = iterations, photos, repeat

    def key(self):
        return (self.project.name, self.mesh, self.backend, self.iterations, self.photos or self.project.photos)


def reference_grid(p, ref_mesh, photo_counts, caps, meshes, repeat, reference_repeat):
    g = []
    for backend in ("gpu", "cpu"):
        for cap in caps:
            g.append(Config(p, "iterations", ref_mesh, backend, cap, 0,
                            reference_repeat if cap == REFERENCE_CAP else repeat))
        for n in photo_counts:
            g.append(Config(p, "photos", ref_mesh, backend, REFERENCE_CAP, n, repeat))
        for m in meshes:
            g.append(Config(p, "mesh", m, backend, REFERENCE_CAP, 0, repeat))
    return g


def scene_grid(p, photo_counts, caps):
    g = [Config(p, "photos", "full", "cpu", REFERENCE_CAP, n) for n in photo_counts if n < p.photos]
    g += [Config(p, "iterations", "full", "cpu", c, 0) for c in caps]
    g.append(Config(p, "backend", "full", "gpu", REFERENCE_CAP, 0))
    if "10k" in p.meshes:
        g.append(Config(p, "mesh", "10k", "cpu", REFERENCE_CAP, 0))
    return g


def build_grid(tools, work, smoke):
    synth = synthetic_project(tools, work, smoke)
    if smoke:
        return reference_grid(synth, "full", [3], [1, REFERENCE_CAP], ["1k"], 1, 2)
    grid = reference_grid(synth, "100k", [4, 8, 16], CAPS, ["10k", "full"], 3, 3)
    grid.append(Config(synth, "backend", "100k", "cpu-all", REFERENCE_CAP, 0, 2))
    for name in SHARED_SCENES:
        p = shared_project(tools, work, name)
        if p:
            grid += scene_grid(p, [4, 8, 16], [1, 5, REFERENCE_CAP, 50, 400])
    for name in SAMPLE_PROJECTS:
        grid += scene_grid(sample_project(name), [4, 8], [1, REFERENCE_CAP, 400])
    return grid


def run_once(tools, work, c, evaluate):
    """One run; `evaluate` False skips the error measurements (repeats only re-measure time)."""
    p = c.project
    cmd = [tools.bench, "fit", "--project", p.mlp, "--backend", c.backend, "--iterations", str(c.iterations),
           "--photos", str(c.photos), "--work", os.path.join(work, "runs", p.name), "--name", p.name]
    options = [("--mesh", p.meshes[c.mesh]), ("--photo-dir", p.photo_dir)]
    if evaluate:
        options += [("--heldout", p.heldout), ("--gt", p.gt), ("--heldout-photo-dir", p.heldout_photo_dir),
                    ("--albedo-factors", p.factors)]
    for flag, value in options:
        if value:
            cmd += [flag, value]
    out = run(cmd)
    line = next(l for l in out.splitlines() if l.startswith("RESULT "))
    return json.loads(line[len("RESULT "):])


def run_grid(tools, work, configs):
    """Runs every configuration `repeat` times, in rounds (round k runs every configuration that
    wants k+1 runs), so that the repeats of one configuration fall at different times. Keeps the
    fastest run: other jobs on the shared machine only ever add time (the errors are the same in
    every run; the slowest total is kept as t_total_max)."""
    runs = [[] for _ in configs]
    total = sum(c.repeat for c in configs)
    done = 0
    for round_index in range(max(c.repeat for c in configs)):
        for i, c in enumerate(configs):
            if c.repeat <= round_index:
                continue
            runs[i].append(run_once(tools, work, c, evaluate=round_index == 0))
            done += 1
            r = runs[i][-1]
            errors = f"relit dE {r['relit_mean']:.3f} / p95 {r['relit_p95']:.2f}" if round_index == 0 else "(timing)"
            log(f"[{done}/{total}] {c.project.name:26s} {c.backend} it{c.iterations} p{r['photos']} {c.mesh:5s} "
                f"total {r['t_total']:7.2f} s (fit {r['t_fit']:.2f}) {errors}")
    rows = []
    for c, results in zip(configs, runs):
        row = dict(results[0])  # errors from the first (evaluated) run
        fastest = min(results, key=lambda r: r["t_total"])
        row.update({k: v for k, v in fastest.items() if k.startswith("t_") and k != "t_eval"})
        row.update(scene=c.project.name, axis=c.axis, mesh=c.mesh, repeats=c.repeat,
                   t_total_max=max(r["t_total"] for r in results))
        rows.append(row)
    return rows


# ---------------------------------------------------------------------------------------------
# Analysis

def pareto(rows, x="t_total", y="relit_mean", resolution=0.005):
    """Marks rows not dominated in (time, error): no faster row is as good. Errors closer than
    `resolution` (relative, at least 0.005 CIEDE2000) count as equal."""
    ordered = sorted(rows, key=lambda r: (r[x], r[y]))
    best = math.inf
    for r in ordered:
        r["pareto"] = 1 if best == math.inf or r[y] < best - max(0.005, resolution * best) else 0
        best = min(best, r[y])


def short(r):
    return f"{r['backend']} it{r['iterations']} p{r['photos']} {r['mesh']}"


def write_csv(rows, path):
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=CSV_COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{r[k]:.6g}" if isinstance(r.get(k), float) else r.get(k, "")) for k in CSV_COLUMNS})


def read_csv(path):
    """Rows of a results.csv with numbers as numbers."""
    def value(v):
        try:
            return int(v)
        except ValueError:
            try:
                return float(v)
            except ValueError:
                return v
    with open(path, encoding="utf-8") as f:
        return [{k: value(v) for k, v in r.items()} for r in csv.DictReader(f)]


def plot(tools, rows, path, title, series, group, labels):
    points = path + ".points.csv"
    with open(points, "w", encoding="utf-8") as f:
        f.write("series,x,y,front,label,group\n")
        for r in rows:
            label = short(r) if labels and r["pareto"] else ""
            f.write(f"{series(r)},{r['t_total']},{r['relit_mean']},{r['pareto']},{label},{group(r)}\n")
    run([tools.bench, "plot", "--points", points, "--out", path, "--title", title,
         "--x-label", "total wall time (s, log scale)", "--y-label", "held-out relit CIEDE2000, mean"])
    os.remove(points)


def loglog_slope(pairs):
    """Least-squares exponent b of t = a n^b."""
    pts = [(math.log(n), math.log(t)) for n, t in pairs if n > 0 and t > 0]
    if len(pts) < 2:
        return float("nan")
    mx = statistics.mean(p[0] for p in pts)
    my = statistics.mean(p[1] for p in pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx if sxx > 0 else float("nan")


def knee(rows, tolerance=0.02):
    """Smallest cap whose relit mean CIEDE2000 is within `tolerance` (relative) of the best cap's:
    beyond it more iterations buy less than 2 % of error."""
    rows = sorted(rows, key=lambda r: r["iterations"])
    if not rows:
        return None
    target = min(r["relit_mean"] for r in rows) * (1 + tolerance)
    return next(r for r in rows if r["relit_mean"] <= target)


STAGES = ["t_init", "t_prepare", "t_visibility", "t_gather", "t_fit", "t_output", "t_total"]


def table(rows, columns, headers):
    out = ["| " + " | ".join(headers) + " |", "|" + "|".join("---:" for _ in headers) + "|"]
    for r in rows:
        cells = []
        for c in columns:
            v = r.get(c, "")
            cells.append(f"{v:.3g}" if isinstance(v, float) else str(v))
        out.append("| " + " | ".join(cells) + " |")
    return "\n".join(out)


def summary(rows, smoke):
    ref_mesh = "full" if smoke else "100k"
    synth = [r for r in rows if r["scene"] == "synthetic"]
    lines = ["# Benchmark summary (generated by run_benchmark.py)", ""]
    ref = [r for r in synth if r["mesh"] == ref_mesh and r["photos"] == max(x["photos"] for x in synth)]
    for backend in ("gpu", "cpu"):
        sweep = sorted((r for r in ref if r["backend"] == backend and r["axis"] == "iterations"),
                       key=lambda r: r["iterations"])
        if not sweep:
            continue
        lines += [f"## Synthetic, {ref_mesh} vertices x {sweep[0]['photos']} photos, {backend}: iteration cap", "",
                  table(sweep, ["iterations"] + STAGES + ["relit_mean", "relit_p95", "relit_psnr", "rho_de_mean",
                                                          "ks_rel_median", "alpha_rel_median", "pareto"],
                        ["cap", "init", "prepare", "visibility", "gather", "fit", "output", "total s",
                         "relit dE mean", "relit dE p95", "PSNR dB", "rho dE", "k_s rel", "alpha rel", "front"]), ""]
        k = knee(sweep)
        if k:
            best = min(sweep, key=lambda r: r["relit_mean"])
            lines.append(f"knee ({backend}): cap {k['iterations']} (relit mean {k['relit_mean']:.3f}; best: cap "
                         f"{best['iterations']}, {best['relit_mean']:.3f}; fit stage {k['t_fit']:.2f} s, "
                         f"total {k['t_total']:.2f} s)")
            lines.append("")
    for axis, key, label in (("photos", "photos", "photos"), ("mesh", "vertices", "vertices")):
        part = sorted((r for r in synth if r["axis"] in (axis, "iterations") and r["iterations"] == REFERENCE_CAP
                       and (axis == "mesh" or r["mesh"] == ref_mesh)
                       and (axis == "photos" or r["photos"] == max(x["photos"] for x in synth))),
                      key=lambda r: (r["backend"], r[key]))
        seen, uniq = set(), []
        for r in part:
            if (r["backend"], r[key]) not in seen:
                seen.add((r["backend"], r[key]))
                uniq.append(r)
        if not uniq:
            continue
        lines += [f"## Synthetic: scaling with {label} (cap {REFERENCE_CAP})", "",
                  table(uniq, ["backend", "vertices", "photos"] + STAGES + ["relit_mean", "relit_p95", "rho_de_mean"],
                        ["back end", "vertices", "photos", "init", "prepare", "visibility", "gather", "fit",
                         "output", "total s", "relit dE mean", "relit dE p95", "rho dE"]), ""]
        for backend in ("gpu", "cpu"):
            pairs = [(r[key], r["t_total"]) for r in uniq if r["backend"] == backend]
            fit_pairs = [(r[key], r["t_fit"]) for r in uniq if r["backend"] == backend]
            if len(pairs) >= 2:
                lines.append(f"- {backend}: total time ~ {label}^{loglog_slope(pairs):.2f}, "
                             f"fit stage ~ {label}^{loglog_slope(fit_pairs):.2f}")
        lines.append("")
    others = [r for r in rows if r["scene"] != "synthetic"]
    if others:
        lines += ["## Shared scenes and sample projects", "",
                  table(sorted(others, key=lambda r: (r["scene"], r["axis"], r["backend"], r["photos"], r["iterations"])),
                        ["scene", "axis", "mesh", "vertices", "photos", "backend", "iterations", "t_total", "t_fit",
                         "relit_mean", "relit_p95", "ws_mean", "ws_p95", "ptm_mean", "ptm_p95", "rbf_mean",
                         "rbf_p95", "rho_de_mean", "coverage", "pareto"],
                        ["scene", "axis", "mesh", "vertices", "photos", "back end", "cap", "total s", "fit s",
                         "relit dE mean (interior)", "p95", "whole surface mean", "p95", "PTM mean", "p95",
                         "RBF mean", "p95", "rho dE", "coverage", "front"]), "",
                  "relit dE (interior): image space, lit interior pixels only (silhouettes and depth jumps left "
                  "out). whole surface: every seen, lit, unsaturated vertex at its pixel (RTI protocol, "
                  "vertices without a model black), beside per-pixel PTM and Relight-style RBF on the same "
                  "samples (vbrdf_eval; tests/benchmark/whole_surface_eval.sh).", ""]
    rest = [r for r in synth if r["axis"] == "backend"]
    if rest:
        lines += ["## Synthetic: CPU visibility (ray cast) + CPU fit", "",
                  table(rest, ["backend", "vertices", "photos"] + STAGES + ["relit_mean"],
                        ["back end", "vertices", "photos", "init", "prepare", "visibility", "gather", "fit", "output",
                         "total s", "relit dE mean"]), ""]
    return "\n".join(lines) + "\n"


def check_rows(rows):
    """Smoke checks: every configuration produced finite times and errors."""
    failures = []
    for r in rows:
        for k in ("t_total", "t_fit", "relit_mean", "relit_p95", "rho_de_mean"):
            v = r.get(k)
            if not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
                failures.append(f"{short(r)}: {k} = {v}")
        if r.get("relit_pixels", 0) <= 0:
            failures.append(f"{short(r)}: no held-out pixel compared")
    return failures


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bench", required=True, help="vbrdf_bench executable")
    ap.add_argument("--synth", required=True, help="synthesize_scene executable")
    ap.add_argument("--work", required=True, help="scratch folder (generated data is reused)")
    ap.add_argument("--out", required=True, help="folder for results.csv, plots, summary.md")
    ap.add_argument("--smoke", action="store_true", help="tiny grid for ctest")
    ap.add_argument("--only", default="", help="run only configurations of scenes containing this text")
    ap.add_argument("--from-csv", default="", help="no runs: redo the plots and summary.md from a results.csv")
    a = ap.parse_args(argv)
    a.work, a.out = os.path.abspath(a.work), os.path.abspath(a.out)
    os.makedirs(a.out, exist_ok=True)
    start = time.time()
    if a.from_csv:
        rows = read_csv(a.from_csv)
    else:
        grid = build_grid(a, a.work, a.smoke)
        grid = [c for c in grid if a.only in c.project.name]
        seen, unique = set(), []
        for c in grid:  # the reference configuration appears on several axes
            if c.key() not in seen:
                seen.add(c.key())
                unique.append(c)
        log(f"{len(unique)} configurations (data ready after {time.time() - start:.0f} s)")
        rows = run_grid(a, a.work, unique)
    for scene in {r["scene"] for r in rows}:
        pareto([r for r in rows if r["scene"] == scene])
    write_csv(rows, os.path.join(a.out, "results.csv"))  # with --from-csv: the Pareto column redone
    synth = [r for r in rows if r["scene"] == "synthetic"]
    if synth:
        plot(a, synth, os.path.join(a.out, "time_vs_error.png"),
             "Synthetic scene (1024x768, 8 held-out lights): time vs relit error",
             lambda r: f"{r['backend']} {r['axis']}", lambda r: "all", labels=True)
    others = [r for r in rows if r["scene"] != "synthetic"]
    if others:
        plot(a, others, os.path.join(a.out, "time_vs_error_scenes.png"),
             "Shared scenes and sample projects: time vs held-out relit error (front per scene)",
             lambda r: r["scene"], lambda r: r["scene"], labels=False)
    with open(os.path.join(a.out, "summary.md"), "w", encoding="utf-8") as f:
        f.write(summary(rows, a.smoke))
    log(f"wrote {a.out}/results.csv, summary.md and plots; {len(rows)} configurations in {time.time() - start:.0f} s")
    failures = check_rows(rows)
    for msg in failures:
        log("FAIL: " + msg)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
