#include "inputs/photo_content.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "base/errors.h"
#include "base/file_util.h"
#include "base/vec3.h"

namespace vbrdf {

namespace {

template <typename T>
PhotoContent analyse(const Photo &photo) {
  PhotoContent c;
  int dark_code = 0;  // the largest code below kDarkLevel
  while (dark_code + 1 < int(photo.lut.size()) && photo.lut[size_t(dark_code + 1)] < kDarkLevel) ++dark_code;
  uint64_t hash = 1469598103934665603ull;  // FNV-1a over the codes
  size_t dark = 0, saturated = 0, counted = 0;
  // A grid of about a million pixels: the fractions are estimates against 99.5 % bounds, and any
  // two photos under different lights differ nearly everywhere, so a 12-50 MP photo need not be
  // read whole (every pixel up to 2 MP).
  const int stride = std::max(1, int(std::sqrt(double(photo.width()) * double(photo.height()) / 1.0e6)));
  for (int y = 0; y < photo.height(); y += stride) {
    const T *row = photo.pixels.ptr<T>(y);
    const int n = photo.pixels.channels();
    for (int x = 0; x < photo.width(); x += stride) {
      ++counted;
      const T *px = row + n * x;
      bool all_dark = true, any_clipped = false;
      for (int k = 0; k < 3; ++k) {
        const T code = px[photo.rgb[size_t(k)]];  // R, G, B whatever the layout: one fingerprint per content
        all_dark = all_dark && int(code) <= dark_code;
        any_clipped = any_clipped || int(code) >= photo.saturation_code;
        hash = (hash ^ uint64_t(code)) * 1099511628211ull;
      }
      dark += all_dark, saturated += any_clipped;
    }
  }
  const double pixels = double(std::max<size_t>(1, counted));
  c.dark_fraction = double(dark) / pixels;
  c.saturated_fraction = double(saturated) / pixels;
  c.fingerprint = hash ^ (uint64_t(photo.width()) << 32) ^ uint64_t(photo.height());
  return c;
}

std::string name_of(const Raster &r) { return "raster '" + r.label + "' (photo '" + r.image_path + "')"; }

} // namespace

PhotoContent analyse_photo(const Photo &photo) {
  return photo.pixels.depth() == CV_16U ? analyse<uint16_t>(photo) : analyse<uint8_t>(photo);
}

std::vector<std::string> check_photo_contents(const std::vector<Raster> &rasters,
                                              const std::vector<PhotoContent> &contents) {
  const size_t n = std::min(rasters.size(), contents.size());
  std::vector<std::string> warnings;
  if (n == 0) return warnings;
  std::vector<size_t> dark, saturated;
  std::map<uint64_t, std::vector<size_t>> groups;
  for (size_t i = 0; i < n; ++i) {
    if (contents[i].dark_fraction >= kUselessFraction) dark.push_back(i);
    else if (contents[i].saturated_fraction >= kUselessFraction) saturated.push_back(i);
    groups[contents[i].fingerprint].push_back(i);
  }
  const std::string share = percent(size_t(kUselessFraction * 1000), 1000);
  if (dark.size() == n)
    throw InputError("Every photo is black (" + std::to_string(n) + " of " + std::to_string(n) + " have at least " +
                     share + " of their pixels below " + fixed(100 * kDarkLevel, 1) + " % of full scale), e.g. " +
                     name_of(rasters[0]) + ": the lens was capped or the exposure far too short. Re-shoot, or check "
                     "that the project names the right photos. Nothing was written.");
  if (saturated.size() == n)
    throw InputError("Every photo is saturated (" + std::to_string(n) + " of " + std::to_string(n) +
                     " have at least " + share + " of their pixels clipped at 'Saturation level'), e.g. " +
                     name_of(rasters[0]) + ": the exposure is far too long. Re-shoot with a shorter exposure, or "
                     "check 'Photo encoding' and 'Saturation level'. Nothing was written.");
  if (n >= 2 && groups.size() == 1)
    throw InputError("All " + std::to_string(n) + " photos are identical (e.g. " + name_of(rasters[0]) + " and " +
                     name_of(rasters[1]) + "): one file was copied, or the light never moved. Each photo must be "
                     "taken under its own light. Nothing was written.");
  for (size_t i : dark)
    warnings.push_back("WARNING: " + name_of(rasters[i]) + " is black (" +
                       percent(size_t(contents[i].dark_fraction * 1000), 1000) +
                       " of its pixels): it adds no information; re-shoot it or remove the raster.");
  for (size_t i : saturated)
    warnings.push_back("WARNING: " + name_of(rasters[i]) + " is saturated (" +
                       percent(size_t(contents[i].saturated_fraction * 1000), 1000) +
                       " of its pixels clipped): its samples are not used; re-shoot it with a shorter exposure.");
  for (const auto &g : groups) {
    if (g.second.size() < 2) continue;
    std::string names;
    for (size_t i : g.second) names += (names.empty() ? "" : ", ") + ("'" + rasters[i].label + "'");
    warnings.push_back("WARNING: the photos of rasters " + names + " are identical: one file was probably copied "
                       "over another (each photo needs its own light); check them.");
  }
  return warnings;
}

} // namespace vbrdf
