#!/usr/bin/python3
"""ctest driver (diffuse_choice_auto): the fit's Auto diffuse form (core/fit/diffuse_choice.h)
picks the form the photos were made with, and the pick pays off at held-out lights.

    check_diffuse_choice.py --synth synthesize_scene --fit-tool vbrdf_fit --eval-tool vbrdf_eval
                            --perturb-mesh vbrdf_perturb_mesh --perturb-project perturb_cameras.py --workdir DIR

Three synthetic captures of one scene (synthesize_scene, 16-bit linear photos): Lambertian, with
--coated-diffuse (the diffuse term under a clear coat: Fresnel transmission in and out, the
synthesizer's own exact formula), and with --coated-glossy (the coat only on the glossy regions:
two materials). Checks (each can fail):
  * Auto writes diffuse_form 0 everywhere on the Lambertian capture and 1 everywhere on the coated
    one, and the report says it was Auto's pilot that chose;
  * on the coated capture, the Auto fit relights the held-out photos better (vbrdf_eval mean
    CIEDE2000) than a fit forced to Lambert, and its albedo (k_d C) is nearer the truth;
  * on the two-material capture, Auto writes a coat map that agrees with the truth's glossy regions
    on >= 85 % of the modelled vertices, and relights better than both forms used everywhere;
  * the same with the mesh's normals smoothed as a scan's are (vbrdf_perturb_mesh, 3.5 deg median):
    the pilot refines each vertex's normal as the fit does, so the map still agrees on >= 85 %;
    with the shading normals off (the pilot on the smoothed normals) it must agree less (72 %
    when measured): the smoothed normals are what the refinement has to undo.
"""
import argparse
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "e2e"))
import e2e_lib as lib  # noqa: E402


def run(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return p.returncode, p.stdout


def synthesize(args, out, coat_option):
    cmd = [args.synth, "--out", out, "--vertices", "4000", "--width", "320", "--height", "240", "--lights", "24",
           "--heldout", "4", "--linear16", "--quiet", "--seed", "7"] + ([coat_option] if coat_option else [])
    rc, text = run(cmd)
    if rc != 0:
        raise SystemExit(f"FAIL: synthesize_scene exited {rc}:\n{text}")


def fit(args, scene, out, form, project="project.mlp", options=()):
    rc, text = run([args.fit_tool, os.path.join(scene, project), "--out", out, "--diffuse", form] + list(options))
    if rc != 0:
        raise SystemExit(f"FAIL: vbrdf_fit exited {rc}:\n{text}")
    return text


def diffuse_forms(ply_path):
    """The per-vertex diffuse_form of the modelled vertices."""
    v = lib.read_ply(ply_path).vertex
    return [int(f) for f, status in zip(v["diffuse_form"], v["fit_status"]) if status != 0]


def relit_mean(args, scene, fit_ply):
    rc, text = run([args.eval_tool, "--result", fit_ply, "--project", os.path.join(scene, "heldout", "project.mlp")])
    m = re.search(r"whole surface: product\s+\d+\s+([0-9.]+)", text)
    if rc != 0 or not m:
        raise SystemExit(f"FAIL: vbrdf_eval exited {rc} or printed no figure:\n{text}")
    return float(m.group(1))


def albedo_error(fit_ply, gt_ply):
    fit, gt = lib.read_ply(fit_ply).vertex, lib.read_ply(gt_ply).vertex
    total, n = 0.0, 0
    for i, status in enumerate(fit["fit_status"]):
        if status == 0:
            continue
        for c, key in enumerate(("color_r", "color_g", "color_b")):
            total += abs(fit["kd"][i] * fit[key][i] - gt["albedo_" + "rgb"[c]][i])
            n += 1
    if n == 0:
        raise SystemExit(f"FAIL: {fit_ply}: no modelled vertex")
    return total / n


def coat_map_agreement(fit_ply, scene):
    """Share of the modelled vertices whose diffuse_form is the truth's (coated where glossy), and
    how many they are."""
    fit_v = lib.read_ply(fit_ply).vertex
    gt = lib.read_ply(os.path.join(scene, "ground_truth", "gt_vertex.ply")).vertex
    pairs = [(int(f), ks > 0) for f, status, ks in zip(fit_v["diffuse_form"], fit_v["fit_status"], gt["ks"]) if status != 0]
    return sum(1 for f, glossy in pairs if f == int(glossy)) / max(len(pairs), 1), len(pairs)


def check_smoothed_two_materials(args):
    """The two-material capture with its mesh's normals smoothed: the pilot must see through them."""
    scene = os.path.join(args.workdir, "two_materials")
    mesh = os.path.join(scene, "mesh_smoothed.ply")
    rc, text = run([args.perturb_mesh, os.path.join(scene, "mesh.ply"), mesh, "--smooth-normals", "3",
                    "--target-median", "3.5"])
    if rc != 0:
        raise SystemExit(f"FAIL: vbrdf_perturb_mesh exited {rc}:\n{text}")
    rc, text = run([sys.executable, args.perturb_project, os.path.join(scene, "project.mlp"),
                    os.path.join(scene, "project_smoothed.mlp"), "--mesh", mesh])
    if rc != 0:
        raise SystemExit(f"FAIL: perturb_cameras.py exited {rc}:\n{text}")
    agree = {}
    for normals in ("on", "off"):
        out = os.path.join(args.workdir, f"two_materials_smoothed_normals_{normals}.ply")
        fit(args, scene, out, "auto", "project_smoothed.mlp", ["--shading-normals", normals])
        agree[normals] = coat_map_agreement(out, scene)[0]
    print(f"two-material capture, normals smoothed: coat map agrees with the glossy regions on "
          f"{100 * agree['on']:.1f} % (shading normals on), {100 * agree['off']:.1f} % (off: the pilot on the "
          f"smoothed normals)")
    failures = []
    if agree["on"] < 0.85:
        failures.append(f"smoothed two-material capture: the coat map agrees with the truth on {100 * agree['on']:.1f} % "
                        "(< 85 %): the pilot did not refine the normals")
    if not agree["off"] < agree["on"]:
        failures.append("smoothed two-material capture: the pilot on the smoothed normals agrees as well as with refined "
                        "ones: the capture does not exercise the refinement")
    return failures


def check_two_materials(args):
    scene = os.path.join(args.workdir, "two_materials")
    synthesize(args, scene, "--coated-glossy")
    failures, relit = [], {}
    for form in ("auto", "lambert", "coated"):
        out = os.path.join(args.workdir, f"two_materials_{form}.ply")
        log = fit(args, scene, out, form)
        relit[form] = relit_mean(args, scene, out)
    agree, modelled = coat_map_agreement(os.path.join(args.workdir, "two_materials_auto.ply"), scene)
    print(f"two-material capture: coat map agrees with the glossy regions on {100 * agree:.1f} % of "
          f"{modelled} modelled vertices; relit mean CIEDE2000 Auto {relit['auto']:.3f}, "
          f"Lambert everywhere {relit['lambert']:.3f}, coated everywhere {relit['coated']:.3f}")
    if agree < 0.85:
        failures.append(f"two-material capture: the coat map agrees with the truth on {100 * agree:.1f} % (< 85 %)")
    if not relit["auto"] < min(relit["lambert"], relit["coated"]):
        failures.append("two-material capture: Auto's coat map does not relight better than both uniform forms")
    return failures


def main():
    ap = argparse.ArgumentParser()
    for a in ("--synth", "--fit-tool", "--eval-tool", "--perturb-mesh", "--perturb-project", "--workdir"):
        ap.add_argument(a, required=True)
    args = ap.parse_args()
    os.makedirs(args.workdir, exist_ok=True)
    failures = []
    for name, option, expected in (("lambert", None, 0), ("coated", "--coated-diffuse", 1)):
        scene = os.path.join(args.workdir, name)
        synthesize(args, scene, option)
        out = os.path.join(args.workdir, name + "_auto.ply")
        log = fit(args, scene, out, "auto")
        forms = set(diffuse_forms(out))
        print(f"{name} capture: Auto wrote diffuse_form {sorted(forms)}")
        if forms != {expected}:
            failures.append(f"{name} capture: Auto wrote diffuse_form {sorted(forms)}, expected {expected} everywhere")
        if not re.search(r"diffuse term: (lambert|coated) \(Auto: pilot fit of \d+ vertices", log):
            failures.append(f"{name} capture: the report does not say how Auto chose:\n{log}")
    failures += check_two_materials(args)
    failures += check_smoothed_two_materials(args)
    scene = os.path.join(args.workdir, "coated")
    forced = os.path.join(args.workdir, "coated_lambert.ply")
    fit(args, scene, forced, "lambert")
    auto = os.path.join(args.workdir, "coated_auto.ply")
    relit_auto, relit_forced = relit_mean(args, scene, auto), relit_mean(args, scene, forced)
    gt = os.path.join(scene, "ground_truth", "gt_vertex.ply")
    albedo_auto, albedo_forced = albedo_error(auto, gt), albedo_error(forced, gt)
    print(f"coated capture: held-out relit mean CIEDE2000 Auto {relit_auto:.3f}, forced Lambert {relit_forced:.3f}; "
          f"albedo mean abs error Auto {albedo_auto:.4f}, forced Lambert {albedo_forced:.4f}")
    if not relit_auto < relit_forced:
        failures.append(f"coated capture: Auto's relit error {relit_auto:.3f} is not below Lambert's {relit_forced:.3f}")
    if not albedo_auto < albedo_forced:
        failures.append(f"coated capture: Auto's albedo error {albedo_auto:.4f} is not below Lambert's {albedo_forced:.4f}")
    for f in failures:
        print("FAIL: " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
