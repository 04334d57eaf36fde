#!/usr/bin/env python3
"""GUI tests: Debian's MeshLab GUI, with the built plugin, under xvfb-run, driven by gui_driver
(preloaded; see gui_driver.cpp) as a user would: menu entry, dialog, typing, Apply.

  run_gui_e2e.py typed-paths --project P.mlp --meshlab M --lib-dir L --driver D --workdir W
  run_gui_e2e.py dialogs     --project P.mlp --meshlab M --lib-dir L --driver D --workdir W
  run_gui_e2e.py live-relight --project P.mlp --check C ...   (and live-relight-no-model)

typed-paths: a copy of the project without any light file beside it or its photos; the fit dialog
gets a typed light file (in a folder the default search never looks in, with a space in its name)
and a typed output PLY. Passes only if the fit read the one and wrote the other, and wrote nothing
at the default output path. dialogs: every Vertex BRDF dialog opens from its menu; their sizes
are printed and screenshots kept in W/<filter>/.
live-relight: on a copy of the project the fit is applied, the render mode "Vertex BRDF:
relight" switched on and the light moved (Ctrl+Shift+drag); both screenshots of the 3-D view must
match the relight renderer's image of the logged view and light (C = vbrdf_live_view_check), and
the light must have moved. live-relight-no-model: the render mode on the mesh without a fit must
log the message and draw what MeshLab draws.
Everything is written under --workdir; the project is only read.
"""
import argparse
import os
import shutil
import subprocess
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "e2e"))
import e2e_lib as lib  # noqa: E402

FIT = "Vertex BRDF: fit per-vertex reflectance"
FILTERS = [FIT, "Vertex BRDF: coverage and next light", "Vertex BRDF: relight and compare",
           "Vertex BRDF: estimate light directions from a reflective sphere",
           "Vertex BRDF: import new photos of a viewpoint", "Vertex BRDF: load result attributes",
           "Vertex BRDF: show vertex colours"]
SCREEN = (1280, 1024)


def run_gui(a, project, filter_name, typed, shots, apply=True, timeout=600, extra_env=None):
    """Runs the GUI on `project` with the driver; returns (exit status, driver report lines)."""
    report = os.path.join(shots, "driver.txt")
    os.makedirs(shots, exist_ok=True)
    if os.path.exists(report):
        os.remove(report)
    home = os.path.join(a.workdir, "home")  # MeshLab's settings: fresh, inside the work folder
    os.makedirs(home, exist_ok=True)
    env = dict(os.environ, HOME=home, XDG_CONFIG_HOME=os.path.join(home, ".config"),
               LD_LIBRARY_PATH=a.lib_dir + (":" + os.environ["LD_LIBRARY_PATH"] if os.environ.get("LD_LIBRARY_PATH") else ""),
               LD_PRELOAD=os.path.abspath(a.driver), VBRDF_GUI_FILTER=filter_name,
               VBRDF_GUI_TYPE="\n".join(f"{k}={v}" for k, v in typed.items()), VBRDF_GUI_SHOTS=shots,
               VBRDF_GUI_LOG=report, VBRDF_GUI_APPLY="1" if apply else "0", LIBGL_ALWAYS_SOFTWARE="1")
    env.update(extra_env or {})
    cmd = ["xvfb-run", "-a", "-s", f"-screen 0 {SCREEN[0]}x{SCREEN[1]}x24", a.meshlab, os.path.abspath(project)]
    print("running:", " ".join(cmd), flush=True)
    try:
        proc = subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=timeout)
        rc, out = proc.returncode, proc.stdout.decode("utf-8", "replace")
    except subprocess.TimeoutExpired as e:
        rc, out = 124, (e.stdout or b"").decode("utf-8", "replace")
    lib.write_text(os.path.join(shots, "meshlab_output.txt"), out)
    lines = lib.read_text(report).splitlines() if os.path.isfile(report) else []
    print("\n".join("  " + l for l in lines))
    return rc, lines


def values(lines, key):
    return [l.split(": ", 1)[1] for l in lines if l.startswith(key + ": ")]


def copy_project_without_lights(src_mlp, dst_dir):
    """The project's mesh, photos and .mlp in dst_dir, and no light file anywhere near them."""
    src_dir = os.path.dirname(os.path.abspath(src_mlp))
    shutil.rmtree(dst_dir, ignore_errors=True)
    shutil.copytree(src_dir, dst_dir, ignore=shutil.ignore_patterns("*.lp", "*.json", "*.dome", "heldout",
                                                                     "ground_truth", "*_brdf*", "*.mlx"))
    return os.path.join(dst_dir, os.path.basename(src_mlp))


def cmd_typed_paths(a):
    work = a.workdir
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    src_dir = os.path.dirname(os.path.abspath(a.project))
    before = lib.tree_checksums(src_dir)
    project = copy_project_without_lights(a.project, os.path.join(work, "project"))
    typed_lp = os.path.join(work, "typed lights", "session 1.lp")
    os.makedirs(os.path.dirname(typed_lp))
    shutil.copy(os.path.join(src_dir, "lights.lp"), typed_lp)
    out_ply = os.path.join(work, "out", "typed result.ply")
    os.makedirs(os.path.dirname(out_ply))
    default_ply = os.path.join(os.path.dirname(project), "project_brdf.ply")

    rc, lines = run_gui(a, project, FIT, {"Light file (.lp, .json, .dome)": typed_lp, "Output PLY": out_ply},
                        os.path.join(work, "shots"))
    failures = []
    if rc != 0:
        failures.append(f"meshlab/driver exit status {rc}")
    if values(lines, "menu_entry_enabled") != ["1"]:
        failures.append("the fit's menu entry was not enabled")
    if values(lines, "applied") != ["1"]:
        failures.append("Apply was not pressed")
    for box in values(lines, "message_box"):
        failures.append(f"MeshLab reported: {box}")
    if not os.path.isfile(out_ply):
        failures.append(f"the typed output path was ignored: nothing at {out_ply}")
    if os.path.exists(default_ply):
        failures.append(f"the fit wrote the default output {default_ply} instead of the typed path")
    if not any("session 1.lp" in l for l in values(lines, "log")):
        failures.append("the log does not name the typed light file")
    if os.path.isfile(out_ply):
        ply = lib.read_ply(out_ply)
        mesh = lib.read_ply(os.path.join(os.path.dirname(project), "mesh.ply"))
        if len(ply.vertex) != len(mesh.vertex) or "kd" not in ply.property_names():
            failures.append("the written PLY is not the fit's result for the mesh")
    if values(lines, "dialog_preview") != ["0"]:
        failures.append("the fit dialog offers Preview (it would re-run the fit and write files)")
    if lib.tree_checksums(src_dir) != before:
        failures.append(f"the sample project {src_dir} was modified")
    size = values(lines, "dialog_size")
    print(f"fit dialog size: {size}")
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        print(lib.read_text(os.path.join(work, "shots", "meshlab_output.txt"))[-4000:])
        return 1
    print(f"ok: the fit read {typed_lp} and wrote {out_ply}, as typed")
    return 0


def cmd_dialogs(a):
    shutil.rmtree(a.workdir, ignore_errors=True)
    os.makedirs(a.workdir)
    failures = []
    for name in FILTERS:
        folder = os.path.join(a.workdir, name.split(": ", 1)[1].replace(" ", "_"))
        rc, lines = run_gui(a, a.project, name, {}, folder, apply=False, timeout=300)
        if rc != 0 or not values(lines, "dialog_size"):
            failures.append(f"{name}: the dialog did not open (exit status {rc})")
            continue
        print(f"{name}: dialog {values(lines, 'dialog_size')[0]} (size hint {values(lines, 'dialog_size_hint')[0]}), "
              f"preview offered: {values(lines, 'dialog_preview')[0]}")
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        return 1
    return 0


RELIGHT = "Vertex BRDF: relight"


def cmd_live_relight(a):
    shutil.rmtree(a.workdir, ignore_errors=True)
    os.makedirs(a.workdir)
    src_dir = os.path.dirname(os.path.abspath(a.project))
    project_dir = os.path.join(a.workdir, "project")
    shutil.copytree(src_dir, project_dir, ignore=shutil.ignore_patterns("heldout", "ground_truth", "*_brdf*"))
    project = os.path.join(project_dir, os.path.basename(a.project))
    result = os.path.join(project_dir, os.path.splitext(os.path.basename(a.project))[0] + "_brdf.ply")
    shots = os.path.join(a.workdir, "shots")
    rc, lines = run_gui(a, project, FIT, {}, shots, extra_env={
        "VBRDF_GUI_RENDER": RELIGHT, "VBRDF_GUI_LIGHT_DRAG": "150,-100",
        "VBRDF_RELIGHT_VIEW_LOG": os.path.join(a.workdir, "view_log.txt")})
    failures = []
    if rc != 0:
        failures.append(f"meshlab/driver exit status {rc}")
    for box in values(lines, "message_box"):
        failures.append(f"MeshLab reported: {box}")
    if values(lines, "render_mode") != [RELIGHT]:
        failures.append("the render mode was not switched on")
    if not any("Vertex BRDF relight:" in l and "vertices of" in l for l in values(lines, "log")):
        failures.append("the log does not report the model the live view drew")
    views = [os.path.join(shots, n) for n in ("view.txt", "view_moved.txt")]
    if not all(os.path.isfile(v) for v in views):
        failures.append("the render plugin logged no view (it did not draw the model)")
    else:
        lights = [l for v in views for l in lib.read_text(v).splitlines() if l.startswith("light ")]
        if len(lights) != 2 or lights[0] == lights[1]:
            failures.append(f"Ctrl+Shift+drag did not move the light the plugin uses: {lights}")
        for view, png in zip(views, ("view.png", "view_moved.png")):
            cmd = [a.check, result, view, os.path.join(shots, png), os.path.join(shots, "diff_" + png)] + \
                values(lines, "panel_rect")[:1]
            proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
            print(proc.stdout.decode("utf-8", "replace").strip())
            if proc.returncode != 0:
                failures.append(f"{png} does not match the relight renderer (exit status {proc.returncode})")
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        print(lib.read_text(os.path.join(shots, "meshlab_output.txt"))[-4000:])
        return 1
    print("ok: the live view matches the relight renderer before and after the light was moved")
    return 0


def cmd_live_relight_no_model(a):
    shutil.rmtree(a.workdir, ignore_errors=True)
    os.makedirs(a.workdir)
    shots = os.path.join(a.workdir, "shots")
    view_log = os.path.join(a.workdir, "view_log.txt")
    rc, lines = run_gui(a, a.project, "", {}, shots, extra_env={"VBRDF_GUI_RENDER": RELIGHT,
                                                                 "VBRDF_RELIGHT_VIEW_LOG": view_log})
    failures = []
    if rc != 0:
        failures.append(f"meshlab/driver exit status {rc}")
    log = " ".join(values(lines, "log"))
    for needed in ("has no per-vertex attribute 'kd'", "MeshLab's normal rendering", "Vertex BRDF: load result attributes"):
        if needed not in log:
            failures.append(f"the log lacks '{needed}'")
    if os.path.exists(view_log):
        failures.append("the plugin drew a model although the mesh has none")
    panel = values(lines, "panel_rect")
    if not panel:
        failures.append("the panel with the message is not shown")
    proc = subprocess.run([a.check, "--fallback", os.path.join(shots, "view_before.png"), os.path.join(shots, "view.png"),
                           panel[0] if panel else "0,0,0,0", os.path.join(shots, "diff_fallback.png")],
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    print(proc.stdout.decode("utf-8", "replace").strip())
    if proc.returncode != 0:
        failures.append("the view is not MeshLab's own rendering")
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        return 1
    print("ok: without a model the message is logged and MeshLab's rendering is shown")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("command", choices=["typed-paths", "dialogs", "live-relight", "live-relight-no-model"])
    ap.add_argument("--project", required=True)
    ap.add_argument("--meshlab", required=True)
    ap.add_argument("--lib-dir", required=True)
    ap.add_argument("--driver", required=True)
    ap.add_argument("--workdir", required=True)
    ap.add_argument("--check", help="vbrdf_live_view_check (live-relight commands)")
    a = ap.parse_args()
    a.workdir = os.path.abspath(a.workdir)
    return {"typed-paths": cmd_typed_paths, "dialogs": cmd_dialogs, "live-relight": cmd_live_relight,
            "live-relight-no-model": cmd_live_relight_no_model}[a.command](a)


if __name__ == "__main__":
    sys.exit(main())
