#!/usr/bin/python3
"""Specular figures of a fit against a shared scene's ground truth (issue 16).

  material_stats.py FIT.ply SCENE_DIR

Over the ground-truth visible vertices (gt_vertex.npz `visible`): share of glossy-material vertices
with k_s > 0; share of diffuse-material vertices with k_s below 1 % of k_d; the median fitted
shininess of glossy vertices with k_s > 0 against the truth for the fit's lobe form (`lobe_form`;
`phong_shininess_approx` is the N.H exponent; the R.E exponent is about a quarter of it); and the found `material` labels against
the true `material_id` (vertex counts per pair). Needs numpy.
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'e2e'))
import e2e_lib  # noqa: E402  (the project's one PLY reader for scripts)


def read_ply_vertices(path):
    return e2e_lib.read_ply(path).vertex


def main():
    fit = read_ply_vertices(sys.argv[1])
    gt = np.load(sys.argv[2] + '/gt_vertex.npz')
    vis = gt['visible'].astype(bool)
    glossy = gt['is_glossy'].astype(bool)
    ks, kd, alpha = fit['ks'], fit['kd'], fit['shininess']
    g = vis & glossy
    d = vis & ~glossy
    print('glossy visible vertices with k_s > 0: %.1f %% of %d' % (100 * np.mean(ks[g] > 0), g.sum()))
    if d.any():
        print('diffuse visible vertices with k_s < 1 %% of k_d: %.1f %% of %d' % (100 * np.mean(ks[d] <= 0.01 * kd[d]), d.sum()))
    sel = g & (ks > 0)
    # The lobe's form from the fit's per-vertex lobe_form (absent: R.E, files before issue 16).
    nh = 'lobe_form' in fit.dtype.names and bool(np.any(fit['lobe_form'][vis] > 0.5))
    if sel.any():
        truth = float(np.median(gt['phong_shininess_approx'][g]))
        med = float(np.median(alpha[sel]))
        if nh:
            print('median fitted shininess (N.H) %.1f; truth N.H %.1f (ratio to the truth %.2f)'
                  % (med, truth, med / truth))
        else:
            print('median fitted shininess (R.E) %.1f; truth N.H %.1f, R.E about %.1f (ratio to R.E truth %.2f)'
                  % (med, truth, truth / 4, med / (truth / 4)))
    if 'material' in fit.dtype.names:
        lab = fit['material'].astype(int)
        for m in np.unique(lab[vis]):
            row = ['true %d: %d' % (t, np.sum(vis & (lab == m) & (gt['material_id'] == t)))
                   for t in np.unique(gt['material_id'])]
            print('found material %d: %s' % (m, ', '.join(row)))


if __name__ == '__main__':
    main()
