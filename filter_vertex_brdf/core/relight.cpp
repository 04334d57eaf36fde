#include "relight.h"

#include <algorithm>
#include <cmath>

#include "color_difference.h"

namespace vbrdf {

namespace {
double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const size_t k = std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + long(k), v.end());
  return v[k];
}
} // namespace

RelightStats evaluate_relighting(const MeshView &mesh, const std::vector<VertexFit> &fits,
                                 const std::vector<Raster> &rasters,
                                 const std::vector<std::array<float, 3>> &light_dirs_world, VisibilityBackend &visibility,
                                 const GatherSettings &settings) {
  RelightStats stats;
  stats.per_raster_mean_de2000.assign(rasters.size(), 0.0);
  stats.per_raster_samples.assign(rasters.size(), 0);
  const VisibilityMasks masks = compute_visibility(mesh, rasters, light_dirs_world, visibility);
  PhotoCache photos(settings.encoding, settings.saturation_level, settings.photo_cache_bytes);
  std::vector<double> de;
  double squared_error = 0;
  size_t channels = 0;
  gather_samples(mesh, rasters, light_dirs_world, masks, settings, photos, [&](const SampleChunk &chunk) {
    for (uint32_t i = 0; i < chunk.vertex_count; ++i) {
      const VertexFit &fit = fits[chunk.first_vertex + i];
      if (fit.status == kFitNone) continue;
      for (uint32_t k = chunk.offsets[i]; k < chunk.offsets[i + 1]; ++k) {
        const Sample &s = chunk.samples[k];
        if ((s.flags & (kShadowed | kSaturated | kMixedPixel)) || !(s.n_dot_l > 0)) continue;
        float predicted[3];
        evaluate_phong(fit, s.n_dot_l, s.r_dot_e, predicted);
        const double d = delta_e2000_linear_srgb(predicted, s.rgb);
        de.push_back(d);
        stats.per_raster_mean_de2000[s.raster] += d;
        ++stats.per_raster_samples[s.raster];
        for (int c = 0; c < 3; ++c) {
          const double e = double(std::min(predicted[c], 1.0f)) - double(s.rgb[c]);
          squared_error += e * e;
        }
        channels += 3;
      }
    }
  });
  for (size_t r = 0; r < rasters.size(); ++r)
    if (stats.per_raster_samples[r]) stats.per_raster_mean_de2000[r] /= double(stats.per_raster_samples[r]);
  stats.samples = de.size();
  if (!de.empty()) {
    double sum = 0;
    for (double d : de) sum += d;
    stats.mean_de2000 = sum / double(de.size());
    stats.median_de2000 = percentile(de, 0.5);
    stats.p95_de2000 = percentile(de, 0.95);
    const double mse = squared_error / double(std::max<size_t>(channels, 1));
    stats.psnr_db = mse > 0 ? 10 * std::log10(1.0 / mse) : 99.0;
  }
  return stats;
}

} // namespace vbrdf
