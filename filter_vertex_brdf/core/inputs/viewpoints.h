#pragma once
// Viewpoints: the photos of one registration (one camera position; only the light moves). One
// definition for every filter and tool (fit, coverage, relight, sphere, import), built on
// same_shot (camera.h).
#include <vector>

#include "inputs/camera.h"

namespace vbrdf {

struct Viewpoint {
  Shot shot;                    // the shared registration (that of its first raster)
  std::vector<size_t> rasters;  // indices into the raster list, ascending
};

// Groups rasters whose shots are identical (same_shot: intrinsics and extrinsics equal to 1e-6
// relative), in order of first appearance. Every raster belongs to exactly one viewpoint.
std::vector<Viewpoint> group_viewpoints(const std::vector<Raster> &rasters);

// The same grouping as raster index lists only.
std::vector<std::vector<size_t>> rasters_by_viewpoint(const std::vector<Raster> &rasters);

// Index of the viewpoint holding raster `raster` (viewpoints from group_viewpoints). Throws
// InputError when no viewpoint holds it.
size_t viewpoint_of_raster(const std::vector<Viewpoint> &viewpoints, size_t raster);

} // namespace vbrdf
