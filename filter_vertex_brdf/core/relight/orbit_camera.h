#pragma once
// Novel views for relighting: a camera orbited around a pivot, and labels safe in file names.
#include <string>

#include "inputs/camera.h"

namespace vbrdf {

// A new viewpoint from an existing camera: orbits it around `pivot` by `azimuth_deg` about the
// camera's up axis (positive: the camera moves to its right) and `elevation_deg` about its right
// axis (positive: upwards), then scales its distance to the pivot by `distance_scale` (> 0).
// Intrinsics are kept. Throws InputError for a non-positive or non-finite scale.
Shot orbit_shot(const Shot &base, const float pivot[3], float azimuth_deg, float elevation_deg, float distance_scale);

// Characters of a raster label that are safe in a file name ("a b/c.png" -> "a_b_c.png").
std::string file_safe_label(const std::string &label);

} // namespace vbrdf
