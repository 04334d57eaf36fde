#include "gl/gl_depth.h"

#include <algorithm>
#include <climits>
#include <cmath>

#include "base/errors.h"
#include "gl/gl_api.h"

namespace vbrdf {

const char *const kLinearDepthVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_view;
uniform mat4 u_projection;
out float v_depth;
void main() {
  vec4 view_pos = u_view * vec4(a_position, 1.0);
  v_depth = -view_pos.z;
  gl_Position = u_projection * view_pos;
}
)";

const char *const kLinearDepthFragmentShader = R"(#version 330 core
in float v_depth;
layout(location = 0) out float o_depth;
void main() { o_depth = v_depth; }
)";

GlMeshFrame gl_mesh_frame(const MeshView &mesh, float depth_tolerance_fraction, const std::string &who) {
  if (mesh.index_count > size_t(INT_MAX))
    throw ProcessingError(who + ": the mesh has " + std::to_string(mesh.index_count / 3) +
                          " triangles, more than one OpenGL draw call can take.");
  for (size_t i = 0; i < mesh.index_count; ++i)
    if (mesh.indices[i] >= mesh.vertex_count)
      throw InputError(who + ": face " + std::to_string(i / 3) + " references vertex " +
                       std::to_string(mesh.indices[i]) + " which does not exist.");
  GlMeshFrame f;
  const Bounds b = compute_bounds(mesh);
  f.tolerance = depth_tolerance_fraction * b.diagonal();
  if (mesh.vertex_count == 0) return f;
  const std::array<float, 3> centre = b.centre();
  for (int k = 0; k < 3; ++k) f.origin[k] = centre[size_t(k)];
  for (int c = 0; c < 8; ++c)
    for (int k = 0; k < 3; ++k) f.corners[c][k] = ((c >> k) & 1 ? b.max[k] : b.min[k]) - f.origin[k];
  float r2 = 0;
  for (size_t v = 0; v < mesh.vertex_count; ++v) {
    float d2 = 0;
    for (int k = 0; k < 3; ++k) {
      const float d = mesh.positions[3 * v + k] - f.origin[k];
      d2 += d * d;
    }
    r2 = std::max(r2, d2);
  }
  f.radius = std::sqrt(r2);
  return f;
}

void check_gl_target_size(const GlApi &gl, int width, int height, const std::string &who, const std::string &what) {
  GLint max_texture = 0, max_renderbuffer = 0, max_viewport[2] = {0, 0};
  gl.GetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture);
  gl.GetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_renderbuffer);
  gl.GetIntegerv(GL_MAX_VIEWPORT_DIMS, max_viewport);
  const int limit_x = std::min(std::min(max_texture, max_renderbuffer), max_viewport[0]);
  const int limit_y = std::min(std::min(max_texture, max_renderbuffer), max_viewport[1]);
  if (width > limit_x || height > limit_y)
    throw ProcessingError(who + ": " + what + " needs a " + std::to_string(width) + "x" + std::to_string(height) +
                          " render target, but this OpenGL (" + gl.version_string() + ") allows at most " +
                          std::to_string(limit_x) + "x" + std::to_string(limit_y) +
                          ". Use smaller photos or shadow map, or the CPU back end.");
}

} // namespace vbrdf
