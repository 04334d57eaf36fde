#pragma once
// The per-vertex reflectance model: the parameters a fit gives each vertex and their evaluation.
//
//     f_c = k_d d C_c + k_s g(s, alpha)   per colour channel c, for a light of unit irradiance
//
// d: the diffuse factor (diffuse_form.h: N.L, or N.L through a clear coat); g: the specular lobe
// of the cosine s (lobe.h: R.E or N.H, s^alpha or GGX), seen through the photo's pixel footprint.
// The relighting shaders evaluate the same terms (shaders/reflectance_model.glsl); the GPU fit's
// (shaders/reflectance_fit.comp) and the GLSL constants are checked against this model by
// tests/unit/model_constants_check.py.
//
// Normalisation of the k_d C ambiguity: C_max = max_c C_c = 1 and k_d = max_c rho_c (k_d carries
// the magnitude); a black vertex has k_d = 0 and C = (0,0,0). Sentinels for a vertex without any
// usable sample: status kFitNone, k_d = k_s = 0, shininess = 0, C = (0,0,0), dq = sq = rmse = 0.
#include <algorithm>
#include <cstdint>

#include "model/lobe.h"

namespace vbrdf {

enum FitStatus : uint8_t {
  kFitNone = 0,         // no usable sample: sentinels
  kFitDiffuseOnly = 1,  // k_s = 0 (not enough specular evidence)
  kFitFull = 2,         // all parameters fitted
  kFitFromNeighbours = 3,   // no usable sample of its own: parameters from the nearest fitted
                            //   vertices over the mesh (neighbour_fill.h); dq = sq = 0
  kFitFromWeakSamples = 4,  // no sample passes the strict rules: fitted from grazing and/or
                            //   contaminated (mixed-pixel) samples (fit_vertex_weak); k_s may be 0
};

struct VertexFit {
  float color[3];     // C, max channel 1
  float kd;           // k_d
  float ks;           // k_s
  float shininess;    // alpha (0 when not determined)
  float dq;           // diffuse quality in [0, 2] (thesis 4.7.1)
  float sq;           // specular quality in [0, 2]
  float rmse;         // sqrt(weighted mean squared residual per channel)
  uint16_t iterations;
  uint8_t status;     // FitStatus
  uint8_t converged;  // 1 when stopped by tolerance (not by the cap)
};

// True when the vertex has a reflectance model (any status but kFitNone).
inline bool has_model(const VertexFit &fit) { return fit.status != kFitNone; }

// Sets k_d and C from a diffuse reflectance rho = k_d C: k_d is its largest channel and C = rho / k_d
// (largest channel 1); C = 0 when k_d <= 0. The one place that splits k_d C; other fields untouched.
inline void set_kd_color(const double rho[3], VertexFit &fit) {
  const double kd = std::max(rho[0], std::max(rho[1], rho[2]));
  fit.kd = float(kd);
  for (int c = 0; c < 3; ++c) fit.color[c] = kd > 0 ? float(std::min(1.0, rho[c] / kd)) : 0.0f;
}

// Evaluates the model (fits, rendering, relighting and tests). Writes 3 channels.
// d: the diffuse factor (Sample::d: N.L for Lambert, diffuse_factor() in general); lobe_cos and
// form: the lobe's cosine (Sample::lobe_cos) and the form the fit used (ReflectanceFitOptions::lobe).
// footprint: the sample's Sample::footprint (the lobe seen through the photo's pixel footprint).
// A negative d is 0; no specular term where d <= 0 or k_s <= 0.
inline void evaluate_reflectance(const VertexFit &fit, float d_in, float lobe_cos, LobeForm form, float out_rgb[3],
                           float footprint = 0) {
  const float d = std::max(d_in, 0.0f);
  const float spec =
      (d > 0 && fit.ks > 0) ? fit.ks * float(lobe_value(form, lobe_cos, fit.shininess, footprint)) : 0.0f;
  for (int c = 0; c < 3; ++c) out_rgb[c] = fit.kd * d * fit.color[c] + spec;
}

} // namespace vbrdf
