// Photo light directions of the open project (photo_lights.h).
#include "photo_lights.h"

#include "core/base/errors.h"
#include "core/inputs/light_file.h"
#include "core/inputs/light_source.h"

namespace vbrdf_plugin {

PhotoLights photo_lights(const MeshDocument &document, const MeshModel &mesh, const MeshArrays &arrays) {
  const ActiveRasters active = active_rasters(document);
  if (active.rasters.empty())
    throw vbrdf::InputError("No photo lights to show: the project has no visible raster.");
  PhotoLights out;
  out.file = vbrdf::resolve_light_file("", active.rasters, project_path(document, mesh));
  const vbrdf::LightPlacement placement = vbrdf::light_placement_of(arrays.data.view(), 0.0f, 0.0f);
  out.directions = vbrdf::light_directions(vbrdf::resolve_lights(active.rasters, out.file, placement));
  return out;
}

} // namespace vbrdf_plugin
