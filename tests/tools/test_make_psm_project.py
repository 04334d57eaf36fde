#!/usr/bin/env python3
"""Unit tests of make_psm_project.py's geometry (numpy only; no shared data needed)."""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_psm_project as psm  # noqa: E402


class SkirtTest(unittest.TestCase):
    def setUp(self):
        self.mask = np.zeros((7, 8), bool)
        self.mask[2:5, 2:6] = True            # rows 2..4, cols 2..5
        self.depth = np.zeros((7, 8))
        self.depth[2:5, 2:6] = np.arange(12, dtype=float).reshape(3, 4)
        self.normals = np.zeros((7, 8, 3))
        self.normals[2:5, 2:6] = (0.0, 0.0, 1.0)

    def test_ring_vertices_sit_on_the_mask_pixels_edges(self):
        rows, cols, shifts, depth, normals, covered = psm.skirt(self.mask, self.depth, self.normals)
        self.assertEqual(len(rows), 6 * 5 - 12)         # the 8-neighbourhood ring of a 3x4 block
        pos = {(r, c): (r + s[0], c + s[1]) for r, c, s in zip(rows, cols, shifts)}
        self.assertEqual(pos[(1, 3)], (1.5, 3.0))       # above: half a pixel down, onto the edge
        self.assertEqual(pos[(3, 6)], (3.0, 5.5))       # right: half a pixel left
        self.assertEqual(pos[(1, 1)], (1.5, 1.5))       # a corner: onto the mask's corner
        self.assertEqual(pos[(5, 6)], (4.5, 5.5))
        self.assertTrue(covered[1:6, 1:7].all() and covered.sum() == 30)
        np.testing.assert_allclose(normals, np.tile([0.0, 0.0, 1.0], (len(rows), 1)))
        i = [k for k in range(len(rows)) if (rows[k], cols[k]) == (1, 1)][0]
        self.assertAlmostEqual(depth[i], self.depth[2, 2])  # a corner has one mask neighbour
        i = [k for k in range(len(rows)) if (rows[k], cols[k]) == (1, 3)][0]
        self.assertAlmostEqual(depth[i], np.mean(self.depth[2, 2:5]))

    def test_faces_cover_every_mask_pixel_whole(self):
        rows, cols, shifts, _, _, covered = psm.skirt(self.mask, self.depth, self.normals)
        mr, mc = np.nonzero(self.mask)
        idx = -np.ones(self.mask.shape, np.int64)
        idx[mr, mc] = np.arange(len(mr))
        idx[rows, cols] = len(mr) + np.arange(len(rows))
        faces = psm.relief_faces(covered, idx)
        pts = np.concatenate([np.stack([mr, mc], 1).astype(float), np.stack([rows, cols], 1) + shifts])
        area = 0.5 * np.abs(np.cross(pts[faces[:, 1]] - pts[faces[:, 0]], pts[faces[:, 2]] - pts[faces[:, 0]]))
        self.assertAlmostEqual(area.sum(), float(self.mask.sum()))  # exactly the mask's pixels
        self.assertTrue(np.all(area > 0))


if __name__ == '__main__':
    unittest.main()
