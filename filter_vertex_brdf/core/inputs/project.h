#pragma once
// A registered MeshLab project: one mesh plus photos (rasters) with their shots. Light directions
// are not part of it: they come from an .lp file (light_file.h).
#include <string>
#include <vector>

#include "inputs/camera.h"

namespace vbrdf {

struct Project {
  std::string project_path;   // the .mlp (may be empty when built in memory / from MeshLab)
  std::string mesh_path;      // absolute path of the (first) mesh
  std::vector<Raster> rasters;
};

// Parses a MeshLab .mlp (MeshLab 2020.09 layout: <MeshGroup><MLMesh filename=.../>,
// <RasterGroup><MLRaster label=...><VCGCamera .../><Plane fileName=.../></MLRaster>).
// Paths are resolved relative to the .mlp's folder. Mirrors MeshLab's reading: the first
// <Plane> is the photo, <VCGCamera> gives the shot. Throws InputError for an unreadable file,
// a project without mesh, or a raster without a valid camera (named by label and index).
Project read_project(const std::string &mlp_path);

} // namespace vbrdf
