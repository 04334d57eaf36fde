#pragma once
// Does each photo's light agree with the photo? A wrong entry in a light file (a direction in the
// wrong frame, a position with the wrong sign or units, another photo's light) makes the fit
// explain bright pixels with a light that does not reach them. The check: per photo, the
// correlation between N.L times the light's irradiance at each seen vertex (signed: negative on
// the side facing away from the light) and the pixel's luminance. A right light correlates
// positively (albedo varies, but not with N.L); a light on the wrong side correlates negatively,
// since the vertices it says face away from it are the bright ones.
#include <string>
#include <vector>

#include "inputs/camera.h"
#include "inputs/light_source.h"
#include "samples/samples.h"

namespace vbrdf {

// Below this correlation over at least kLightCheckMinSamples samples, a photo's light is refused.
constexpr double kLightCheckMaxCorrelation = -0.1;
constexpr size_t kLightCheckMinSamples = 100;

class LightAgreement {
public:
  explicit LightAgreement(size_t raster_count);
  // Adds a chunk's samples (before apply_light_falloff: colours as photographed, after any colour
  // correction); saturated and mixed-pixel samples are left out.
  void add(const SampleChunk &chunk, const MeshView &mesh, const std::vector<LightSource> &lights);
  // Pearson correlation of raster r (0 when it has fewer than 2 samples or no spread).
  double correlation(size_t r) const;
  size_t samples(size_t r) const { return r < n_.size() ? size_t(n_[r]) : 0; }

private:
  std::vector<double> n_, sx_, sy_, sxx_, syy_, sxy_;
};

// "lowest agreement: photo 'x.png', correlation 0.61 over 1234 samples" (for reports); "" when no
// photo has enough samples.
std::string weakest_light_agreement(const LightAgreement &agreement, const std::vector<Raster> &rasters);

// Throws InputError naming the light file, the first photo whose correlation is below
// kLightCheckMaxCorrelation over at least kLightCheckMinSamples samples, and what to check.
void check_light_agreement(const LightAgreement &agreement, const std::vector<Raster> &rasters,
                           const std::string &light_file);

} // namespace vbrdf
