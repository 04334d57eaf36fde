#!/usr/bin/env python3
"""End-to-end tests of the acquisition feedback: Debian's meshlabserver runs the built plugin's
"Vertex BRDF: coverage and next light" and "Vertex BRDF: import new photos of a viewpoint".

  run_coverage_e2e.py dump    --wrapper W --mlx coverage.mlx --workdir D
  run_coverage_e2e.py classes --wrapper W --project P.mlp --mlx coverage.mlx --workdir D
                              [--min-agreement X] [--max-class-diff X]
  run_coverage_e2e.py loop    --wrapper W --project DENSE.mlp --mlx coverage.mlx --workdir D
                              --coverage-tool vbrdf_coverage [--max-photos N] [--min-diffuse X] [--min-full X]
  run_coverage_e2e.py sphere  --wrapper W --project P.mlp --mlx coverage.mlx --workdir D [--max-angle DEG]

classes: the classification (vertex colours saved by meshlabserver, counts in the suggestion file)
is compared with an independent computation from the synthetic project's ground truth (camera
visibility, light visibility, normals, lights; no pixels), and the suggested lights must be
placeable. loop: the photographer's loop through meshlabserver on a dense synthetic capture: start
from one photo, read the suggestion file, import the candidate photo nearest to the suggested light
(import filter, lights from the capture's .lp, which lists photos not imported yet), repeat; the
coverage must reach what all candidates together give. sphere: photos imported with lights
estimated from the reflective sphere match the capture's .lp.

Everything is written under --workdir; inputs are only read (checksums compared).
"""
import argparse
import math
import os
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "e2e"))
import numpy as np  # noqa: E402

import e2e_lib as lib  # noqa: E402

COVERAGE = "Vertex BRDF: coverage and next light"
IMPORT = "Vertex BRDF: import new photos of a viewpoint"
CLASS_KEYS = ["unseen", "seen_not_diffuse", "diffuse_no_specular", "fully_covered"]
CLASS_COLOURS = [(128, 0, 128), (40, 90, 220), (240, 200, 0), (40, 180, 60)]  # coverage_class_color


def run_server(wrapper, args, log_path, timeout=900):
    cmd = [wrapper] + args
    print("running:", " ".join(cmd), flush=True)
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=timeout)
    text = proc.stdout.decode("utf-8", "replace")
    lib.write_text(log_path, text)
    if proc.returncode != 0:
        print(text[-5000:])
    return proc.returncode, text


def fresh_dir(path):
    shutil.rmtree(path, ignore_errors=True)
    os.makedirs(path)
    return path


def read_suggestions(path):
    out = {}
    for line in lib.read_text(path).splitlines():
        if line.startswith("#") or ": " not in line:
            continue
        key, _, value = line.partition(": ")
        out[key] = value
    return out


def import_mlx(path, values):
    """A script for the import filter listing every parameter (meshlabserver aborts otherwise)."""
    p = {"photoFiles": "", "photoFolder": "", "referenceRaster": -1, "lightSource": 0, "lightFile": "",
         "sphereCenterX": 0, "sphereCenterY": 0, "sphereRadius": 0, "outputLightFile": "", "updateCoverage": "true"}
    p.update(values)
    text = f"""<!DOCTYPE FilterScript>
<FilterScript>
 <filter name="{IMPORT}">
  <Param name="photoFiles" type="RichString" value="{p['photoFiles']}"/>
  <Param name="photoFolder" type="RichString" value="{p['photoFolder']}"/>
  <Param name="referenceRaster" type="RichInt" value="{p['referenceRaster']}"/>
  <Param name="lightSource" type="RichEnum" value="{p['lightSource']}" enum_cardinality="2" enum_val0="Light file (.lp)" enum_val1="Reflective sphere"/>
  <Param name="lightFile" type="RichOpenFile" value="{p['lightFile']}" exts_cardinality="1" ext_val0="Light positions (*.lp)"/>
  <Param name="sphereCenterX" type="RichFloat" value="{p['sphereCenterX']}"/>
  <Param name="sphereCenterY" type="RichFloat" value="{p['sphereCenterY']}"/>
  <Param name="sphereRadius" type="RichFloat" value="{p['sphereRadius']}"/>
  <Param name="outputLightFile" type="RichString" value="{p['outputLightFile']}"/>
  <Param name="updateCoverage" type="RichBool" value="{p['updateCoverage']}"/>
 </filter>
</FilterScript>
"""
    lib.write_text(path, text)


def project_subset(src, dst, keep, mesh_path=None):
    """Copy of an .mlp with absolute paths keeping only the rasters whose index is in `keep`."""
    lib.rewrite_mlp(src, dst, mesh_path=mesh_path)
    text = lib.read_text(dst)
    blocks = re.findall(r"\s*<MLRaster .*?</MLRaster>", text, flags=re.S)
    for i, b in enumerate(blocks):
        if i not in keep:
            text = text.replace(b, "", 1)
    lib.write_text(dst, text)


def own_mesh_copy(src_mlp, work):
    """meshlabserver -w also saves the mesh (as <mesh>_out.ply beside it): give the copies their
    own mesh in the work folder, so that nothing is written beside the inputs."""
    mesh = os.path.join(work, "mesh.ply")
    root = ET.parse(src_mlp).getroot()
    name = root.find("./MeshGroup/MLMesh").get("filename")
    shutil.copyfile(os.path.join(os.path.dirname(os.path.abspath(src_mlp)), name), mesh)
    return mesh


def pin_mesh(mlp, mesh):
    """Points a saved project back at `mesh` and removes meshlabserver's _out copies."""
    lib.rewrite_mlp(mlp, mlp, mesh_path=mesh)
    for f in os.listdir(os.path.dirname(mesh)):
        if f.startswith("mesh_out") and f.endswith(".ply"):
            os.remove(os.path.join(os.path.dirname(mesh), f))


def rasters_of(mlp):
    """[(label, photo path, camera centre)] of an .mlp (absolute photo paths)."""
    base = os.path.dirname(os.path.abspath(mlp))
    out = []
    for r in ET.parse(mlp).getroot().iter("MLRaster"):
        cam = r.find("VCGCamera")
        t = [float(x) for x in cam.get("TranslationVector").split()]
        out.append((r.get("label"), os.path.normpath(os.path.join(base, r.find("Plane").get("fileName"))),
                    -np.array(t[:3])))
    return out


# ---------------------------------------------------------------------------------------------

def cmd_dump(a):
    work = fresh_dir(a.workdir)
    dump = os.path.join(work, "filters.txt")
    rc, log = run_server(a.wrapper, ["-d", dump], os.path.join(work, "meshlabserver.log"))
    text = lib.read_text(dump) if os.path.isfile(dump) else ""
    failures = [] if rc == 0 else [f"meshlabserver exit status {rc}"]
    imp = os.path.join(work, "import.mlx")
    import_mlx(imp, {})
    for name, mlx in ((COVERAGE, a.mlx), (IMPORT, imp)):
        section = text[text.find(name):] if name in text else ""
        section = section[:section.find("\\section")] if "\\section" in section else section
        expected = len(list(ET.parse(mlx).getroot().iter("Param")))
        rows = section.count("<TR>")
        print(f"{name!r}: {rows} parameters listed, {expected} in {os.path.basename(mlx)}")
        if name not in text:
            failures.append(f"filter {name!r} not listed")
        elif rows != expected:
            failures.append(f"{name!r} lists {rows} parameters, the script has {expected}")
    return report(failures)


def mlx_values(mlx):
    """{parameter name: value string} of a filter script."""
    return {p.get("name"): p.get("value") for p in ET.parse(mlx).getroot().iter("Param")}


def independent_classes(mlp, ts=0.9, td=0.5, min_diffuse=1, min_specular=1):
    """Classes from the synthetic ground truth alone: a photo gives a vertex a diffuse sample when
    the vertex is visible from the photo's view, lit (no shadow), N.L >= T_d and R.E <= T_s; a
    specular sample when visible, lit and R.E > T_s (pixels, saturation and mixed pixels ignored).
    A vertex is diffusely (specularly) covered from min_diffuse (min_specular) samples."""
    base = os.path.dirname(os.path.abspath(mlp))
    gt = np.genfromtxt(os.path.join(base, "ground_truth", "gt_vertex.csv"), delimiter=",", names=True)
    normals = np.stack([gt["nx"], gt["ny"], gt["nz"]], 1)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    pos = np.stack([gt["x"], gt["y"], gt["z"]], 1)
    lit_lines = [l for l in lib.read_text(os.path.join(base, "ground_truth", "gt_lit.txt")).splitlines()
                 if l and not l.startswith("#")]
    lit = np.array([[c == "1" for c in l] for l in lit_lines])
    import json
    lw = json.loads(lib.read_text(os.path.join(base, "lights_world.json")))
    names = [os.path.basename(n) for n in lw["images"]]
    centres = {}
    for label, photo, centre in rasters_of(mlp):
        centres[os.path.basename(photo)] = centre
    diffuse = np.zeros(len(pos), int)
    specular = np.zeros(len(pos), int)
    seen_any = np.zeros(len(pos), bool)
    for j, name in enumerate(names):
        if name not in centres:
            continue
        view = lw["view"][j]
        seen = gt[f"visible_view{view}"] > 0.5
        e = centres[name][None, :] - pos
        e /= np.linalg.norm(e, axis=1, keepdims=True)
        l = np.array(lw["dir_world"][j])
        d = normals @ l
        r = 2 * d[:, None] * normals - l[None, :]
        s = np.sum(r * e, 1)
        ok = seen & lit[:, j] & (d > 0)
        diffuse += ok & (d >= td) & (s <= ts)
        specular += ok & (s > ts)
        seen_any |= seen
    classes = np.where(~seen_any, 0, np.where(diffuse < min_diffuse, 1, np.where(specular < min_specular, 2, 3)))
    return classes


def classes_from_colours(ply_path):
    v = lib.read_ply(ply_path).vertex
    rgb = np.stack([v["red"], v["green"], v["blue"]], 1).astype(int)
    classes = np.full(len(rgb), -1)
    for c, col in enumerate(CLASS_COLOURS):
        classes[np.all(rgb == np.array(col)[None, :], 1)] = c
    return classes


def cmd_classes(a):
    work = fresh_dir(a.workdir)
    src_dir = os.path.dirname(os.path.abspath(a.project))
    before = lib.tree_checksums(src_dir)
    sugg = os.path.join(work, "next_light.txt")
    mlx = os.path.join(work, "coverage.mlx")
    values = dict(kv.split("=", 1) for kv in (a.set or []))
    values["suggestionFile"] = sugg
    lib.write_mlx(a.mlx, mlx, values)
    coloured = os.path.join(work, "coloured.ply")
    rc, log = run_server(a.wrapper, ["-p", os.path.abspath(a.project), "-s", mlx, "-o", coloured, "-m", "vc"],
                         os.path.join(work, "meshlabserver.log"))
    failures = [] if rc == 0 else [f"meshlabserver exit status {rc}"]
    if lib.tree_checksums(src_dir) != before:
        failures.append(f"the project folder {src_dir} was modified")
    for f in (sugg, coloured, os.path.join(work, "next_light_new_view_vertices.txt")):
        if not os.path.isfile(f):
            failures.append(f"missing output {f}")
    if failures:
        return report(failures)
    print("\n".join(l for l in log.splitlines() if l.startswith("Vertex BRDF") or l.startswith("  ")))
    s = read_suggestions(sugg)
    counts = [int(s[k]) for k in CLASS_KEYS]
    ours = classes_from_colours(coloured)
    if (ours < 0).any():
        failures.append(f"{int((ours < 0).sum())} vertices have a colour that is no class colour")
    colour_counts = [int((ours == c).sum()) for c in range(4)]
    if colour_counts != counts:
        failures.append(f"vertex colours {colour_counts} disagree with the suggestion file {counts}")
    v = mlx_values(mlx)  # the thresholds the filter ran with
    ref = independent_classes(a.project, float(v["specularThreshold"]), float(v["diffuseThreshold"]),
                              int(v["minDiffuseSamples"]), int(v["minSpecularSamples"]))
    n = len(ref)
    agreement = float((ours == ref).mean()) if len(ours) == n else 0.0
    ref_counts = [int((ref == c).sum()) for c in range(4)]
    print(f"classes (unseen, no diffuse, no specular, full): filter {counts}, independent {ref_counts}; "
          f"per-vertex agreement {agreement:.4f}")
    confusion = np.zeros((4, 4), int)
    for c1, c2 in zip(ref, ours):
        confusion[c1, max(c2, 0)] += 1
    print("confusion (rows: independent, columns: filter):\n" + str(confusion))
    # Pixels only take samples away (saturation; mixed pixels at silhouettes with the GL back end):
    # the filter's class is rarely above the independent one.
    above = float(((ours > ref) & (ref > 0)).mean())
    print(f"vertices the filter classes above the independent computation: {above:.4f}")
    if above > a.max_above:
        failures.append(f"{above:.4f} of the vertices are classed above the independent computation (> {a.max_above})")
    if agreement < a.min_agreement:
        failures.append(f"per-vertex agreement {agreement:.4f} < {a.min_agreement}")
    for c in range(4):
        if abs(counts[c] - ref_counts[c]) > a.max_class_diff * n:
            failures.append(f"class {CLASS_KEYS[c]}: {counts[c]} vs {ref_counts[c]} independent "
                            f"(more than {a.max_class_diff:.0%} of the vertices apart)")
    for kind in ("diffuse", "specular"):
        if s.get(f"{kind}_valid") == "1":
            el = float(s[f"{kind}_elevation_deg"])
            cam = [float(x) for x in s[f"{kind}_camera"].split()]
            print(f"{kind} light: azimuth {s[f'{kind}_azimuth_deg']}, elevation {el}, covers {s[f'{kind}_covers']} "
                  f"of {s[f'{kind}_needing']}")
            if el < 5.0 - 0.05 or cam[2] < math.sin(math.radians(5.0)) - 1e-3:
                failures.append(f"{kind} light below the placeable horizon: elevation {el}")
    return report(failures)


def nearest(entries, cam_dir, taken):
    best, best_cos = None, -2
    for name, d in entries:
        if name in taken:
            continue
        c = sum(x * y for x, y in zip(d, cam_dir)) / max(1e-9, math.sqrt(sum(x * x for x in d)))
        if c > best_cos:
            best, best_cos = name, c
    return best, math.degrees(math.acos(max(-1.0, min(1.0, best_cos)))) if best else 0.0


def read_lp(path):
    lines = [l.split() for l in lib.read_text(path).splitlines() if l.strip()]
    return [(t[0], [float(x) for x in t[1:4]]) for t in lines[1:]]


def cmd_loop(a):
    """The field loop through meshlabserver: coverage -> suggestion -> nearest candidate photo ->
    import (with coverage update) -> ... until the coverage of all candidates is reached."""
    work = fresh_dir(a.workdir)
    src_dir = os.path.dirname(os.path.abspath(a.project))
    before = lib.tree_checksums(src_dir)
    # What the whole candidate set gives (the target), from the command-line tool.
    full_sugg = os.path.join(work, "all_candidates.txt")
    # The same classification as the filters (the script's values; the import runs the defaults,
    # which the script lists).
    v = mlx_values(a.mlx)
    subprocess.run([a.coverage_tool, a.project, "--out", full_sugg, "--ts", v["specularThreshold"],
                    "--td", v["diffuseThreshold"], "--min-diffuse", v["minDiffuseSamples"],
                    "--min-specular", v["minSpecularSamples"]], check=True, stdout=subprocess.DEVNULL)
    target = read_suggestions(full_sugg)
    target_full, target_diffuse = int(target["fully_covered"]), int(target["fully_covered"]) + int(target["diffuse_no_specular"])
    print(f"all {target['photos']} candidates: {target_diffuse} vertices diffusely covered, {target_full} fully")
    lp = [f for f in os.listdir(src_dir) if f.endswith(".lp")][0]
    entries = [(os.path.basename(n), d) for n, d in read_lp(os.path.join(src_dir, lp))]
    cur = os.path.join(work, "project.mlp")  # saved over itself each step, as in the field
    mesh = own_mesh_copy(a.project, work)
    project_subset(a.project, cur, keep={0}, mesh_path=mesh)
    taken = {os.path.basename(rasters_of(cur)[0][1])}
    mlx = os.path.join(work, "coverage.mlx")
    lib.write_mlx(a.mlx, mlx, {"lightFile": os.path.join(src_dir, lp)})
    rc, _ = run_server(a.wrapper, ["-p", cur, "-s", mlx], os.path.join(work, "step00.log"))
    sugg = os.path.splitext(cur)[0] + "_next_light.txt"
    if rc != 0:
        return report([f"coverage filter failed on the one-photo project (exit {rc})"])
    failures, history = [], []
    for step in range(1, a.max_photos + 1):
        s = read_suggestions(sugg)
        full, diffuse = int(s["fully_covered"]), int(s["fully_covered"]) + int(s["diffuse_no_specular"])
        history.append((len(taken), diffuse, full))
        print(f"photos {len(taken):2d}: diffusely covered {diffuse}/{target_diffuse}, fully {full}/{target_full}")
        if (full >= target_full and diffuse >= target_diffuse) or step == a.max_photos:
            break
        kind = s.get("recommended", "none")
        if kind not in ("diffuse", "specular"):
            print("no further light suggested")
            break
        covers = int(s[f"{kind}_covers"])
        cam = [float(x) for x in s[f"{kind}_camera"].split()]
        photo, off = nearest(entries, cam, taken)
        if photo is None:
            break
        print(f"  next: {kind} light (az {s[f'{kind}_azimuth_deg']}, el {s[f'{kind}_elevation_deg']}, covers "
              f"{covers}); nearest photo {photo}, {off:.1f} deg away")
        taken.add(photo)
        nxt = cur
        imp = os.path.join(work, f"import{step:02d}.mlx")
        import_mlx(imp, {"photoFiles": os.path.join(src_dir, "images", photo), "lightFile": os.path.join(src_dir, lp)})
        rc, log = run_server(a.wrapper, ["-p", cur, "-w", nxt, "-s", imp], os.path.join(work, f"step{step:02d}.log"))
        if rc != 0:
            return report([f"import filter failed at step {step} (exit {rc})"])
        pin_mesh(nxt, mesh)
        if len(rasters_of(nxt)) != len(taken):
            return report([f"the saved project has {len(rasters_of(nxt))} rasters, expected {len(taken)}"])
    photos, diffuse, full = history[-1]
    print(f"after {photos} photos: {diffuse / max(1, target_diffuse):.4f} of the diffuse target, "
          f"{full / max(1, target_full):.4f} of the full target (all {target['photos']} candidates)")
    if diffuse < a.min_diffuse * target_diffuse or full < a.min_full * target_full:
        failures.append(f"following the suggestions reached only {diffuse}/{target_diffuse} diffuse and "
                        f"{full}/{target_full} full within {a.max_photos} photos")
    if lib.tree_checksums(src_dir) != before:
        failures.append(f"the candidate project folder {src_dir} was modified")
    return report(failures)


def cmd_sphere(a):
    """First raster registered; the others imported from the photo folder with lights from the
    sphere: they must match the capture's .lp."""
    work = fresh_dir(a.workdir)
    src_dir = os.path.dirname(os.path.abspath(a.project))
    before = lib.tree_checksums(src_dir)
    cur = os.path.join(work, "one.mlp")
    project_subset(a.project, cur, keep={0}, mesh_path=own_mesh_copy(a.project, work))
    lp = [f for f in sorted(os.listdir(src_dir)) if f.endswith(".lp")][0]
    # The first photo's light as the acquisition's .lp so far (the sphere lights go to a new one).
    first = os.path.basename(rasters_of(cur)[0][1])
    entries = dict(read_lp(os.path.join(src_dir, lp)))
    key = [k for k in entries if os.path.basename(k) == first][0]
    start_lp = os.path.join(work, "start.lp")
    lib.write_text(start_lp, f"1\n{key} {' '.join(str(x) for x in entries[key])}\n")
    out_lp = os.path.join(work, "acquired.lp")
    imp = os.path.join(work, "import.mlx")
    import_mlx(imp, {"photoFolder": os.path.join(src_dir, "images"), "lightSource": 1, "lightFile": start_lp,
                     "outputLightFile": out_lp, "updateCoverage": "true"})
    nxt = os.path.join(work, "all.mlp")
    rc, log = run_server(a.wrapper, ["-p", cur, "-w", nxt, "-s", imp], os.path.join(work, "meshlabserver.log"))
    failures = [] if rc == 0 else [f"meshlabserver exit status {rc}"]
    if failures:
        return report(failures)
    print("\n".join(l for l in log.splitlines() if "import" in l or "Sphere" in l)[:3000])
    got = {os.path.basename(n): d for n, d in read_lp(out_lp)}
    worst = 0.0
    for name, d in entries.items():
        g = got.get(os.path.basename(name))
        if g is None:
            failures.append(f"{name}: no light in {out_lp}")
            continue
        c = sum(x * y for x, y in zip(g, d)) / math.sqrt(sum(x * x for x in g) * sum(x * x for x in d))
        worst = max(worst, math.degrees(math.acos(max(-1.0, min(1.0, c)))))
    n_rasters = len(rasters_of(nxt))
    print(f"{n_rasters} rasters after the import; sphere lights vs {lp}: worst {worst:.2f} deg")
    if n_rasters != len(entries):
        failures.append(f"{n_rasters} rasters after the import, expected {len(entries)}")
    if worst > a.max_angle:
        failures.append(f"sphere light {worst:.2f} deg from {lp} (allowed {a.max_angle})")
    if not os.path.isfile(os.path.splitext(cur)[0] + "_next_light.txt"):
        failures.append("the import did not update the suggestions")
    if lib.tree_checksums(src_dir) != before:
        failures.append(f"the project folder {src_dir} was modified")
    return report(failures)


def report(failures):
    for f in failures:
        print("FAIL:", f)
    if not failures:
        print("ok")
    return 1 if failures else 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    for name in ("dump", "classes", "loop", "sphere"):
        p = sub.add_parser(name)
        p.add_argument("--wrapper", required=True)
        p.add_argument("--mlx", required=True, help="coverage.mlx template listing every parameter")
        p.add_argument("--workdir", required=True)
        if name != "dump":
            p.add_argument("--project", required=True)
    sub.choices["classes"].add_argument("--min-agreement", type=float, default=0.95)
    sub.choices["classes"].add_argument("--max-class-diff", type=float, default=0.03)
    sub.choices["classes"].add_argument("--max-above", type=float, default=0.01)
    sub.choices["classes"].add_argument("--set", action="append", help="filter parameter name=value")
    sub.choices["loop"].add_argument("--coverage-tool", required=True)
    sub.choices["loop"].add_argument("--max-photos", type=int, default=40)
    sub.choices["loop"].add_argument("--min-diffuse", type=float, default=1.0)
    sub.choices["loop"].add_argument("--min-full", type=float, default=0.99)
    sub.choices["sphere"].add_argument("--max-angle", type=float, default=1.0)
    a = ap.parse_args(argv)
    return {"dump": cmd_dump, "classes": cmd_classes, "loop": cmd_loop, "sphere": cmd_sphere}[a.command](a)


if __name__ == "__main__":
    sys.exit(main())
