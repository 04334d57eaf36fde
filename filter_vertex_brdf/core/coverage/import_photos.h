#pragma once
// Importing new photos of a registered viewpoint (the between-shots step): which photos in a
// folder are new, their lights from the reflective sphere, and the merged light file.
#include <functional>
#include <string>
#include <vector>

#include "base/callbacks.h"
#include "calibration/sphere_lights.h"
#include "inputs/camera.h"
#include "inputs/light_file.h"

namespace vbrdf {

// Image files (png, jpg, jpeg, tif, tiff, bmp; any case) in `folder`, sorted by name, that are not
// already the photo of one of `rasters` (compared by absolute, symlink-resolved path). Throws
// InputError naming the folder when it cannot be read.
std::vector<std::string> new_photos_in_folder(const std::string &folder, const std::vector<Raster> &rasters);

// Light directions estimated from the reflective sphere (sphere_lights.h) for the photos
// photos[wanted[i]] of one viewpoint with shot `shot`. The sphere is located on all `photos`
// together (median/max images and the highlights' track), or given by `manual` when its radius
// is > 0 (image pixels, top-left origin). Returns one .lp entry per wanted photo, named by its path
// relative to `lp_folder`, direction in the camera frame. What was found goes to `log`. Throws
// InputError naming the photo when it has no usable highlight, or when no sphere is found.
std::vector<LightEntry> sphere_light_entries(const std::vector<std::string> &photos, const std::vector<size_t> &wanted,
                                             const Shot &shot, const SphereCircle &manual,
                                             const std::string &lp_folder,
                                             const LogFn &log);

// Entries of `existing` (kept in order, except those naming the same image file as an entry of
// `added`) followed by `added`.
std::vector<LightEntry> merge_light_entries(const std::vector<LightEntry> &existing, const std::vector<LightEntry> &added);

} // namespace vbrdf
