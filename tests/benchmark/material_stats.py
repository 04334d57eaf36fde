#!/usr/bin/python3
"""Specular figures of a fit against a shared scene's ground truth.

  material_stats.py FIT.ply SCENE_DIR [--check]
  material_stats.py --fit-tool vbrdf_fit --work DIR SCENE_DIR [--check]

Over the ground-truth visible vertices (gt_vertex.npz `visible`): share of glossy-material vertices
with k_s > 0; share of diffuse-material vertices with k_s below 1 % of k_d; the median fitted
shininess of glossy vertices with k_s > 0 against the truth for the fit's lobe form (`lobe_form`;
`phong_shininess_approx` is the N.H exponent; the R.E exponent is about a quarter of it); and the found `material` labels against
the true `material_id` (vertex counts per pair). Needs numpy.
--fit-tool: fit SCENE_DIR/project.mlp first (16-bit linear photos, colour correction off, the fit's
defaults: the acceptance protocol) into DIR/fit.ply. --check: exit 1 unless the lobe acceptance
bounds hold: >= 95 %
of the glossy vertices with k_s > 0, >= 95 % of the diffuse ones with k_s below 1 % of k_d, and the
median exponent within 30 % of the truth for the lobe's form.
"""
import subprocess
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'e2e'))
import e2e_lib  # noqa: E402  (the project's one PLY reader for scripts)


def read_ply_vertices(path):
    return e2e_lib.read_ply(path).vertex


def main():
    args = sys.argv[1:]
    check = '--check' in args
    args = [a for a in args if a != '--check']
    if args and args[0] == '--fit-tool':
        tool, work, scene = args[1], args[3], args[4]
        os.makedirs(work, exist_ok=True)
        fit_path = os.path.join(work, 'fit.ply')
        run = subprocess.run([tool, scene + '/project.mlp', '--photo-dir', scene + '/linear', '--color-correction', 'off',
                              '--out', fit_path], capture_output=True, text=True)
        if run.returncode != 0:
            print(run.stdout + run.stderr)
            print('FAIL: vbrdf_fit exit %d' % run.returncode)
            return 1
        args = [fit_path, scene]
    if len(args) != 2:
        print(__doc__)
        return 2
    fit = read_ply_vertices(args[0])
    gt = np.load(args[1] + '/gt_vertex.npz')
    failures = []
    vis = gt['visible'].astype(bool)
    glossy = gt['is_glossy'].astype(bool)
    ks, kd, alpha = fit['ks'], fit['kd'], fit['shininess']
    g = vis & glossy
    d = vis & ~glossy
    print('glossy visible vertices with k_s > 0: %.1f %% of %d' % (100 * np.mean(ks[g] > 0), g.sum()))
    if g.any() and np.mean(ks[g] > 0) < 0.95:
        failures.append('glossy vertices with k_s > 0 below 95 %')
    if d.any():
        print('diffuse visible vertices with k_s < 1 %% of k_d: %.1f %% of %d' % (100 * np.mean(ks[d] <= 0.01 * kd[d]), d.sum()))
        if np.mean(ks[d] <= 0.01 * kd[d]) < 0.95:
            failures.append('diffuse vertices with k_s ~ 0 below 95 %')
    sel = g & (ks > 0)
    # The lobe's form from the fit's per-vertex lobe_form (absent from a file: R.E).
    nh = 'lobe_form' in fit.dtype.names and bool(np.any(fit['lobe_form'][vis] > 0.5))
    if sel.any():
        truth = float(np.median(gt['phong_shininess_approx'][g]))
        med = float(np.median(alpha[sel]))
        if nh:
            ratio = med / truth
            print('median fitted shininess (N.H) %.1f; truth N.H %.1f (ratio to the truth %.2f)'
                  % (med, truth, ratio))
        else:
            ratio = med / (truth / 4)
            print('median fitted shininess (R.E) %.1f; truth N.H %.1f, R.E about %.1f (ratio to R.E truth %.2f)'
                  % (med, truth, truth / 4, ratio))
        if not 0.7 <= ratio <= 1.3:
            failures.append('median exponent %.2f x the truth, not within 30 %%' % ratio)
    elif g.any():
        failures.append('no glossy vertex with a lobe')
    if 'material' in fit.dtype.names:
        lab = fit['material'].astype(int)
        for m in np.unique(lab[vis]):
            row = ['true %d: %d' % (t, np.sum(vis & (lab == m) & (gt['material_id'] == t)))
                   for t in np.unique(gt['material_id'])]
            print('found material %d: %s' % (m, ', '.join(row)))
    if check:
        for f in failures:
            print('FAIL: ' + f)
        if failures:
            return 1
        print('OK: the acceptance bounds on the lobes hold')
    return 0


if __name__ == '__main__':
    sys.exit(main())
