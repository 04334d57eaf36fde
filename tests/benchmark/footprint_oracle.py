#!/usr/bin/python3
"""What a photo's pixel footprint does to a shared scene's pixels (docs/decisions/pixel_footprint_lobe.md).

    footprint_oracle.py SCENE_DIR [--photos heldout|training] [--common OTHER_SCENE_DIR] [--pooled-lobe]

Predicts the photos of SCENE_DIR (16-bit linear, colour correction off) with the scene's TRUE
reflectance (oracle_eval.py's Mitsuba roughplastic: GGX lobe, dielectric Fresnel, Smith masking, the
coat's diffuse table) in two ways and scores both with CIEDE2000 at every ground-truth-visible lit
vertex (saturated pixels left out), sampled as the product samples: bilinearly at the vertex's pixel.
  at the vertex:        the vertex's own normal and albedo (what vbrdf_eval compares a model with);
  through the footprint: the mean over the pixel footprint of the sample: the 4 pixels of the
                        bilinear sample, each a box (the scenes' reconstruction filter) of 4 x 4
                        subpixels, each subpixel's surface point found among the triangles of the
                        vertex's 2-ring (nearest in depth), with normal and albedo interpolated
                        linearly over its triangle as Mitsuba shades (the albedo from the per-vertex
                        truth, so detail finer than the mesh is not represented).
"clean" footprints are those whose every subpixel lies on the vertex's own surface (2-ring, depth
within 5 %). --common: only vertices that camera sees too (the spot pair). --pooled-lobe: on the
glossy vertices' training samples near the highlight (N.H within 0.3 rad), the photo minus the true
diffuse against one GGX lobe k * spec(alpha) with k free, at the vertex and through the footprint,
over a grid of alpha: the roughness each explains the photos with best.
Only numpy and the repository's scripts. Figures: docs/decisions/pixel_footprint_lobe.md.
"""
import argparse
import json
import os
import sys

import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "e2e"))
sys.path.insert(0, os.path.join(here, "..", "tools"))
sys.path.insert(0, here)
import e2e_lib as lib  # noqa: E402
import make_psm_project as mp  # noqa: E402  (its 16-bit PNG reader)
from oracle_eval import spec_value  # noqa: E402

SUB = (np.arange(4) + 0.5) / 4
K = 64  # 4 pixels x 4 x 4 subpixels


def footprints(gt, sel):
    """Per selected vertex: K subpixel normals, albedos, glossy weights and weights; clean flags."""
    P, F = gt["positions"].astype(float), gt["faces"]
    N = gt["normals"].astype(float)
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    xy, dep = gt["pixel_xy"].astype(float), gt["depth"].astype(float)
    alb, glossy = gt["albedo_effective_normal"].astype(float), gt["is_glossy"].astype(float)
    vf = [[] for _ in range(len(P))]
    for fi, tri in enumerate(F):
        for x in tri:
            vf[x].append(fi)
    out_n, out_a = np.zeros((len(sel), K, 3)), np.zeros((len(sel), K, 3))
    out_g, out_w = np.zeros((len(sel), K)), np.zeros((len(sel), K))
    clean = np.zeros(len(sel), bool)
    r = np.arange(K)
    for i, v in enumerate(sel):
        x, y = xy[v]
        fx, fy = x - 0.5, y - 0.5
        x0, y0 = np.floor(fx), np.floor(fy)
        ax, ay = fx - x0, fy - y0
        pts, w = [], []
        for px, py, bw in ((x0, y0, (1 - ax) * (1 - ay)), (x0 + 1, y0, ax * (1 - ay)), (x0, y0 + 1, (1 - ax) * ay),
                           (x0 + 1, y0 + 1, ax * ay)):
            for sx in SUB:
                for sy in SUB:
                    pts.append((px + sx, py + sy))
                    w.append(bw / 16)
        pts, w = np.array(pts), np.array(w)
        ring = set()
        for u in set(F[vf[v]].ravel()):
            ring.update(vf[u])
        fs = F[list(ring)]
        A, B, C = xy[fs[:, 0]], xy[fs[:, 1]], xy[fs[:, 2]]
        d = (B[:, 1] - C[:, 1]) * (A[:, 0] - C[:, 0]) + (C[:, 0] - B[:, 0]) * (A[:, 1] - C[:, 1])
        ok = np.abs(d) > 1e-12
        dd = np.where(ok, d, 1)[None]
        l1 = ((B[None, :, 1] - C[None, :, 1]) * (pts[:, None, 0] - C[None, :, 0]) +
              (C[None, :, 0] - B[None, :, 0]) * (pts[:, None, 1] - C[None, :, 1])) / dd
        l2 = ((C[None, :, 1] - A[None, :, 1]) * (pts[:, None, 0] - C[None, :, 0]) +
              (A[None, :, 0] - C[None, :, 0]) * (pts[:, None, 1] - C[None, :, 1])) / dd
        l3 = 1 - l1 - l2
        inside = (l1 >= -1e-9) & (l2 >= -1e-9) & (l3 >= -1e-9) & ok[None]
        z = np.where(inside, l1 * dep[fs[None, :, 0]] + l2 * dep[fs[None, :, 1]] + l3 * dep[fs[None, :, 2]], np.inf)
        k = np.argmin(z, axis=1)
        zk = z[r, k]
        hit = np.isfinite(zk) & (np.abs(zk - dep[v]) < 0.05 * dep[v])
        clean[i] = hit.all()
        f = fs[k]
        b = np.stack([l1[r, k], l2[r, k], l3[r, k]], 1)
        n = (b[:, :, None] * N[f]).sum(1)
        out_n[i] = n / np.linalg.norm(n, axis=1, keepdims=True)
        out_a[i] = (b[:, :, None] * alb[f]).sum(1)
        out_g[i] = (b * glossy[f]).sum(1)
        out_w[i] = w * hit
    out_w /= np.maximum(out_w.sum(1, keepdims=True), 1e-12)
    return out_n, out_a, out_g, out_w, clean


def bilinear(img, x, y):
    fx, fy = x - 0.5, y - 0.5
    x0, y0 = np.floor(fx).astype(int), np.floor(fy).astype(int)
    ax, ay = fx - x0, fy - y0
    h, w = img.shape[:2]

    def p(yy, xx):
        return img[np.clip(yy, 0, h - 1), np.clip(xx, 0, w - 1)][:, :3]
    return (((1 - ax) * (1 - ay))[:, None] * p(y0, x0) + (ax * (1 - ay))[:, None] * p(y0, x0 + 1) +
            ((1 - ax) * ay)[:, None] * p(y0 + 1, x0) + (ax * ay)[:, None] * p(y0 + 1, x0 + 1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--photos", choices=("heldout", "training"), default="heldout")
    ap.add_argument("--common")
    ap.add_argument("--pooled-lobe", action="store_true")
    a = ap.parse_args()
    meta = json.load(open(os.path.join(a.scene, "gt_scene.json")))
    gt = np.load(os.path.join(a.scene, "gt_vertex.npz"))
    scale = meta["camera_response"]["exposure"] * meta["lights"]["irradiance"]
    cam = np.array(meta["camera"]["origin_world"])
    vis = gt["visible"] & ~gt["occluded_by_props"]
    if a.common:
        vis &= np.load(os.path.join(a.common, "gt_vertex.npz"))["visible"]
    sel = np.where(vis)[0]
    fN, fA, fG, fW, clean = footprints(gt, sel)
    N = gt["normals"].astype(float)[sel]
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    E = cam - gt["positions"].astype(float)[sel]
    E /= np.linalg.norm(E, axis=1, keepdims=True)
    glossy = [m for m in meta["materials"] if m["type"] == "roughplastic"]
    alpha_true = glossy[0]["alpha"] if glossy else 0.1
    eta = 1.49
    if glossy and "diffuse_factor_table" in glossy[0]:
        tab = glossy[0]["diffuse_factor_table"]
        deg, fac = np.array(tab["incidence_deg"]), np.array(tab["pi_f_over_rho"])
        t = lambda c: np.interp(np.degrees(np.arccos(np.clip(c, 0, 1))), deg, fac)  # noqa: E731
    else:
        t = lambda c: np.ones_like(c)  # noqa: E731

    def parts(n, e, light, alpha):
        """Diffuse factor (per unit albedo) and specular value for unit vectors (any leading shape)."""
        h = light + e
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        ndl, nde = np.sum(n * light, -1), np.sum(n * e, -1)
        sp = spec_value(np.maximum(nde, 1e-6), ndl, np.sum(n * h, -1), np.sum(e * h, -1), alpha, eta) * (ndl > 0)
        return t(ndl) * t(nde) / t(1.0) ** 2 * np.maximum(ndl, 0) / np.pi, np.maximum(ndl, 0) / np.pi, sp

    lp = os.path.join(a.scene, "heldout", "lights.lp") if a.photos == "heldout" else os.path.join(a.scene, "lights.lp")
    names = [ln.split()[0].split("/")[-1] for ln in open(lp).read().splitlines()[1:] if ln.strip()]
    dirs = gt["heldout_light_dir_world" if a.photos == "heldout" else "light_dir_world"]
    lits = gt["heldout_lit" if a.photos == "heldout" else "lit"]
    img_dir = os.path.join(a.scene, "heldout", "linear") if a.photos == "heldout" else os.path.join(a.scene, "linear")
    g_v = gt["is_glossy"].astype(float)[sel]
    de_v, de_f, cl, lobe_rows = [], [], [], []
    Eb = np.broadcast_to(E[:, None], fN.shape)
    for j, name in enumerate(names):
        obs = bilinear(mp.read_png(os.path.join(img_dir, name)).astype(float) / 65535.0, gt["pixel_xy"][sel, 0],
                       gt["pixel_xy"][sel, 1])
        light = dirs[j].astype(float)
        dc, dl, sp = parts(N, E, light[None], alpha_true)
        at_vertex = gt["albedo_effective_normal"][sel] * (g_v * dc + (1 - g_v) * dl)[:, None] + (g_v * sp)[:, None]
        dcf, dlf, spf = parts(fN, Eb, np.broadcast_to(light, fN.shape), alpha_true)
        through = (fW[..., None] * (fA * (fG * dcf + (1 - fG) * dlf)[..., None] + (fG * spf)[..., None])).sum(1)
        m = lits[sel, j] & (obs.max(1) < 0.999)
        lab = lib.linear_rgb_to_lab(obs[m])
        de_v.append(lib.ciede2000(lab, lib.linear_rgb_to_lab(np.minimum(scale * at_vertex[m], 1))))
        de_f.append(lib.ciede2000(lab, lib.linear_rgb_to_lab(np.minimum(scale * through[m], 1))))
        cl.append(clean[m])
        if a.pooled_lobe and glossy:
            h = light + E
            h /= np.linalg.norm(h, axis=1, keepdims=True)
            near = m & (g_v > 0.999) & (np.sum(N * h, 1) > np.cos(0.3))
            y = obs[near] / scale
            lum = np.array([0.2126, 0.7152, 0.0722])
            diff_v = (gt["albedo_effective_normal"][sel][near] * dc[near][:, None]) @ lum
            diff_f = (fW[near][..., None] * fA[near] * dcf[near][..., None]).sum(1) @ lum
            lobe_rows.append((np.where(near)[0], light, y @ lum - diff_v, y @ lum - diff_f))
    de_v, de_f, cl = np.concatenate(de_v), np.concatenate(de_f), np.concatenate(cl)
    name = os.path.basename(os.path.normpath(a.scene))
    for label, m in (("all", np.ones(len(de_v), bool)), ("clean footprints", cl)):
        print(f"{name} {a.photos} {label:17s} {m.sum():7d}  truth at the vertex {de_v[m].mean():.3f} / "
              f"{np.percentile(de_v[m], 95):.3f}   through the footprint {de_f[m].mean():.3f} / {np.percentile(de_f[m], 95):.3f}")
    if lobe_rows:
        idx = np.concatenate([r[0] for r in lobe_rows])
        L = np.concatenate([np.broadcast_to(r[1], (len(r[0]), 3)) for r in lobe_rows])
        yv, yf = np.concatenate([r[2] for r in lobe_rows]), np.concatenate([r[3] for r in lobe_rows])
        print(f"pooled GGX lobe on {len(idx)} glossy samples near the highlight (truth alpha {alpha_true}, "
              f"exponent 2/alpha^2 - 2 = {2 / alpha_true ** 2 - 2:.0f}):")
        best = {}
        for alpha in np.geomspace(0.5 * alpha_true, 2 * alpha_true, 17):
            pv = spec_value(np.maximum(np.sum(N[idx] * E[idx], 1), 1e-6), *(lambda h: (
                np.sum(N[idx] * L, 1), np.sum(N[idx] * h, 1), np.sum(E[idx] * h, 1)))(
                (L + E[idx]) / np.linalg.norm(L + E[idx], axis=1, keepdims=True)), alpha, eta) * (np.sum(N[idx] * L, 1) > 0)
            Lf = np.broadcast_to(L[:, None], fN[idx].shape)
            pf = (fW[idx] * parts(fN[idx], Eb[idx], Lf, alpha)[2]).sum(1)
            for key, p, y in (("at the vertex", pv, yv), ("through the footprint", pf, yf)):
                k = (p @ y) / max(p @ p, 1e-30)
                rms = np.sqrt(np.mean((y - k * p) ** 2))
                if key not in best or rms < best[key][1]:
                    best[key] = (alpha, rms, k)
        for key, (alpha, rms, k) in best.items():
            print(f"  {key:22s} best alpha {alpha:.4f} (exponent {2 / alpha ** 2 - 2:.0f}, "
                  f"{(2 / alpha ** 2 - 2) / (2 / alpha_true ** 2 - 2):.2f}x the truth), scale {k:.3f}, rms {rms:.5f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
