#pragma once
// The photo light directions of the open project, for the live view's light sphere
// ("Vertex BRDF: relight", render_plugin/): the default light file of the visible rasters (the
// fit's rule and message, light_file.h resolve_light_file) resolved to world directions (light_source.h;
// point lights as seen from the mesh's bounding-box centre).
#include <array>
#include <string>
#include <vector>

#include "meshlab_bridge.h"

namespace vbrdf_plugin {

struct PhotoLights {
  std::vector<std::array<float, 3>> directions;  // world, unit, towards the light; one per raster
  std::string file;                              // the light file read
};

// Throws vbrdf::InputError with a message for the panel when the document has no visible raster,
// no light file qualifies, or the file cannot be read.
PhotoLights photo_lights(const MeshDocument &document, const MeshModel &mesh, const MeshArrays &arrays);

} // namespace vbrdf_plugin
