#include "samples/diffuse_color.h"

#include <algorithm>
#include <cmath>

#include "base/luminance.h"

namespace vbrdf {

namespace {
float median(std::vector<float> &v) {
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + long(mid), v.end());
  return v[mid];
}

// One robust pass: drop samples whose luminance residual |P - rho d| is beyond
// 3 * 1.4826 * MAD + 1% of the fitted luminance. Needs >= 4 samples to say anything.
size_t reject_outliers(std::vector<Sample> &used, const float rho[3]) {
  if (used.size() < 4) return 0;
  const float rho_y = luminance(rho);
  std::vector<float> residuals(used.size());
  for (size_t i = 0; i < used.size(); ++i) residuals[i] = luminance(used[i].rgb) - rho_y * used[i].d;
  std::vector<float> abs_dev(residuals.size());
  for (size_t i = 0; i < residuals.size(); ++i) abs_dev[i] = std::fabs(residuals[i]);
  const float mad = median(abs_dev);
  const float limit = 3.0f * 1.4826f * mad + 0.01f * rho_y;
  const size_t before = used.size();
  size_t keep = 0;
  for (size_t i = 0; i < used.size(); ++i)
    if (std::fabs(residuals[i]) <= limit) used[keep++] = used[i];
  used.resize(keep);
  return before - keep;
}
} // namespace

bool least_squares_reflectance(const Sample *samples, size_t count, float out_rgb[3]) {
  double dd = 0, dp[3] = {0, 0, 0};
  for (size_t i = 0; i < count; ++i) {
    const double d = samples[i].d;
    dd += d * d;
    for (int c = 0; c < 3; ++c) dp[c] += d * double(samples[i].rgb[c]);
  }
  // Safeguard: no usable geometry term (all d = 0) means no estimate, never a division by zero.
  if (!(dd > 1e-12)) {
    out_rgb[0] = out_rgb[1] = out_rgb[2] = 0;
    return false;
  }
  for (int c = 0; c < 3; ++c) out_rgb[c] = float(std::max(0.0, dp[c] / dd));
  return true;
}

void estimate_diffuse_chunk(const SampleChunk &chunk, DiffuseEstimate *out) {
#pragma omp parallel
  {
    std::vector<Sample> used;
#pragma omp for schedule(dynamic, 256)
    for (long long i = 0; i < (long long)chunk.vertex_count; ++i) {
      DiffuseEstimate est;
      used.clear();
      const uint32_t begin = chunk.offsets[size_t(i)], end = chunk.offsets[size_t(i) + 1];
      est.n_seen = uint16_t(std::min<uint32_t>(end - begin, 65535));
      for (uint32_t k = begin; k < end; ++k) {
        const Sample &s = chunk.samples[k];
        if (is_specular_sample(s)) ++est.n_specular;
        if (is_diffuse_sample(s)) used.push_back(s);
      }
      if (used.empty())  // fall back to mixed pixels rather than leave the vertex without colour
        for (uint32_t k = begin; k < end; ++k) {
          Sample s = chunk.samples[k];
          s.flags = uint16_t(s.flags & ~kMixedPixel);
          if (is_diffuse_sample(s)) used.push_back(s), est.from_mixed_pixels = true;
        }
      est.from_rim_pixels = !used.empty() && std::all_of(used.begin(), used.end(), [](const Sample &s) {
        return (s.flags & kRimFootprint) != 0;
      });
      if (least_squares_reflectance(used.data(), used.size(), est.rgb)) {
        est.n_rejected = uint16_t(reject_outliers(used, est.rgb));
        if (est.n_rejected) least_squares_reflectance(used.data(), used.size(), est.rgb);
        est.valid = !used.empty();
      }
      est.n_diffuse = uint16_t(used.size());
      out[i] = est;
    }
  }
}

} // namespace vbrdf
