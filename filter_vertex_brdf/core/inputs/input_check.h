#pragma once
// The checks every filter that samples the photos (fit, coverage) makes before any work, in one
// place so that both refuse the same input with the same message.
#include <cstdint>
#include <string>
#include <vector>

#include "base/mesh_view.h"
#include "inputs/camera.h"

namespace vbrdf {

// A non-empty mesh with normals (validate_mesh), a selection of one entry per vertex (or none), at
// least one raster, and every raster with a valid, registered (not identity) shot and an existing
// photo. Throws InputError naming the item and the fix.
void validate_mesh_and_rasters(const MeshView &mesh, const std::string &mesh_name, const std::vector<Raster> &rasters,
                               const std::vector<uint8_t> &vertex_mask = {});

} // namespace vbrdf
