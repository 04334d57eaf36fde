#pragma once
// Basic diffuse colour (thesis 4.4, with the erratum fixed).
//
// Model for a diffuse sample i of a vertex: P_i = rho * d_i (light of unit irradiance, white),
// rho = k_d * C the diffuse reflectance, d_i = N.L_i. The estimate is the least-squares solution
//     rho = sum_i d_i P_i / sum_i d_i^2
// (equivalently the mean of the per-sample ratios P_i / d_i weighted by d_i^2: brighter, less
// grazing samples count more). The thesis's "simplified" sum_i P_i / k_d drops the normalisation.
// One robust pass follows: samples whose luminance residual exceeds 3 scaled MADs (plus 1% of
// the estimate) are dropped and rho re-solved, which removes shadow-edge and highlight-edge
// samples the flags missed. Only samples passing is_diffuse_sample() are used; a vertex whose only
// otherwise usable samples are mixed pixels (silhouette, mesh border, contact with another surface)
// falls back to them and is marked `from_mixed_pixels` (a colour of lower confidence rather than
// none).
#include <cstdint>
#include <vector>

#include "samples/samples.h"

namespace vbrdf {

struct DiffuseEstimate {
  float rgb[3] = {0, 0, 0};   // linear diffuse reflectance rho = k_d * C (0 when !valid)
  uint16_t n_seen = 0;        // photos that see the vertex
  uint16_t n_diffuse = 0;     // diffuse samples used (after outlier rejection)
  uint16_t n_specular = 0;    // specular samples (R.E > T_s, lit, unsaturated)
  uint16_t n_rejected = 0;    // diffuse samples rejected as outliers
  bool valid = false;         // at least one diffuse sample
  bool from_mixed_pixels = false;  // estimated from mixed-pixel samples only
  bool from_rim_pixels = false;    // estimated from rim samples (kRimFootprint) only: the vertex
                                   //   lies on a silhouette or contact in every photo that sees it
};

// Least-squares reflectance of `count` samples (all assumed diffuse-usable). Returns false when
// sum d^2 is zero. No robust pass. Exposed for tests.
bool least_squares_reflectance(const Sample *samples, size_t count, float out_rgb[3]);

// Estimates every vertex of the chunk; `out` has chunk.vertex_count entries.
void estimate_diffuse_chunk(const SampleChunk &chunk, DiffuseEstimate *out);

} // namespace vbrdf
