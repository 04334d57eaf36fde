#pragma once
// Per-pixel RTI baselines, fitted at one point (pixel or vertex) from the photos of one viewpoint:
// what cultural-heritage staff would otherwise use to relight a capture. Used by the relighting
// evaluation to score the product against them on the same samples.
//
//  - PTM (Malzbender, Gelb, Wolters 2001): per colour channel a biquadratic polynomial in the
//    light direction's projection (lu, lv) on the image plane of the viewpoint (camera frame:
//    x right, y up, z towards the viewer):
//      f(lu, lv) = a0 lu^2 + a1 lv^2 + a2 lu lv + a3 lu + a4 lv + a5.
//  - RBF as in CNR-ISTI Relight: Gaussian kernel on the angle between light directions,
//      k(theta) = exp(-(theta / sigma)^2),
//    the form of Relight's RtiBuilder::buildResampleMap (exp(-d^2 / sigma^2) on the distance
//    between unit directions; here on the angle, as k(theta) above states), sigma = mean over the
//    training lights of the angle to the nearest other training light, ridge lambda:
//      (K + lambda I) w = y per channel,   f(l) = sum_i w_i k(angle(l, l_i)).
//    This plain kernel falls towards black far from sparse training lights.
//
// Plain arrays that the caller owns; nothing is allocated that outlives a call. Every output is
// finite for any finite input (degenerate inputs are handled as each function states).
#include <cstddef>

namespace vbrdf {

constexpr int kPtmCoefficients = 6;  // per channel; a fit is 3 x 6 floats, channel-major

// Least-squares PTM fit of `count` samples: light_uv[2*i..2*i+1] = (lu, lv) of sample i,
// rgb[3*i..3*i+2] its linear colour. Writes out_coefficients[6*c + j] = a_j of channel c.
// Plain least squares (column-pivoting QR) when count >= 6 and the 6 columns have full rank;
// otherwise (fewer than 6 samples, repeated or collinear light directions) the solution of the
// ridge system (A^T A + lambda I) a = A^T y with lambda = 1e-3 * (trace(A^T A) / 6 + 1e-12), which
// reproduces the data as closely as the ridge allows and keeps unconstrained coefficients small.
// count == 0: all coefficients 0 (predicts black). Non-finite samples are skipped.
void fit_ptm(const float *light_uv, const float *rgb, size_t count, float out_coefficients[3 * kPtmCoefficients]);

// PTM prediction at (lu, lv): out_rgb[c] = f_c(lu, lv), unclamped (may be negative or > 1).
void evaluate_ptm(const float coefficients[3 * kPtmCoefficients], float lu, float lv, float out_rgb[3]);

// Angle in radians between two directions (normalised here; 0 when either has zero length).
float light_angle(const float a[3], const float b[3]);

// RBF width: mean over the `count` directions (rows of 3 floats) of the angle to the nearest
// other direction. Safeguards: fewer than 2 directions -> pi/4; the result is at least 1e-3 rad
// (identical directions do not give a zero width).
float rbf_sigma(const float *light_dirs, size_t count);

// RBF fit: solves (K + ridge I) w = y per channel, K_ij = exp(-(angle(l_i, l_j) / sigma)^2).
// light_dirs: count x 3, rgb: count x 3; writes out_weights[3*i + c]. sigma > 0 (else replaced
// by rbf_sigma's floor), ridge >= 0 (a non-positive ridge is replaced by 1e-6). Solved with LDLT;
// if that fails or gives non-finite weights, with a complete orthogonal decomposition
// (minimum-norm least squares); if that too is non-finite, all weights 0.
void fit_rbf(const float *light_dirs, const float *rgb, size_t count, float sigma, float ridge, float *out_weights);

// RBF prediction at direction `dir`: out_rgb[c] = sum_i w_ic k(angle(dir, l_i)), unclamped.
// count == 0: black.
void evaluate_rbf(const float *light_dirs, const float *weights, size_t count, float sigma, const float dir[3],
                  float out_rgb[3]);

} // namespace vbrdf
