#!/usr/bin/python3
"""Checks oracle_eval.py's own pieces without data: the GGX distribution's normalisation, and the
rough coat's reflectance at normal incidence against the Fresnel F0 of the shared scenes' coat
(0.0387 for index 1.49). Its CIELAB / CIEDE2000 are e2e_lib's, checked on Sharma's pairs by
tests/e2e/test_e2e_lib.py. Exit 1 on a failure."""
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


# The GGX normal distribution integrates to 1 over projected solid angle (D(h) cos(theta_h) d omega).
n = 4000
th = (np.arange(n) + 0.5) / n * (np.pi / 2)
for alpha in (0.05, 0.15, 0.4):
    integral = np.sum(oe.ggx_d(np.cos(th), alpha) * np.cos(th) * np.sin(th)) * (np.pi / 2 / n) * 2 * np.pi
    check(f"GGX D normalised at alpha {alpha}", abs(integral - 1) < 5e-3, f"{integral:.4f}")

# Rough dielectric reflection at normal incidence: about the Fresnel F0 (slightly less: masking).
f0 = float(oe.lib.fresnel_dielectric(np.array([1.0]), 1.49)[0])
r1 = 1 - float(oe.rough_transmittance(np.array([1.0]), 0.15, 1.49)[0])
check("rough coat reflectance at normal incidence", 0.9 * f0 < r1 <= f0 + 1e-3, f"{r1:.4f} against F0 {f0:.4f}")
check("Fresnel F0 of index 1.49", abs(f0 - 0.0387) < 2e-4, f"{f0:.5f}")
sys.exit(1 if failures else 0)
