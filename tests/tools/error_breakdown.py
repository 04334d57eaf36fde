#!/usr/bin/env python3
"""Where the relit error sits: a breakdown of vbrdf_eval's per-sample dump (--samples-csv).

  error_breakdown.py SAMPLES.csv

Prints, for the product and beside it per-pixel PTM / RBF on the same samples, mean and p95 of
CIEDE2000 over: all samples; the samples the photo shows much darker than the model predicts
(observed < 0.3 x predicted: a cast shadow or occlusion the mesh does not produce); much brighter
(observed > 2 x predicted: a highlight the lobe misses, or a wrong normal); mixed footprints
(silhouettes and contacts); by fit_status; and the figures with each class left out, so that one
sees which class moves the p95. Needs numpy.
"""
import sys

import numpy as np


def summary(de):
    if de.size == 0:
        return '      -        -'
    return '%7.3f  %7.3f' % (de.mean(), np.percentile(de, 95))


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    d = np.genfromtxt(sys.argv[1], delimiter=',', names=True, dtype=None, encoding=None)
    if d.size == 0:
        sys.exit('%s: no samples' % sys.argv[1])
    d = np.atleast_1d(d)
    obs = d['obs_r'] + d['obs_g'] + d['obs_b']
    pred = d['pred_r'] + d['pred_g'] + d['pred_b']
    dark = obs < 0.3 * pred
    bright = obs > 2.0 * np.maximum(pred, 1e-6)
    mixed = d['mixed'] > 0
    base = (d['de_ptm'] >= 0) & (d['de_rbf'] >= 0)
    rows = [('all samples', np.ones(d.size, bool)),
            ('photo much darker than the model (< 0.3x)', dark),
            ('photo much brighter than the model (> 2x)', bright),
            ('mixed footprint (silhouette / contact)', mixed)]
    rows += [('fit_status %d' % s, d['fit_status'] == s) for s in np.unique(d['fit_status'])]
    rows += [('all but the much darker ones', ~dark), ('all but darker and brighter', ~(dark | bright)),
             ('all but mixed footprints', ~mixed)]
    total = d['de'].sum()
    print('%-44s %8s %7s %8s  %-16s  %-16s  %-16s' % ('CIEDE2000 mean / p95', 'samples', 'share', 'of error',
                                                      'product', 'PTM', 'RBF'))
    for label, m in rows:
        b = m & base
        print('%-44s %8d %6.1f%% %7.1f%%  %s  %s  %s' % (label, m.sum(), 100.0 * m.mean(),
                                                          100.0 * d['de'][m].sum() / max(total, 1e-12),
                                                          summary(d['de'][m]), summary(d['de_ptm'][b]),
                                                          summary(d['de_rbf'][b])))
    print('by held-out photo:')
    for photo in np.unique(d['photo']):
        m = d['photo'] == photo
        print('  %-42s %8d         %8s  %s  %s  %s' % (photo, m.sum(), '', summary(d['de'][m]),
                                                      summary(d['de_ptm'][m & base]), summary(d['de_rbf'][m & base])))


if __name__ == '__main__':
    main()
