#pragma once
// Per-vertex light geometry shared by the coverage run, the suggestions and the failed-prediction
// test: unit normals and eye directions, and whether a light covers a vertex (for unit vectors).
#include <cmath>

#include "base/vec3.h"
#include "coverage/coverage.h"

namespace vbrdf {
namespace coverage_geometry {

// A mesh normal, normalised (file normals need not be unit length).
inline void unit_normal(const float *n, float out[3]) {
  const float l = std::sqrt(dot3(n, n));
  for (int k = 0; k < 3; ++k) out[k] = l > 0 ? n[k] / l : 0.0f;
}

inline void eye_direction(const float centre[3], const float *p, float e[3]) {
  for (int k = 0; k < 3; ++k) e[k] = centre[k] - p[k];
  const float l = std::sqrt(dot3(e, e));
  for (int k = 0; k < 3; ++k) e[k] = l > 0 ? e[k] / l : 0.0f;
}

// light_covers_diffuse / light_covers_specular (coverage.h) for unit vectors, without their
// renormalisation: this runs per vertex and photo.
inline bool covers_unit(CoverageKind kind, const float *n, const float *e, const float *l, const LightSuggestionSettings &s) {
  const float d = dot3(n, l);
  if (d <= 0) return false;
  const float spec = 2 * d * dot3(n, e) - dot3(l, e);  // R.E with R = 2 (N.L) N - L
  return kind == CoverageKind::Specular ? spec > s.specular_threshold
                                        : d >= s.diffuse_threshold && spec <= s.specular_threshold;
}

} // namespace coverage_geometry
} // namespace vbrdf
