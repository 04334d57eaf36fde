#pragma once
// The light sphere of "Vertex BRDF: relight": the project's photo light directions as points on a
// sphere around the mesh, and MeshLab's current light (the one the live view uses) as a line from
// the centre with a larger point, so that a user sees where the model was measured and where the
// light is now. Drawn with MeshLab's fixed-function state (compatibility context); all state it
// changes is pushed and popped.
#include <array>
#include <vector>

namespace vbrdf_render {

void draw_light_sphere(const std::array<float, 3> &centre, float radius,
                       const std::vector<std::array<float, 3>> &photo_lights, const std::array<float, 3> &current_light);

} // namespace vbrdf_render
