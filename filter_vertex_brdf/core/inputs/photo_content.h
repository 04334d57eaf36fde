#pragma once
// What the photos hold, checked before any work: photos that are black (lens cap, far too short
// an exposure), saturated (far too long) or identical to another photo (a file copied, or the light
// never moved) carry no reflectance information. All photos so: the fit is refused (InputError).
// Some: one warning per case, which the fit puts at the top of its report and its log.
#include <cstdint>
#include <string>
#include <vector>

#include "inputs/camera.h"
#include "inputs/photo.h"

namespace vbrdf {

struct PhotoContent {
  double dark_fraction = 0;       // pixels whose every channel is below kDarkLevel (linear)
  double saturated_fraction = 0;  // pixels with a channel at or above the photo's saturation code
  uint64_t fingerprint = 0;       // hash of the pixel codes (equal photos, equal fingerprints)
};

constexpr float kDarkLevel = 0.002f;         // linear; 8-bit sRGB codes 0..6
constexpr double kUselessFraction = 0.995;   // a photo this dark / saturated carries nothing

// Reads every pixel of photos up to 2 MP, an even grid of about a million pixels of larger ones.
PhotoContent analyse_photo(const Photo &photo);

// Checks the photos of `rasters` (contents[i] of rasters[i]). Throws InputError, naming a photo of
// each kind and the remedy, when every photo is dark, every photo saturated, or (two or more
// photos) every photo identical. Returns the warnings for the photos that are so when others are
// not (each naming the raster and the file).
std::vector<std::string> check_photo_contents(const std::vector<Raster> &rasters,
                                              const std::vector<PhotoContent> &contents);

} // namespace vbrdf
