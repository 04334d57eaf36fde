#include "inputs/input_check.h"

#include "base/errors.h"
#include "base/file_util.h"

namespace vbrdf {

void validate_mesh_and_rasters(const MeshView &mesh, const std::string &mesh_name, const std::vector<Raster> &rasters,
                               const std::vector<uint8_t> &vertex_mask) {
  validate_mesh(mesh, mesh_name);
  if (!vertex_mask.empty() && vertex_mask.size() != mesh.vertex_count)
    throw InputError("internal: the vertex selection has " + std::to_string(vertex_mask.size()) +
                     " entries for " + std::to_string(mesh.vertex_count) + " vertices");
  if (rasters.empty())
    throw InputError("The project has no rasters: load the registered photos (File > Import Raster) or open the .mlp.");
  for (size_t r = 0; r < rasters.size(); ++r) {
    const Raster &raster = rasters[r];
    if (!shot_is_valid(raster.shot))
      throw InputError("Raster " + std::to_string(r) + " ('" + raster.label +
                       "') has no valid camera: register it to the mesh first.");
    if (shot_is_identity(raster.shot))
      throw InputError("Raster " + std::to_string(r) + " ('" + raster.label +
                       "') has an identity camera (at the world origin, looking along -z): it was not registered. "
                       "Register it to the mesh first, or remove the raster.");
    if (!file_exists(raster.image_path))
      throw InputError("Raster " + std::to_string(r) + " ('" + raster.label + "'): photo '" + raster.image_path +
                       "' is missing. Restore the file or fix the path in the project.");
  }
}

} // namespace vbrdf
