#include "fit/photo_shadows.h"

#include <cmath>
#include <vector>

namespace vbrdf {

namespace {
float mean_rgb(const float rgb[3]) { return (rgb[0] + rgb[1] + rgb[2]) / 3.0f; }

bool usable(const Sample &s) {
  return !(s.flags & (kShadowed | kSaturated | kNotSeen)) && s.d > 0 && std::isfinite(s.d) &&
         std::isfinite(s.lobe_cos) && std::isfinite(s.rgb[0]) && std::isfinite(s.rgb[1]) && std::isfinite(s.rgb[2]);
}
} // namespace

size_t flag_photo_shadows(const VertexFit &fit, Sample *samples, size_t count, const PhotoShadowSettings &settings) {
  if (!settings.enabled || !has_model(fit)) return 0;
  std::vector<size_t> dark;
  size_t n_usable = 0;
  for (size_t k = 0; k < count; ++k) {
    const Sample &s = samples[k];
    if (!usable(s)) continue;
    ++n_usable;
    // Against the diffuse part alone: a shadow darkens all of a sample, while a sample below an
    // overshooting lobe is only darker than diffuse + lobe (that is the lobe's misfit, not a shadow).
    const float diffuse[3] = {fit.kd * fit.color[0] * s.d, fit.kd * fit.color[1] * s.d, fit.kd * fit.color[2] * s.d};
    const float expected = mean_rgb(diffuse);
    if (expected >= settings.min_predicted && mean_rgb(s.rgb) < settings.darker_than * expected) dark.push_back(k);
  }
  if (dark.empty() || n_usable - dark.size() < kPhotoShadowMinRemaining ||
      float(dark.size()) > settings.max_share * float(n_usable))
    return 0;
  for (size_t k : dark) samples[k].flags |= kCastShadow;
  return dark.size();
}

void refit_photo_shadows(SampleChunk &chunk, const ReflectanceFitOptions &options, const PhotoShadowSettings &settings,
                         VertexFit *fits, size_t &flagged_samples, size_t &refitted_vertices) {
  if (!settings.enabled) return;
  size_t flagged = 0, refitted = 0;
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : flagged, refitted)
  for (long long ii = 0; ii < (long long)chunk.vertex_count; ++ii) {
    const size_t i = size_t(ii);
    Sample *samples = chunk.samples.data() + chunk.offsets[i];
    const size_t count = chunk.offsets[i + 1] - chunk.offsets[i];
    VertexFit &fit = fits[i];
    const size_t n = flag_photo_shadows(fit, samples, count, settings);
    if (n == 0) continue;
    flagged += n;
    ++refitted;
    const bool weak = fit.status == kFitFromWeakSamples;
    if (!weak) fit_vertex_cpu(samples, count, options, fit);
    if (weak || fit.status == kFitNone) fit_vertex_weak(samples, count, options, fit);
  }
  flagged_samples += flagged;
  refitted_vertices += refitted;
}

} // namespace vbrdf
