#pragma once
// Mesh loading for the command-line tool and tests (the plugin gets the mesh from MeshLab).
#include <string>

#include "base/mesh_view.h"

namespace vbrdf {

// Loads a PLY with vcglib's importer: positions, faces, per-vertex normals (computed,
// area-weighted, when the file has none and `compute_missing_normals`) and colours when present.
// Throws InputError naming the file when it cannot be read.
MeshData load_mesh_ply(const std::string &path, bool compute_missing_normals = false);

} // namespace vbrdf
