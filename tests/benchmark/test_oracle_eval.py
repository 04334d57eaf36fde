#!/usr/bin/python3
"""Checks oracle_eval.py's pieces without data: CIEDE2000 against Sharma, Wu and Dalal's (2005) test
pairs, the GGX distribution's normalisation, and the rough coat's reflectance at normal incidence
against the Fresnel F0 of the shared scenes' coat (0.0387 for index 1.49). Exit 1 on a failure."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import oracle_eval as oe  # noqa: E402

failures = []


def check(name, ok, detail):
    print(("ok   " if ok else "FAIL ") + name + ": " + detail)
    if not ok:
        failures.append(name)


# Sharma et al. 2005, Table 1: pairs 1, 7, 17, 25 (Lab1, Lab2, dE00).
pairs = [((50.0, 2.6772, -79.7751), (50.0, 0.0, -82.7485), 2.0425),
         ((50.0, 0.0, 0.0), (50.0, -1.0, 2.0), 2.3669),
         ((50.0, 2.5, 0.0), (73.0, 25.0, -18.0), 27.1492),
         ((60.2574, -34.0099, 36.2677), (60.4626, -34.1751, 39.4387), 1.2644)]
lab1 = np.array([p[0] for p in pairs])
lab2 = np.array([p[1] for p in pairs])
de = oe.ciede2000(lab1, lab2)
expected = np.array([p[2] for p in pairs])
check("CIEDE2000 on Sharma's pairs", np.all(np.abs(de - expected) < 1e-3), f"{np.round(de, 4)} against {expected}")
check("CIEDE2000 symmetric", np.allclose(de, oe.ciede2000(lab2, lab1)), "swapped pairs")
check("white is L 100", abs(oe.lab(np.ones((1, 3)))[0, 0] - 100) < 1e-6, "linear (1, 1, 1)")

# The GGX normal distribution integrates to 1 over projected solid angle (D(h) cos(theta_h) d omega).
n = 4000
th = (np.arange(n) + 0.5) / n * (np.pi / 2)
for alpha in (0.05, 0.15, 0.4):
    integral = np.sum(oe.ggx_d(np.cos(th), alpha) * np.cos(th) * np.sin(th)) * (np.pi / 2 / n) * 2 * np.pi
    check(f"GGX D normalised at alpha {alpha}", abs(integral - 1) < 5e-3, f"{integral:.4f}")

# Rough dielectric reflection at normal incidence: about the Fresnel F0 (slightly less: masking).
f0 = float(oe.fresnel_dielectric(np.array([1.0]), 1.49)[0])
r1 = 1 - float(oe.rough_transmittance(np.array([1.0]), 0.15, 1.49)[0])
check("rough coat reflectance at normal incidence", 0.9 * f0 < r1 <= f0 + 1e-3, f"{r1:.4f} against F0 {f0:.4f}")
check("Fresnel F0 of index 1.49", abs(f0 - 0.0387) < 2e-4, f"{f0:.5f}")
sys.exit(1 if failures else 0)
