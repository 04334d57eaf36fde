#!/usr/bin/env python3
"""End-to-end benchmark through meshlabserver: wall time, peak memory, stage times and
errors of the fit filter at its defaults, on synthetic captures made by synthesize_scene.

  run_e2e_benchmark.py --wrapper <build>/meshlab_run/run_meshlabserver.sh
                       --synth <build>/tests/tools/synthesize_scene --work DIR
                       [--cases 100k,1m] [--repeats N] [--baseline-wrapper OTHER.sh [--baseline-mlx OLD.mlx]]
                       [--out FILE.md]

Cases (scenes generated once into --work and reused):
  100k  100 k vertices x 32 photos, 1024x768 (4 held-out photos)
  1m    1 M vertices x 24 photos, 4000x3000 (the large case: ~2.4 GB of data, ~20 min to render
        on 2 cores, minutes per run; never part of the default ctest: target run_benchmark_large)
  smoke 2 k vertices x 6 photos, 320x240 (ctest bench_e2e_smoke: the script itself works)
Each run: `/usr/bin/time -v <wrapper> -p project.mlp -s fit.mlx` (wall time and maximum
resident set size of the process tree), the filter's report (stage times: visibility, samples,
fit; the depth passes' sizes), and errors against the scene's ground truth over the vertices the
fit modelled:
  rho   CIEDE2000 between k_d C and the albedo, after one least-squares global scale (mean)
  ks    median relative error of k_s, alpha: of the shininess (N.H exponent / 4 against the
        truth's R.E exponent), over full fits of glossy vertices (GT k_s > 0.2, >= 2 clean
        highlight samples: as vbrdf_bench counts them)
With --baseline-wrapper (another build's wrapper, e.g. main's), every case also runs there, runs
alternate between the two (the machine is shared: ratios of the same session are the measure),
and the outputs are compared vertex by vertex (vertices modelled by one only, k_d difference).
--baseline-mlx: the fit script template for the baseline build (default: this checkout's
sample_projects/synth_basic/fit.mlx). meshlabserver 2020.09 refuses a script listing a parameter its
filter does not have, so a build from before a new parameter needs its own, e.g.
`git show <rev>:sample_projects/synth_basic/fit.mlx > old.mlx`.
The fastest of --repeats runs is reported; the slowest is kept beside it.
Needs numpy (tests/e2e/e2e_lib.py reads the PLY files).
"""
import argparse
import os
import re
import subprocess
import sys
import time

sys.dont_write_bytecode = True
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "e2e"))
import numpy as np  # noqa: E402
import e2e_lib  # noqa: E402

REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
FIT_MLX = os.path.join(REPO, "sample_projects", "synth_basic", "fit.mlx")
CASES = {
    "100k": ["--vertices", "100000", "--width", "1024", "--height", "768", "--lights", "32", "--heldout", "4"],
    "1m": ["--vertices", "1000000", "--width", "4000", "--height", "3000", "--lights", "24", "--heldout", "0"],
    "smoke": ["--size", "tiny", "--width", "320", "--height", "240", "--lights", "6", "--heldout", "0"],
}


def log(msg):
    print(msg, flush=True)


def make_scene(synth, work, case):
    out = os.path.join(work, "scene_" + case)
    if not os.path.exists(os.path.join(out, "project.mlp")):
        log(f"[{case}] rendering the scene (once) into {out}")
        subprocess.run([synth, "--out", out, "--ss", "1", "--quiet"] + CASES[case], check=True)
    return out


def write_mlx(path, output_ply, template=FIT_MLX):
    text = open(template).read()
    text, n = re.subn(r'(name="outputPly" type="RichString" value=")[^"]*"', r'\g<1>' + output_ply + '"', text)
    if n != 1:
        raise RuntimeError(f"{template}: no outputPly parameter")
    with open(path, "w") as f:
        f.write(text)


def parse_time_v(text):
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", text).group(1)
    parts = [float(p) for p in wall.split(":")]
    seconds = sum(p * 60 ** (len(parts) - 1 - i) for i, p in enumerate(parts))
    rss_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", text).group(1))
    return seconds, rss_kb / 1024.0 / 1024.0


def parse_report(path):
    text = open(path).read()
    m = re.search(r"time: visibility ([\d.]+) s, samples ([\d.]+) s, fit ([\d.]+) s", text)
    stages = {"visibility": float(m.group(1)), "samples": float(m.group(2)), "fit": float(m.group(3))} if m else {}
    m = re.search(r"depth passes: (.*)", text)
    stages["passes"] = m.group(1).strip() if m else ""
    return stages


def run_once(wrapper, scene, work, label, template=FIT_MLX):
    ply = os.path.join(work, f"{label}.ply")
    mlx = os.path.join(work, f"{label}.mlx")
    write_mlx(mlx, ply, template)
    cmd = ["/usr/bin/time", "-v", wrapper, "-p", os.path.join(scene, "project.mlp"), "-s", mlx]
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    with open(os.path.join(work, f"{label}.log"), "w") as f:
        f.write(proc.stdout)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}); see {work}/{label}.log")
    wall, rss = parse_time_v(proc.stdout)
    row = {"wall": wall, "rss_gb": rss, "ply": ply}
    row.update(parse_report(ply[:-4] + "_report.txt"))
    return row


def errors(ply_path, scene):
    out = e2e_lib.read_ply(ply_path).vertex
    gt = e2e_lib.read_ply(os.path.join(scene, "ground_truth", "gt_vertex.ply")).vertex
    modelled = (out["kd"] > 0) & (gt["visible_any"] > 0)
    rho = np.stack([out["kd"] * out["color_" + c] for c in "rgb"], axis=1)[modelled]
    alb = np.stack([gt["albedo_" + c] for c in "rgb"], axis=1)[modelled]
    scale = float((rho * alb).sum() / max((rho * rho).sum(), 1e-12))
    de = e2e_lib.ciede2000(e2e_lib.linear_rgb_to_lab(np.clip(rho * scale, 0, None)), e2e_lib.linear_rgb_to_lab(alb))
    # As vbrdf_bench counts them: GT k_s > 0.2, a full fit (k_s > 0) from >= 2 clean highlight samples.
    glossy = modelled & (gt["ks"] > 0.2) & (out["ks"] > 0) & (out["n_specular"] >= 2)
    ks = np.abs(out["ks"][glossy] / gt["ks"][glossy] - 1)
    # The truth's exponent is on R.E; a Blinn-Phong fit (lobe_form 1, the default) has ~4x that on N.H.
    shininess = np.where(out["lobe_form"] == 1, out["shininess"] / 4, out["shininess"])
    alpha = np.abs(shininess[glossy] / gt["shininess"][glossy] - 1)
    return {"modelled": int(modelled.sum()), "rho_de": float(np.mean(de)) if de.size else float("nan"),
            "ks_rel": float(np.median(ks)) if ks.size else float("nan"),
            "alpha_rel": float(np.median(alpha)) if alpha.size else float("nan")}


def compare_outputs(a_path, b_path):
    a, b = e2e_lib.read_ply(a_path).vertex, e2e_lib.read_ply(b_path).vertex
    both = (a["kd"] > 0) & (b["kd"] > 0)
    status_differs = int(((a["kd"] > 0) != (b["kd"] > 0)).sum())
    kd = np.abs(a["kd"][both] - b["kd"][both]) / np.maximum(b["kd"][both], 1e-6)
    return {"status_differs": status_differs, "kd_rel_median": float(np.median(kd)) if kd.size else 0.0,
            "kd_rel_p99": float(np.percentile(kd, 99)) if kd.size else 0.0}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--wrapper", required=True)
    ap.add_argument("--synth", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--cases", default="100k")
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--baseline-wrapper", default="")
    ap.add_argument("--baseline-mlx", default=FIT_MLX, help="fit script template for the baseline build")
    ap.add_argument("--out", default="")
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    builds = [("new", args.wrapper)] + ([("baseline", args.baseline_wrapper)] if args.baseline_wrapper else [])
    lines = ["| case | build | end to end s (slowest) | peak GB | visibility s | samples s | fit s | rho ΔE00 mean "
             "| k_s rel | α rel | modelled | depth passes |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    summary = {}
    for case in args.cases.split(","):
        if case not in CASES:
            sys.exit(f"unknown case {case} (known: {', '.join(CASES)})")
        scene = make_scene(args.synth, args.work, case)
        runs = {name: [] for name, _ in builds}
        for rep in range(args.repeats):
            for name, wrapper in builds:  # alternate: the same load falls on both builds
                row = run_once(wrapper, scene, args.work, f"{case}_{name}_{rep}",
                               args.baseline_mlx if name == "baseline" else FIT_MLX)
                log(f"[{case}] {name} run {rep + 1}: {row['wall']:.2f} s, peak {row['rss_gb']:.2f} GB, "
                    f"visibility {row.get('visibility')} s, samples {row.get('samples')} s, fit {row.get('fit')} s")
                runs[name].append(row)
        for name, _ in builds:
            best = min(runs[name], key=lambda r: r["wall"])
            slowest = max(r["wall"] for r in runs[name])
            e = errors(best["ply"], scene)
            summary[(case, name)] = (best, e)
            lines.append(f"| {case} | {name} | {best['wall']:.2f} ({slowest:.2f}) | {best['rss_gb']:.2f} | "
                         f"{best.get('visibility', float('nan')):.2f} | {best.get('samples', float('nan')):.2f} | "
                         f"{best.get('fit', float('nan')):.2f} | {e['rho_de']:.3f} | {e['ks_rel']:.3f} | "
                         f"{e['alpha_rel']:.3f} | {e['modelled']} | {best.get('passes', '')} |")
        if args.baseline_wrapper:
            new, base = summary[(case, "new")][0], summary[(case, "baseline")][0]
            c = compare_outputs(new["ply"], base["ply"])
            lines.append(f"| {case} | new / baseline | **{new['wall'] / base['wall']:.2f}×** | "
                         f"{new['rss_gb'] / base['rss_gb']:.2f}× | "
                         f"{new.get('visibility', 0) / max(base.get('visibility', 0), 1e-9):.2f}× | | | "
                         f"outputs: {c['status_differs']} vertices modelled in one only; k_d rel. diff. median "
                         f"{c['kd_rel_median']:.2g}, p99 {c['kd_rel_p99']:.2g} | | | | |")
    for (case, name), (best, e) in summary.items():  # a broken run must not pass as a figure
        if not (best["wall"] > 0 and best["rss_gb"] > 0 and e["modelled"] > 0 and e["rho_de"] == e["rho_de"]):
            sys.exit(f"[{case}] {name}: no usable result (time {best['wall']}, modelled {e['modelled']})")
    text = "\n".join(lines) + "\n"
    log(text)
    if args.out:
        with open(args.out, "w") as f:
            f.write(f"<!-- run_e2e_benchmark.py, {time.strftime('%Y-%m-%d %H:%M')} -->\n" + text)


if __name__ == "__main__":
    main()
