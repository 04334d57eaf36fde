#!/usr/bin/python3
"""The protocol's floor: how the ground-truth reflectance itself scores under vbrdf_eval's protocol.

vbrdf_eval compares, per held-out sample, the model's value AT THE VERTEX with the photo sampled
bilinearly at the vertex's pixel. Where a pixel's footprint covers much more surface than the point
(grazing view, foreshortened texture) or another surface (silhouettes), even the true reflectance
does not match the pixel. This script takes the samples that vbrdf_eval scored (--samples-csv) and
predicts each one with the scene's TRUE BSDF at the vertex (Mitsuba 3's roughplastic as the shared
scenes were rendered: GGX microfacet lobe with dielectric Fresnel over a diffuse base seen through the
coat's rough transmittance, direct light only), then scores both with the same CIEDE2000.

    vbrdf_eval --result fit.ply --project SCENE/heldout/project.mlp --photo-dir SCENE/heldout/linear \
               --gt-visible ... --gt-lit ... --samples-csv SAMPLES.csv
    oracle_eval.py SAMPLES.csv SCENE_DIR [--split-by-nv OTHER_SCENE_DIR ...]

SCENE_DIR: the scored camera's scene (gt_vertex.npz, gt_scene.json, heldout/lights.lp). The
16-bit linear photos are assumed (exposure from gt_scene.json, no colour cast, colour correction
off), as tests/benchmark/cross_camera_eval.sh and whole_surface_eval.sh score them.
Prints the product's and the truth's mean / p95 over the same samples: all, clean and mixed
footprints, split by the scored camera's N.E and, for each further scene given (another camera of
the same mesh), by that camera's N.E. The diffuse base uses the material's own table of pi f / rho
against incidence from gt_scene.json (the rough coat's transmission, in and out), else a quadrature.
Self-check: the script's CIEDE2000 of the product's predictions must match vbrdf_eval's (exit 1
otherwise). Needs numpy; only for roughplastic materials under directional lights (the shared
scenes with directional lights). Figures: docs/decisions/true_reflectance.md.
"""
import csv
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "e2e"))
import e2e_lib as lib  # noqa: E402  (CIELAB, CIEDE2000, Fresnel: the tests' one copy)


def ggx_d(cos_h, alpha):
    c2 = np.clip(cos_h, 1e-9, 1) ** 2
    t2 = (1 - c2) / c2
    return np.where(cos_h > 0, 1 / (np.pi * alpha ** 2 * c2 ** 2 * (1 + t2 / alpha ** 2) ** 2), 0)


def smith_g1(cos_v, v_dot_m, alpha):
    c2 = np.clip(cos_v, 1e-9, 1) ** 2
    t2 = (1 - c2) / c2
    return np.where(v_dot_m * cos_v > 0, 2 / (1 + np.sqrt(1 + alpha ** 2 * t2)), 0)


def spec_value(n_dot_e, n_dot_l, n_dot_h, e_dot_h, alpha, eta):
    """Mitsuba roughplastic's specular eval: D F G / (4 cos_theta_i), i = the view side (f * N.L)."""
    d = ggx_d(n_dot_h, alpha)
    g = smith_g1(n_dot_e, e_dot_h, alpha) * smith_g1(n_dot_l, e_dot_h, alpha)
    return d * lib.fresnel_dielectric(e_dot_h, eta) * g / (4 * np.maximum(n_dot_e, 1e-9))


def rough_transmittance(mu, alpha, eta, n=192):
    """1 - directional albedo of the rough dielectric reflection at incidence cosine mu (quadrature
    over the outgoing hemisphere), Mitsuba's external transmittance table for the diffuse base."""
    th = (np.arange(n) + 0.5) / n * (np.pi / 2)
    ph = (np.arange(2 * n) + 0.5) / (2 * n) * (2 * np.pi)
    T, P = np.meshgrid(th, ph, indexing="ij")
    wo = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], axis=-1)
    dw = np.sin(T) * (np.pi / 2 / n) * (2 * np.pi / (2 * n))
    out = []
    for m in np.atleast_1d(mu):
        wi = np.array([np.sqrt(max(1 - m * m, 0)), 0, m])
        h = wo + wi
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        v = spec_value(m, wo[..., 2], h[..., 2], h @ wi, alpha, eta)
        out.append(1 - np.sum(v * dw))
    return np.array(out)


def main(argv):
    if len(argv) < 3:
        print(__doc__)
        return 2
    samples_csv, scene = argv[1], argv[2]
    split_scenes = argv[argv.index("--split-by-nv") + 1:] if "--split-by-nv" in argv else []
    gt = np.load(f"{scene}/gt_vertex.npz")
    meta = json.load(open(f"{scene}/gt_scene.json"))
    exposure = meta["camera_response"]["exposure"]
    irradiance = meta["lights"]["irradiance"]
    cam = np.array(meta["camera"]["origin_world"])
    rows = list(csv.DictReader(open(samples_csv)))
    v = np.array([int(r["vertex"]) for r in rows])
    photo = [r["photo"] for r in rows]
    obs = np.array([[float(r[k]) for k in ("obs_r", "obs_g", "obs_b")] for r in rows])
    pred = np.array([[float(r[k]) for k in ("pred_r", "pred_g", "pred_b")] for r in rows])
    de_csv = np.array([float(r["de"]) for r in rows])
    # Which held-out light each photo is: the held-out lights in gt order are heldout/lights.lp's order.
    names = [l.split()[0].split('/')[-1] for l in open(f"{scene}/heldout/lights.lp").read().splitlines()[1:] if l.strip()]
    j = np.array([names.index(p) for p in photo])
    light = gt["heldout_light_dir_world"][j]
    n = gt["normals"][v] / np.linalg.norm(gt["normals"][v], axis=1, keepdims=True)
    e = cam - gt["positions"][v]
    e /= np.linalg.norm(e, axis=1, keepdims=True)
    h = light + e
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    ndl, nde = np.sum(n * light, 1), np.sum(n * e, 1)
    alpha = gt["ggx_alpha"][v]
    eta = 1.49
    mats = meta["materials"]
    assert all(m.get("type", "roughplastic") in ("roughplastic", "diffuse") for m in mats), mats
    spec = np.where(gt["is_glossy"][v], spec_value(nde, ndl, np.sum(n * h, 1), np.sum(e * h, 1), alpha, eta), 0)
    # Diffuse base: albedo_effective_normal * t(N.L) t(N.E) / t(1)^2 * N.L / pi (linear roughplastic).
    diff = np.zeros_like(ndl)
    for mid, mat in enumerate(mats):
        sel = gt["is_glossy"][v] & (gt["material_id"][v] == mid)
        if not sel.any():
            continue
        if "diffuse_factor_table" in mat:  # the scene generator's own pi f / rho against incidence
            tab = mat["diffuse_factor_table"]
            deg, fac = np.array(tab["incidence_deg"]), np.array(tab["pi_f_over_rho"])
            t = lambda c: np.interp(np.degrees(np.arccos(np.clip(c, 0, 1))), deg, fac)
        else:
            grid = np.linspace(0, 1, 65)
            tg = rough_transmittance(np.maximum(grid, 1e-4), mat["alpha"], eta)
            t = lambda c: np.interp(np.clip(c, 0, 1), grid, tg)
        diff[sel] = t(ndl[sel]) * t(nde[sel]) / t(1.0) ** 2
    diff = np.where(gt["is_glossy"][v], diff, 1.0) * np.maximum(ndl, 0) / np.pi
    lit = gt["heldout_lit"][v, j]
    truth = exposure * irradiance * (gt["albedo_effective_normal"][v] * diff[:, None] + spec[:, None]) * lit[:, None]
    truth = np.minimum(truth, 1.0)
    de_prod = lib.ciede2000(lib.linear_rgb_to_lab(obs), lib.linear_rgb_to_lab(np.minimum(pred, 1.0)))
    de_true = lib.ciede2000(lib.linear_rgb_to_lab(obs), lib.linear_rgb_to_lab(truth))
    check = np.abs(de_prod - de_csv)
    print(f"{len(rows)} samples; this script's CIEDE2000 of the product against vbrdf_eval's: max |diff| {check.max():.4f}")
    if not check.max() < 0.01:
        print("FAIL: this script's colour difference disagrees with vbrdf_eval's")
        return 1

    def line(name, sel):
        if sel.sum() == 0:
            return
        print(f"  {name:44s} {sel.sum():7d}  product {de_prod[sel].mean():6.3f} / {np.percentile(de_prod[sel], 95):6.3f}"
              f"   truth {de_true[sel].mean():6.3f} / {np.percentile(de_true[sel], 95):6.3f}")
    line("all", np.ones(len(rows), bool))
    line("clean footprint", np.array([r["mixed"] == "0" for r in rows]))
    line("mixed footprint", np.array([r["mixed"] != "0" for r in rows]))
    for s in [scene] + split_scenes:
        m = json.load(open(f"{s}/gt_scene.json"))
        c = np.array(m["camera"]["origin_world"])
        ev = c - gt["positions"][v]
        nv = np.sum(n * ev / np.linalg.norm(ev, axis=1, keepdims=True), 1)
        for lo, hi in ((-1, 0.2), (0.2, 0.4), (0.4, 1.01)):
            line(f"N.E of {s.rstrip('/').split('/')[-1]} in [{max(lo, 0):.1f}, {min(hi, 1):.1f})", (nv >= lo) & (nv < hi))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
