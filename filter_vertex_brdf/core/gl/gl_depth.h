#pragma once
// What every depth pass shares (the visibility passes in visibility_gl.cpp, the relighting shadow
// map in relight_render.cpp): the linear-depth shaders and the column-major matrix GL takes.
// The depth written is the linear distance along the view axis (positive in front), exact per
// fragment since varyings are interpolated perspective-correctly; the CPU-side tests compare
// vertex depths (light_view.h, view_depth) with it.
#include <string>

#include "base/mesh_view.h"

namespace vbrdf {

struct GlApi;

extern const char *const kLinearDepthVertexShader;    // a_position (location 0), u_view, u_projection
extern const char *const kLinearDepthFragmentShader;  // one float output: the linear depth

// Column-major 4x4 matrix, as GL takes it.
struct Mat4 {
  float m[16] = {0};
  float &at(int row, int col) { return m[col * 4 + row]; }
  float at(int row, int col) const { return m[col * 4 + row]; }
};

// The frame in which a GL pass uploads a mesh: positions relative to the bounding-box centre, so
// that far-from-origin (georeferenced) coordinates keep their precision in the float transforms.
struct GlMeshFrame {
  float origin[3] = {0, 0, 0};  // bounding-box centre
  float corners[8][3] = {};     // bounding-box corners, relative to origin
  float radius = 0;             // bounding sphere radius around origin (over the vertices)
  float tolerance = 0;          // depth tolerance in world units (fraction x bbox diagonal)
};

// Checks that the mesh can be drawn (indices in range: an out-of-range index can crash the driver,
// InputError naming the face; one draw call: ProcessingError) and returns its frame. `who`
// ("OpenGL visibility", "Relighting") starts the messages.
GlMeshFrame gl_mesh_frame(const MeshView &mesh, float depth_tolerance_fraction, const std::string &who);

// Throws ProcessingError ("<who>: <what> needs a WxH render target, but this OpenGL allows at most
// ...") when the context's texture, renderbuffer or viewport limits are smaller.
void check_gl_target_size(const GlApi &gl, int width, int height, const std::string &who, const std::string &what);

} // namespace vbrdf
