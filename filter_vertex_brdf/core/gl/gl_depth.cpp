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

const char *const kDepthOnlyFragmentShader = R"(#version 330 core
void main() {}
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

namespace {
// (Re)allocates texture `name` as width x height float data of `format`, read texel by texel
// (nearest, one level). Its contents are undefined until drawn.
void allocate_float_texture(const GlApi &gl, GLuint name, GLint format, GLenum channels, int width, int height) {
  gl.BindTexture(GL_TEXTURE_2D, name);
  gl.TexImage2D(GL_TEXTURE_2D, 0, format, width, height, 0, channels, GL_FLOAT, nullptr);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
}

// The bound framebuffer of `t` is attached: throws when the allocation or the framebuffer failed,
// else records its size.
void finish_render_target(const GlApi &gl, GlRenderTarget &t, int width, int height, const std::string &what) {
  check_gl_error(gl, "the allocation of the " + std::to_string(width) + "x" + std::to_string(height) +
                         " render target for " + what);
  check_framebuffer(gl, GL_FRAMEBUFFER, what);
  t.width = t.allocated_width = width;
  t.height = t.allocated_height = height;
}

void ensure_window_depth_target(const GlApi &gl, GlRenderTarget &t, int width, int height, const std::string &what) {
  if (!t.fbo) {
    t.fbo = GlObject::generate(gl, GlKind::Framebuffer);
    t.color = GlObject::generate(gl, GlKind::Texture);
  }
  gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);  // else the null data pointer is an offset into it
  allocate_float_texture(gl, t.color, GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, width, height);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_NONE);  // texelFetch reads the depth itself
  gl.BindFramebuffer(GL_FRAMEBUFFER, t.fbo);
  gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, t.color, 0);
  const GLenum none = GL_NONE;
  gl.DrawBuffers(1, &none);
  gl.ReadBuffer(GL_NONE);
  finish_render_target(gl, t, width, height, what);
}
} // namespace

float linear_depth_from_window(const float projection[16], float window) {
  float u[4];
  window_depth_unproject(projection, u);
  const float ndc = 2.0f * window - 1.0f;
  return -(u[1] - ndc * u[3]) / (ndc * u[2] - u[0]);
}

void window_depth_unproject(const float projection[16], float out[4]) {
  out[0] = projection[10];  // P[2][2]: column 2, row 2
  out[1] = projection[14];  // P[3][2]: column 3, row 2
  out[2] = projection[11];  // P[2][3]: column 2, row 3
  out[3] = projection[15];  // P[3][3]
}

void ensure_render_target(const GlApi &gl, GlRenderTarget &t, int width, int height, RenderTargetKind kind,
                          const std::string &who, const std::string &what) {
  if (t.fbo && t.allocated_width == width && t.allocated_height == height) {
    t.width = width, t.height = height;
    return;
  }
  check_gl_target_size(gl, width, height, who, what);
  if (kind == RenderTargetKind::WindowDepth) {
    ensure_window_depth_target(gl, t, width, height, what);
    return;
  }
  const bool shading = kind == RenderTargetKind::ShadingAndDepth;
  if (!t.fbo) {
    t.fbo = GlObject::generate(gl, GlKind::Framebuffer);
    t.color = GlObject::generate(gl, GlKind::Texture);
    t.depth = GlObject::generate(gl, GlKind::Renderbuffer);
  }
  if (shading && !t.extra) t.extra = GlObject::generate(gl, GlKind::Texture);
  gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);  // else the null data pointer is an offset into it
  allocate_float_texture(gl, t.color, shading ? GL_RGBA32F : GL_R32F, shading ? GL_RGBA : GL_RED, width, height);
  if (shading) allocate_float_texture(gl, t.extra, GL_R32F, GL_RED, width, height);
  gl.BindRenderbuffer(GL_RENDERBUFFER, t.depth);
  gl.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, width, height);
  gl.BindFramebuffer(GL_FRAMEBUFFER, t.fbo);
  gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, t.color, 0);
  if (shading) gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, t.extra, 0);
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, t.depth);
  const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  gl.DrawBuffers(shading ? 2 : 1, buffers);
  gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
  finish_render_target(gl, t, width, height, what);
}

void ensure_render_target_region(const GlApi &gl, GlRenderTarget &t, int width, int height, RenderTargetKind kind,
                                 const std::string &who, const std::string &what) {
  if (t.fbo && t.allocated_width >= width && t.allocated_height >= height) {  // within a size GL allocated
    t.width = width, t.height = height;
    return;
  }
  ensure_render_target(gl, t, width, height, kind, who, what);
}

void release_render_target(const GlApi &, GlRenderTarget &t) {
  t.fbo.reset(), t.color.reset(), t.extra.reset(), t.depth.reset();
  t = GlRenderTarget();
}

} // namespace vbrdf
