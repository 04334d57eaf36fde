#!/usr/bin/env python3
"""End-to-end check of "Vertex BRDF: relight and compare" in Debian's meshlabserver: one script fits
a project (its fit.mlx) and relights the fit on the held-out photos (relight.mlx, rasterProject =
heldout/project.mlp) plus a novel view; then checks the written images and table, the bound on the
pooled held-out CIEDE2000, and that the project folder was not modified.

  relight_filter_check.py --wrapper <build>/meshlab_run/run_meshlabserver.sh --project P.mlp --work DIR
                          [--max-mean-de X] [--color-correction 0|1|2]
Standard library only.
"""
import argparse
import csv
import hashlib
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

sys.dont_write_bytecode = True
HERE = os.path.dirname(os.path.abspath(__file__))


def checksums(root):
    out = {}
    for dirpath, _, files in os.walk(root):
        for name in files:
            path = os.path.join(dirpath, name)
            with open(path, "rb") as f:
                out[os.path.relpath(path, root)] = hashlib.sha256(f.read()).hexdigest()
    return out


def set_params(filter_node, values):
    for p in filter_node.iter("Param"):
        if p.get("name") in values:
            for attr, v in values.pop(p.get("name")).items():
                p.set(attr, v)
    if values:
        raise KeyError(f"no such parameters: {sorted(values)}")


def script(project_dir, work, color_correction):
    fit = ET.parse(os.path.join(project_dir, "fit.mlx")).getroot().find("filter")
    relight = ET.parse(os.path.join(HERE, "relight.mlx")).getroot().find("filter")
    set_params(fit, {"outputPly": {"value": os.path.join(work, "fit.ply")}})
    if color_correction is not None:
        set_params(fit, {"colorCorrection": {"value": str(color_correction)}})
    # The relighting corrects the compared photos' colours as the fit corrected its samples.
    same = {p.get("name"): {"value": p.get("value")} for p in fit.iter("Param")
            if p.get("name") in ("colorCorrection", "chartCorners", "exposureNormalisation")}
    set_params(relight, same)
    set_params(relight, {"rasterProject": {"value": "heldout/project.mlp"},
                         "outputFolder": {"value": os.path.join(work, "relight")},
                         "novelView": {"value": "true"}, "orbitAzimuth": {"value": "35"},
                         "orbitElevation": {"value": "10"},
                         "novelLight": {"x": "-0.4", "y": "0.6", "z": "0.7"}})
    root = ET.Element("FilterScript")
    root.extend([fit, relight])
    path = os.path.join(work, "fit_relight.mlx")
    with open(path, "w", encoding="utf-8") as f:
        f.write("<!DOCTYPE FilterScript>\n" + ET.tostring(root, encoding="unicode") + "\n")
    return path


def check_without_fit(a, project_dir):
    """Relighting a mesh that was never fitted fails with a message saying what to run first."""
    relight = ET.parse(os.path.join(HERE, "relight.mlx")).getroot()
    out = os.path.join(a.work, "no_fit")
    set_params(relight.find("filter"), {"outputFolder": {"value": out}})
    mlx = os.path.join(a.work, "relight_only.mlx")
    with open(mlx, "w", encoding="utf-8") as f:
        f.write("<!DOCTYPE FilterScript>\n" + ET.tostring(relight, encoding="unicode") + "\n")
    proc = subprocess.run([a.wrapper, "-p", os.path.abspath(a.project), "-s", mlx], stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, timeout=600)
    log = proc.stdout.decode("utf-8", "replace")
    failures = []
    if proc.returncode == 0:
        failures.append("relighting an unfitted mesh did not fail")
    for text in ("Vertex BRDF: relight and compare failed:", "has no per-vertex 'kd'", "fit per-vertex reflectance"):
        if text not in log:
            failures.append(f"the failure message lacks {text!r}")
    if os.path.exists(out):
        failures.append(f"{out} was created although the filter failed")
    print("unfitted mesh:", "ok" if not failures else "FAILED")
    return failures


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--wrapper", required=True)
    ap.add_argument("--project", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--max-mean-de", type=float, default=1.5)
    ap.add_argument("--color-correction", type=int, choices=(0, 1, 2),
                    help="colorCorrection of the fit (and so of the relighting); default: the project's fit.mlx")
    a = ap.parse_args(argv)
    a.work = os.path.abspath(a.work)  # meshlabserver resolves relative paths against the project folder
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)
    project_dir = os.path.dirname(os.path.abspath(a.project))
    before = checksums(project_dir)
    mlx = script(project_dir, a.work, a.color_correction)
    proc = subprocess.run([a.wrapper, "-p", os.path.abspath(a.project), "-s", mlx], stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, timeout=600)
    log = proc.stdout.decode("utf-8", "replace")
    with open(os.path.join(a.work, "meshlabserver.log"), "w", encoding="utf-8") as f:
        f.write(log)
    failures = [] if proc.returncode == 0 else [f"meshlabserver exit status {proc.returncode}"]
    out = os.path.join(a.work, "relight")
    heldout = ET.parse(os.path.join(project_dir, "heldout", "project.mlp")).getroot()
    expected = ["contact_sheet.png", "relight_table.csv", "novel_view.png"]
    expected += [f"relight_{i:03d}_" for i, _ in enumerate(heldout.iter("MLRaster"))]
    names = os.listdir(out) if os.path.isdir(out) else []
    for e in expected:
        if not any(n.startswith(e) for n in names):
            failures.append(f"missing output {e}* in {out}")
    table = os.path.join(out, "relight_table.csv")
    if os.path.isfile(table):
        rows = list(csv.DictReader(open(table, encoding="utf-8")))
        overall = rows[-1] if rows else {}
        print("relight table:", *[f"{r['raster']}: {r['mean_de2000']} / p95 {r['p95_de2000']}" for r in rows], sep="\n  ")
        if overall.get("raster") != "all" or int(overall.get("pixels", 0)) <= 0:
            failures.append("the table has no pooled 'all' row with compared pixels")
        elif float(overall["mean_de2000"]) > a.max_mean_de:
            failures.append(f"held-out CIEDE2000 mean {overall['mean_de2000']} > {a.max_mean_de}")
    failures += check_without_fit(a, project_dir)
    if checksums(project_dir) != before:
        failures.append(f"the project folder {project_dir} was modified")
    for f in failures:
        print("FAIL:", f)
    if failures:
        print(log[-4000:])
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
