#include "samples/sample_colors.h"

namespace vbrdf {

void apply_color_calibration(const ColorCalibration &cal, Sample *samples, size_t count) {
  for (size_t i = 0; i < count; ++i) apply_color_calibration(cal, samples[i].raster, samples[i].rgb);
}

void correct_samples(const ColorPlan &plan, SampleChunk &chunk) {
#pragma omp parallel for schedule(static)
  for (long long i = 0; i < (long long)chunk.samples.size(); ++i) {
    Sample &s = chunk.samples[size_t(i)];
    const ColorCalibration *cal = plan.of_raster(s.raster);
    if (!cal) continue;
    apply_color_calibration(*cal, plan.photo_of[s.raster], s.rgb);
    for (float &c : s.rgb) c = c > 0 ? c : 0.0f;  // also NaN -> 0
  }
}

} // namespace vbrdf
