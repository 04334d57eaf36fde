#include "samples/light_check.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "base/errors.h"
#include "base/file_util.h"
#include "base/luminance.h"

namespace vbrdf {

LightAgreement::LightAgreement(size_t raster_count)
    : n_(raster_count, 0), sx_(raster_count, 0), sy_(raster_count, 0), sxx_(raster_count, 0),
      syy_(raster_count, 0), sxy_(raster_count, 0) {}

void LightAgreement::add(const SampleChunk &chunk, const MeshView &mesh, const std::vector<LightSource> &lights) {
  for (uint32_t i = 0; i < chunk.vertex_count; ++i) {
    const float *x = mesh.positions + 3 * (size_t(chunk.first_vertex) + i);
    for (uint32_t k = chunk.offsets[i]; k < chunk.offsets[i + 1]; ++k) {
      const Sample &s = chunk.samples[k];
      if ((s.flags & (kSaturated | kMixedPixel)) || s.raster >= n_.size()) continue;
      // N.L signed (not clamped): the vertices facing away from the light must be the dark ones.
      const double predicted = double(s.d) * light_irradiance_at(lights[s.raster], x);
      const double lum = luminance_double(s.rgb);
      if (!std::isfinite(predicted) || !std::isfinite(lum)) continue;
      const size_t r = s.raster;
      n_[r] += 1, sx_[r] += predicted, sy_[r] += lum;
      sxx_[r] += predicted * predicted, syy_[r] += lum * lum, sxy_[r] += predicted * lum;
    }
  }
}

double LightAgreement::correlation(size_t r) const {
  if (r >= n_.size() || n_[r] < 2) return 0;
  const double n = n_[r];
  const double vx = sxx_[r] - sx_[r] * sx_[r] / n, vy = syy_[r] - sy_[r] * sy_[r] / n;
  const double cov = sxy_[r] - sx_[r] * sy_[r] / n;
  if (!(vx > 1e-12 * n) || !(vy > 1e-12 * n)) return 0;
  return cov / std::sqrt(vx * vy);
}

std::string weakest_light_agreement(const LightAgreement &agreement, const std::vector<Raster> &rasters) {
  size_t worst = rasters.size();
  for (size_t r = 0; r < rasters.size(); ++r)
    if (agreement.samples(r) >= kLightCheckMinSamples &&
        (worst == rasters.size() || agreement.correlation(r) < agreement.correlation(worst)))
      worst = r;
  if (worst == rasters.size()) return "";
  std::ostringstream s;
  s.precision(2);
  s << "lowest agreement: photo '" << file_name_of(rasters[worst].image_path) << "', correlation "
    << agreement.correlation(worst) << " over " << agreement.samples(worst) << " samples";
  return s.str();
}

void check_light_agreement(const LightAgreement &agreement, const std::vector<Raster> &rasters,
                           const std::string &light_file) {
  for (size_t r = 0; r < rasters.size(); ++r) {
    const double c = agreement.correlation(r);
    if (agreement.samples(r) < kLightCheckMinSamples || c >= kLightCheckMaxCorrelation) continue;
    std::ostringstream why;
    why.precision(2);
    why << "Light file '" << light_file << "' disagrees with photo '" << file_name_of(rasters[r].image_path)
        << "' (raster '" << rasters[r].label << "'): the vertices its light should light most are the darkest "
        << "(correlation " << c << " between the predicted irradiance and the brightness over "
        << agreement.samples(r) << " samples). Check that entry: its direction (camera frame: x right, y up, z "
        << "towards the camera) or position (frame and units), or that it belongs to this photo. Nothing was written.";
    throw InputError(why.str());
  }
}

} // namespace vbrdf
