"""The plugin through PyMeshLab 2025.7 against the same filter through Debian's meshlabserver
2020.09 (tests/pymeshlab/CMakeLists.txt registers one ctest entry per command).

    run_pymeshlab_tests.py load --work DIR
    run_pymeshlab_tests.py {fit,coverage,sphere,relight,bad_input} --work DIR --project P.mlp
                           --meshlabserver run_meshlabserver.sh

Runs under the virtual environment's python (pymeshlab and numpy). Exits 77 (ctest: skipped) with
the reason when pymeshlab or the PyMeshLab build of the plugin is missing.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "filter_vertex_brdf" / "python"))
sys.path.insert(0, str(REPO / "tests" / "e2e"))
SKIP = 77

# Agreement with 2020.09 on modelled vertices (fit_status > 0): MeshLab 2025.07 keeps the mesh in
# double, 2020.09 in float; the core computes in float in both.
MAX_REL = 1e-4


def skip(reason):
    print(f"SKIPPED: {reason}")
    sys.exit(SKIP)


def import_vbrdf():
    try:
        import vbrdf  # noqa: F401  (imports pymeshlab)
    except ImportError as e:
        skip(f"pymeshlab is not importable here ({e}): .ci/setup-pymeshlab.sh installs it into build/venv-pymeshlab")
    import vbrdf
    if not vbrdf.plugin_path().is_file():
        skip(f"the PyMeshLab build of the plugin is missing ({vbrdf.plugin_path()}): run .ci/build-pymeshlab.sh")
    vbrdf.load()
    return vbrdf


def copy_project(project, dest):
    """A fresh copy of the project's folder (tests never write into the repository)."""
    src = Path(project).resolve().parent
    if dest.exists():
        shutil.rmtree(dest)
    shutil.copytree(src, dest, ignore=shutil.ignore_patterns("*_brdf.ply", "*_report.txt", "exr", "*.npz"))
    return dest / Path(project).name


def run_2020(meshlabserver, project, mlx_template, values, mlx_path):
    import e2e_lib
    e2e_lib.write_mlx(mlx_template, mlx_path, values)
    # Debian's meshlabserver with Debian's Qt: not the platform plugins set for PyMeshLab's Qt.
    env = {k: v for k, v in os.environ.items() if k not in ("QT_PLUGIN_PATH", "VBRDF_OPENGL")}
    proc = subprocess.run([meshlabserver, "-p", str(project), "-s", str(mlx_path)], capture_output=True, text=True,
                          env=env)
    return proc.returncode, proc.stdout + proc.stderr


# --- load: the plugin loads, every filter is bound, names and defaults as in 2020.09 -----------

def same_value(pymeshlab_value, mlx_value):
    """A PyMeshLab default against the value an .mlx writes (floats declared in float)."""
    if isinstance(pymeshlab_value, bool):
        return str(pymeshlab_value).lower() == mlx_value.lower()
    if isinstance(pymeshlab_value, (int, float)):
        return abs(float(pymeshlab_value) - float(mlx_value)) <= 1e-6 * max(1.0, abs(float(mlx_value)))
    return str(pymeshlab_value) == mlx_value


def cmd_load(args):
    vbrdf = import_vbrdf()
    import xml.etree.ElementTree as ET
    ms = vbrdf.open_project(REPO / "sample_projects" / "synth_basic" / "project.mlp")
    failures = [f"MeshSet has no method {vbrdf.method_name(k)}" for k in vbrdf.FILTERS
                if not hasattr(ms, vbrdf.method_name(k))]
    # Every parameter of the 2020.09 scripts is a parameter of the 2025.07 filter; the sample
    # projects' scripts hold every default, which must be the same.
    scripts = {"fit": ("sample_projects/synth_basic/fit.mlx", True),
               "coverage": ("sample_projects/synth_basic/coverage.mlx", True),
               "sphere": ("sample_projects/spot_dir24/sphere.mlx", False),
               "relight": ("tests/benchmark/relight.mlx", False)}
    for key, (script, defaults_too) in scripts.items():
        defaults = ms.filter_parameter_values(vbrdf.method_name(key))
        params = list(ET.parse(REPO / script).getroot().iter("Param"))
        for p in params:
            py = vbrdf.python_name(p.get("name"))
            if py not in defaults:
                failures.append(f"{key}: parameter {p.get('name')} missing under PyMeshLab")
            elif defaults_too and not same_value(defaults[py], p.get("value")):
                failures.append(f"{key}: {p.get('name')} defaults to {defaults[py]!r} under PyMeshLab, "
                                f"{p.get('value')!r} in {script}")
        extra = sorted(set(defaults) - {vbrdf.python_name(p.get("name")) for p in params})
        print(f"{key}: {len(params)} parameters as in {script}; only under PyMeshLab: {extra}")
        if extra != ["projectfile"]:
            failures.append(f"{key}: parameters beyond the 2020.09 ones: {extra}")
    for f in failures:
        print("FAIL:", f)
    print("load: " + ("ok" if not failures else f"{len(failures)} failures"))
    return 1 if failures else 0


# --- fit: PyMeshLab against meshlabserver, both on the CPU back ends ---------------------------

CPU = {"fitBackend": 2, "visibilityBackend": 2}
CPU_VISIBILITY = {"visibilityBackend": 2}
GPU = {"fitBackend": 1, "visibilityBackend": 1}
# Relit figures (rendered by the GL of two different processes): within 1 %.
MAX_RELIT_REL = 0.01


def compare_plys(ref_path, new_path):
    import numpy as np
    import e2e_lib
    ref, new = e2e_lib.read_ply(ref_path), e2e_lib.read_ply(new_path)
    rv, nv = ref.elements["vertex"], new.elements["vertex"]
    names = rv.dtype.names
    problems = []
    if names != nv.dtype.names:
        problems.append(f"properties differ: {names} vs {nv.dtype.names}")
        return problems, {}
    if len(rv) != len(nv):
        return [f"vertex counts differ: {len(rv)} vs {len(nv)}"], {}
    modelled = np.asarray(rv["fit_status"]) > 0 if "fit_status" in names else np.ones(len(rv), bool)
    stats = {}
    for name in names:
        a = np.asarray(rv[name], dtype=np.float64)[modelled]
        b = np.asarray(nv[name], dtype=np.float64)[modelled]
        # Relative to the attribute's own scale (a colour code of 0 and of 1 differ by 1/255 of it).
        scale = max(np.max(np.abs(a)) if a.size else 0.0, 1e-12)
        rel = float(np.max(np.abs(a - b)) / scale) if a.size else 0.0
        stats[name] = rel
        if not rel <= MAX_REL:
            worst = int(np.argmax(np.abs(a - b)))
            problems.append(f"{name}: max relative difference {rel:.3g} > {MAX_REL:g} "
                            f"(vertex {worst} of the modelled ones: {a[worst]!r} vs {b[worst]!r})")
    return problems, stats


def cmd_fit(args):
    vbrdf = import_vbrdf()
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    project = copy_project(args.project, work / "project")
    ref_ply, new_ply = work / "meshlab2020_brdf.ply", work / "pymeshlab_brdf.ply"
    for p in (ref_ply, new_ply):
        p.unlink(missing_ok=True)
    template = Path(args.mlx) if args.mlx else Path(args.project).resolve().parent / "fit.mlx"
    backends = GPU if args.gl else CPU
    rc, log = run_2020(args.meshlabserver, project, template, dict(backends, outputPly=str(ref_ply)), work / "fit.mlx")
    if rc != 0 or not ref_ply.is_file():
        print(log[-4000:])
        print(f"FAIL: meshlabserver 2020.09 did not write {ref_ply} (exit status {rc})")
        return 1
    params = dict(vbrdf.script_parameters(template), **backends)
    params.pop("outputPly")
    result = vbrdf.fit(project, out=new_ply, **params)
    print("figures:", result.figures)
    if not result.ply.is_file() or not result.report.is_file():
        print(f"FAIL: PyMeshLab's fit did not write {result.ply} and {result.report}")
        return 1
    problems, stats = compare_plys(ref_ply, new_ply)
    for name, rel in stats.items():
        print(f"  {name:24s} max relative difference {rel:.3g}")
    if result.figures.get("vertices_coloured", 0) <= 0:
        problems.append(f"no vertex coloured: {result.figures}")
    for p in problems:
        print("FAIL:", p)
    print("fit: " + ("ok, within %g relative on every attribute" % MAX_REL if not problems else "failed"))
    return 1 if problems else 0


# --- coverage, sphere, relight: the files each writes, 2025.07 against 2020.09 ----------------

NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def compare_texts(ref, new, max_rel):
    """Problems between two texts: words must match, numbers agree within max_rel of their size
    (at least 1e-6 absolute). Returns (problems, largest relative difference)."""
    ref_words, new_words = NUMBER.split(ref), NUMBER.split(new)
    ref_nums, new_nums = [float(x) for x in NUMBER.findall(ref)], [float(x) for x in NUMBER.findall(new)]
    if ref_words != new_words or len(ref_nums) != len(new_nums):
        return ["the texts differ beyond their numbers"], float("inf")
    worst = 0.0
    for a, b in zip(ref_nums, new_nums):
        diff = abs(a - b)
        if diff > 1e-6:
            worst = max(worst, diff / max(abs(a), abs(b)))
    return ([f"numbers differ by up to {worst:.3g} relative (> {max_rel:g})"] if worst > max_rel else []), worst


def without_timings(text):
    """The text without its run-time lines ('# time: visibility 0.56 s, ...')."""
    return "\n".join(line for line in text.splitlines() if not re.match(r"^#? ?time:", line))


def new_files(folder, before):
    return sorted(p for p in folder.rglob("*") if p.is_file() and p.relative_to(folder).as_posix() not in before)


def two_copies(project, work):
    """The project copied twice: a/ for meshlabserver 2020.09, b/ for PyMeshLab."""
    a, b = copy_project(project, work / "a"), copy_project(project, work / "b")
    return a, b, set(e2e_lib_checksums(a.parent)), set(e2e_lib_checksums(b.parent))


def e2e_lib_checksums(folder):
    import e2e_lib
    return e2e_lib.tree_checksums(folder)


def compare_outputs(a_dir, a_before, b_dir, b_before, max_rel, skip=()):
    """Every file the 2020.09 run wrote against the PyMeshLab run's of the same name (text files;
    images and the files named in `skip` only for their presence)."""
    a_files = [p.relative_to(a_dir).as_posix() for p in new_files(a_dir, a_before)]
    b_files = [p.relative_to(b_dir).as_posix() for p in new_files(b_dir, b_before)]
    problems = [] if a_files == b_files else [f"files written differ: {a_files} vs {b_files}"]
    if not a_files:
        problems.append("nothing written")
    for rel in a_files:
        if rel not in b_files or rel.endswith(".png") or any(rel.endswith(s) for s in skip):
            continue
        ref = without_timings((a_dir / rel).read_text(encoding="utf-8").replace(str(a_dir), "<project>"))
        new = without_timings((b_dir / rel).read_text(encoding="utf-8").replace(str(b_dir), "<project>"))
        found, worst = compare_texts(ref, new, max_rel)
        print(f"  {rel}: largest relative difference {worst:.3g}")
        problems += [f"{rel}: {p}" for p in found]
    return problems


def finish(name, problems):
    for p in problems:
        print("FAIL:", p)
    print(f"{name}: " + ("ok" if not problems else "failed"))
    return 1 if problems else 0


def cmd_coverage(args):
    vbrdf = import_vbrdf()
    work = Path(args.work)
    a, b, a_before, b_before = two_copies(args.project, work)
    template = Path(args.project).resolve().parent / "coverage.mlx"
    rc, log = run_2020(args.meshlabserver, a, template, CPU_VISIBILITY, work / "coverage_cpu.mlx")
    if rc != 0:
        print(log[-4000:])
        return finish("coverage", [f"meshlabserver 2020.09 failed (exit status {rc})"])
    # The 2020.09 script itself, through PyMeshLab's own script runner (no 'Project file': the
    # plugin finds the project beside the mesh).
    ms = vbrdf.open_project(b)
    ms.load_filter_script(str(work / "coverage_cpu.mlx"))
    ms.apply_filter_script()
    return finish("coverage", compare_outputs(a.parent, a_before, b.parent, b_before, MAX_REL))


def cmd_sphere(args):
    vbrdf = import_vbrdf()
    work = Path(args.work)
    a, b, a_before, b_before = two_copies(args.project, work)
    template = Path(args.project).resolve().parent / "sphere.mlx"
    rc, log = run_2020(args.meshlabserver, a, template, {}, work / "sphere.mlx")
    if rc != 0:
        print(log[-4000:])
        return finish("sphere", [f"meshlabserver 2020.09 failed (exit status {rc})"])
    vbrdf.apply("sphere", b, **vbrdf.script_parameters(template))
    return finish("sphere", compare_outputs(a.parent, a_before, b.parent, b_before, MAX_REL))


def cmd_relight(args):
    """The relight filter renders with OpenGL: the PyMeshLab side runs with VBRDF_OPENGL=1 under
    xvfb-run (with_venv.sh --gl). Both relight the same fit (2020.09's, CPU back ends)."""
    vbrdf = import_vbrdf()
    work = Path(args.work)
    a, b, _, _ = two_copies(args.project, work)
    fit_ply = work / "fit_brdf.ply"
    fit_ply.unlink(missing_ok=True)
    rc, log = run_2020(args.meshlabserver, a, Path(args.project).resolve().parent / "fit.mlx",
                       dict(CPU, outputPly=str(fit_ply)), work / "fit_cpu.mlx")
    if rc != 0 or not fit_ply.is_file():
        print(log[-4000:])
        return finish("relight", [f"meshlabserver 2020.09's fit failed (exit status {rc})"])
    values = {"fitResultPly": str(fit_ply), "rasterProject": "heldout/project.mlp", "outputFolder": "relit"}
    rc, log = run_2020(args.meshlabserver, a, REPO / "tests" / "benchmark" / "relight.mlx", values,
                       work / "relight.mlx")
    if rc != 0:
        print(log[-4000:])
        return finish("relight", [f"meshlabserver 2020.09's relight failed (exit status {rc})"])
    vbrdf.apply("relight", b, **dict(vbrdf.script_parameters(REPO / "tests" / "benchmark" / "relight.mlx"), **values))
    problems = []
    ref = (a.parent / "relit" / "relight_table.csv").read_text(encoding="utf-8").replace(str(a.parent), "<project>")
    new_path = b.parent / "relit" / "relight_table.csv"
    if not new_path.is_file():
        return finish("relight", [f"PyMeshLab's relight wrote no {new_path}"])
    new = new_path.read_text(encoding="utf-8").replace(str(b.parent), "<project>")
    found, worst = compare_texts(ref, new, MAX_RELIT_REL)
    print(f"  relight_table.csv: largest relative difference {worst:.3g}")
    problems += found
    return finish("relight", problems)


# --- bad input: the same message as 2020.09, nothing written -----------------------------------

def cmd_bad_input(args):
    vbrdf = import_vbrdf()
    import pymeshlab
    import e2e_lib
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    project = copy_project(args.project, work / "project")
    missing = work / "project" / "no_such_lights.lp"
    out = work / "project" / "bad_brdf.ply"
    template = Path(args.project).resolve().parent / "fit.mlx"
    before = e2e_lib.tree_checksums(project.parent)
    rc, log = run_2020(args.meshlabserver, project, template, {"lightFile": str(missing), "outputPly": str(out)},
                       work / "fit_bad.mlx")
    marker = "Vertex BRDF: fit per-vertex reflectance failed: "
    lines = [line for line in log.splitlines() if marker in line]
    if rc == 0 or not lines:
        print(log[-4000:])
        print("FAIL: meshlabserver 2020.09 did not refuse the missing light file")
        return 1
    expected = lines[-1].split(marker, 1)[1].strip()
    try:
        vbrdf.fit(project, lights=missing, out=out, **{k: v for k, v in vbrdf.script_parameters(template).items()
                                                       if k not in ("lightFile", "outputPly")})
    except pymeshlab.PyMeshLabException as e:
        got = str(e)
    else:
        print("FAIL: PyMeshLab's fit accepted a missing light file")
        return 1
    print("2020.09 :", expected)
    print("2025.07 :", got)
    failures = []
    if expected not in got:
        failures.append("the messages differ")
    if e2e_lib.tree_checksums(project.parent) != before:
        failures.append("the project folder changed (something was written)")
    for f in failures:
        print("FAIL:", f)
    print("bad_input: " + ("ok" if not failures else "failed"))
    return 1 if failures else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("command", choices=["load", "fit", "coverage", "sphere", "relight", "bad_input"])
    parser.add_argument("--work", required=True)
    parser.add_argument("--project")
    parser.add_argument("--meshlabserver")
    parser.add_argument("--mlx", help="fit: the 2020.09 script whose values both sides use (default: the project's fit.mlx)")
    parser.add_argument("--gl", action="store_true",
                        help="fit: the GPU back ends (compute shaders) instead of the CPU ones")
    args = parser.parse_args()
    commands = {"load": cmd_load, "fit": cmd_fit, "coverage": cmd_coverage, "sphere": cmd_sphere,
                "relight": cmd_relight, "bad_input": cmd_bad_input}
    return commands[args.command](args)


if __name__ == "__main__":
    sys.exit(main())
