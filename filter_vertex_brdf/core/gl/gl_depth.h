#pragma once
// What every depth pass shares (the visibility passes in visibility_gl.cpp, the relighting shadow
// map in relight_render.cpp): the linear-depth shaders and the column-major matrix GL takes.
// The depth written is the linear distance along the view axis (positive in front), exact per
// fragment since varyings are interpolated perspective-correctly; the CPU-side tests compare
// vertex depths (light_view.h, view_depth) with it.
#include <string>

#include "base/mesh_view.h"
#include "gl/gl_object.h"

namespace vbrdf {

struct GlApi;

extern const char *const kLinearDepthVertexShader;    // a_position (location 0), u_view, u_projection
extern const char *const kLinearDepthFragmentShader;  // one float output: the linear depth
extern const char *const kDepthOnlyFragmentShader;    // no output: the window depth alone

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

// An FBO with float colour outputs and a 32F depth renderbuffer. Attachment 0 is R32F for a depth
// pass (the linear depth) or RGBA32F for a shading pass, whose attachment 1 (`extra`) is then an
// R32F linear depth. WindowDepth has no colour output: `color` is then a 32F depth *texture* (the
// rasteriser's window depth, which the caller converts: linear_depth_from_window) and `depth` is 0:
// no fragment output to write (the shadow passes of 100 k x 32 on llvmpipe: visibility -11 %).
// The objects free themselves (GlObject); a name 0 = not allocated.
struct GlRenderTarget {
  GlObject fbo, color, extra, depth;
  int width = 0, height = 0;                      // the size in use (passes draw and read this much)
  int allocated_width = 0, allocated_height = 0;  // the size of the GL objects (>= the size in use)
};
enum class RenderTargetKind { LinearDepth, ShadingAndDepth, WindowDepth };

// The depth along the view axis (-z in view space) of a fragment whose window depth (glDepthRange
// 0..1) is `window`, under the projection matrix `projection` (column-major, as GL takes it): from
// z_ndc = (P[2][2] z + P[3][2]) / (P[2][3] z + P[3][3]), exact for orthographic and perspective
// projections. The GLSL of visibility_test.comp does the same with window_depth_unproject().
float linear_depth_from_window(const float projection[16], float window);
// The four entries of `projection` that function uses: P[2][2], P[3][2], P[2][3], P[3][3].
void window_depth_unproject(const float projection[16], float out[4]);

// (Re)allocates `t` at width x height unless it already has that size, after
// check_gl_target_size; leaves it bound as the framebuffer with its colour outputs as draw buffers.
// Throws ProcessingError naming `what` when GL cannot allocate or complete it.
void ensure_render_target(const GlApi &gl, GlRenderTarget &t, int width, int height, RenderTargetKind kind,
                          const std::string &who, const std::string &what);
// The same, but a target already allocated at least that large is kept and only its lower-left
// width x height region used (t.width, t.height): for passes whose size changes from one to the
// next (the shadow maps, sized per light), which would otherwise allocate, and the driver clear,
// a new texture each time (llvmpipe: 64 MB per 4096² pass). Only for users that address texels
// (texelFetch), not normalised coordinates.
void ensure_render_target_region(const GlApi &gl, GlRenderTarget &t, int width, int height, RenderTargetKind kind,
                                 const std::string &who, const std::string &what);
// Deletes the GL objects of `t` now (the context must be current) and resets it.
void release_render_target(const GlApi &gl, GlRenderTarget &t);

// Throws ProcessingError ("<who>: <what> needs a WxH render target, but this OpenGL allows at most
// ...") when the context's texture, renderbuffer or viewport limits are smaller.
void check_gl_target_size(const GlApi &gl, int width, int height, const std::string &who, const std::string &what);

} // namespace vbrdf
