// Image-space relighting (contract in relight_render.h): a shadow-map pass from the light and a
// shading pass from the camera, both into float render targets that are read back; comparison and
// composition on the CPU with OpenCV.
#include "relight_render.h"

#include <algorithm>
#include <cfloat>
#include <climits>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <QDir>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "color_difference.h"
#include "errors.h"
#include "file_util.h"
#include "gl_api.h"
#include "light_view.h"
#include "output_ply.h"  // write_text_file_atomically
#include "visibility.h"  // resolved_shadow_map_size

namespace vbrdf {

namespace {

// Shared by both passes: positions are uploaded relative to the bounding-box centre (precision of
// far-from-origin coordinates), view depth is written for the shadow test and the comparison.
const char *const kShadeVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_rho_fitted;
layout(location = 3) in vec2 a_ks_alpha;
uniform mat4 u_view;
uniform mat4 u_projection;
out vec3 v_position;
out vec3 v_normal;
out vec4 v_rho_fitted;
out vec2 v_ks_alpha;
out float v_depth;
void main() {
  vec4 view_pos = u_view * vec4(a_position, 1.0);
  v_position = a_position;
  v_normal = a_normal;
  v_rho_fitted = a_rho_fitted;
  v_ks_alpha = a_ks_alpha;
  v_depth = -view_pos.z;
  gl_Position = u_projection * view_pos;
}
)";

// Output 0: linear RGB and the RelitPixel class in alpha; output 1: view depth.
// Shadow test as in the visibility pass: lit when the fragment is at most u_tolerance behind the
// farthest of the 2x2 shadow-map texels around it (forgives the map's quantisation).
const char *const kShadeFragmentShader = R"(#version 330 core
in vec3 v_position;
in vec3 v_normal;
in vec4 v_rho_fitted;
in vec2 v_ks_alpha;
in float v_depth;
uniform vec3 u_light_dir;
uniform vec3 u_eye;
uniform mat4 u_light_view;
uniform float u_light_scale;
uniform int u_light_perspective;
uniform vec3 u_light_pos;
uniform float u_light_reference;
uniform float u_light_intensity;
uniform int u_shadow_size;
uniform float u_tolerance;
uniform sampler2D u_shadow_map;
layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_depth;

float shadow_texel(int i, int j) {
  ivec2 p = clamp(ivec2(i, j), ivec2(0), ivec2(u_shadow_size - 1));
  return texelFetch(u_shadow_map, p, 0).r;
}

void main() {
  o_depth = v_depth;
  if (v_rho_fitted.a < 0.999) { o_color = vec4(0.0, 0.0, 0.0, 3.0); return; }
  float len = length(v_normal);
  vec3 n = len > 0.0 ? v_normal / len : v_normal;
  // Light direction and irradiance at the fragment (light_source.h): a point light's change
  // across the object, with the distance clamped as on the CPU.
  vec3 l = u_light_dir;
  float irradiance = u_light_intensity;
  if (u_light_perspective != 0) {
    vec3 to_light = u_light_pos - v_position;
    float dist = max(length(to_light), 1e-3 * u_light_reference);
    l = to_light / dist;
    irradiance = u_light_intensity * (u_light_reference / dist) * (u_light_reference / dist);
  }
  float d = dot(n, l);
  if (!(d > 0.0)) { o_color = vec4(0.0, 0.0, 0.0, 2.0); return; }
  vec4 lp = u_light_view * vec4(v_position, 1.0);
  float light_depth = -lp.z;
  float w = u_light_perspective != 0 ? max(light_depth, 1e-12) : 1.0;
  float wx = (u_light_scale * lp.x / w + 1.0) * 0.5 * float(u_shadow_size);
  float wy = (u_light_scale * lp.y / w + 1.0) * 0.5 * float(u_shadow_size);
  int i0 = int(floor(wx - 0.5)), j0 = int(floor(wy - 0.5));
  float far_depth = max(max(shadow_texel(i0, j0), shadow_texel(i0 + 1, j0)),
                        max(shadow_texel(i0, j0 + 1), shadow_texel(i0 + 1, j0 + 1)));
  if (light_depth > far_depth + u_tolerance) { o_color = vec4(0.0, 0.0, 0.0, 2.0); return; }
  vec3 e = normalize(u_eye - v_position);
  vec3 r = 2.0 * d * n - l;
  float s = dot(r, e);
  float spec = 0.0;
  if (v_ks_alpha.x > 0.0 && s > 0.0)
    spec = v_ks_alpha.x * exp(max(v_ks_alpha.y * log(min(s, 1.0)), -80.0));
  o_color = vec4((v_rho_fitted.rgb * d + vec3(spec)) * irradiance, 1.0);
}
)";

const char *const kShadowFragmentShader = R"(#version 330 core
in float v_depth;
layout(location = 0) out float o_depth;
void main() { o_depth = v_depth; }
)";

const char *const kShadowVertexShader = R"(#version 330 core
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

constexpr int kFloatsPerVertex = 12;  // position 3, normal 3, rho 3, fitted 1, k_s 1, alpha 1

// Column-major 4x4 matrix, as GL takes it.
struct Mat4 {
  float m[16] = {0};
  float &at(int row, int col) { return m[col * 4 + row]; }
  float at(int row, int col) const { return m[col * 4 + row]; }
};

struct Target {
  GLuint fbo = 0, color = 0, extra = 0, depth = 0;  // extra: the camera pass's depth output
  int width = 0, height = 0;
};

// The shininess given to k_s = 0 vertices (see the header): median of the fitted lobes.
float typical_shininess(const std::vector<VertexFit> &fits) {
  std::vector<float> a;
  for (const VertexFit &f : fits)
    if (f.ks > 0 && f.shininess > 0 && std::isfinite(f.shininess)) a.push_back(f.shininess);
  if (a.empty()) return 1.0f;
  std::nth_element(a.begin(), a.begin() + long(a.size() / 2), a.end());
  return a[a.size() / 2];
}

void normalise(const float in[3], float out[3], const char *what) {
  const double len = std::sqrt(double(in[0]) * in[0] + double(in[1]) * in[1] + double(in[2]) * in[2]);
  if (!(len > 1e-12) || !std::isfinite(len))
    throw InputError(std::string("Relighting: the ") + what + " is zero or not finite.");
  for (int k = 0; k < 3; ++k) out[k] = float(in[k] / len);
}

} // namespace

class RelightRenderer::Impl {
public:
  Impl(const MeshView &mesh, const std::vector<VertexFit> &fits, const GetProcAddressFn &get_proc,
       const RelightRenderSettings &settings);
  ~Impl() { release(); }
  RelitImage render(const Shot &shot, const LightSource &light);
  std::string renderer;

private:
  void upload(const MeshView &mesh, const std::vector<VertexFit> &fits);
  void check_size(int width, int height, const std::string &what) const;
  void ensure_target(Target &t, int width, int height, bool camera, const std::string &what);
  void release_target(Target &t);
  void release();
  void shadow_pass(const LightView &lv);
  void camera_pass(const Shot &shot, const LightSource &light, const LightView &lv, RelitImage &out);
  void draw();

  GlApi gl_;
  RelightRenderSettings settings_;
  size_t index_count_ = 0;
  float origin_[3] = {0, 0, 0};
  float corners_[8][3] = {};
  float radius_ = 0, tolerance_ = 0;
  GLuint shade_program_ = 0, shadow_program_ = 0, vao_ = 0, vbo_ = 0, ibo_ = 0;
  Target camera_target_, shadow_target_;
};

RelightRenderer::Impl::Impl(const MeshView &mesh, const std::vector<VertexFit> &fits, const GetProcAddressFn &get_proc,
                            const RelightRenderSettings &settings)
    : gl_(load_gl_api(get_proc)), settings_(settings) {
  if (fits.size() != mesh.vertex_count)
    throw InputError("Relighting: " + std::to_string(fits.size()) + " per-vertex fits for a mesh of " +
                     std::to_string(mesh.vertex_count) + " vertices: use the fit of this mesh.");
  if (mesh.index_count > size_t(INT_MAX))
    throw ProcessingError("Relighting: the mesh has too many triangles for one OpenGL draw call.");
  for (size_t i = 0; i < mesh.index_count; ++i)
    if (mesh.indices[i] >= mesh.vertex_count)  // an out-of-range index can crash the GL driver
      throw InputError("Relighting: face " + std::to_string(i / 3) + " references vertex " +
                       std::to_string(mesh.indices[i]) + " which does not exist.");
  VisibilitySettings visibility;
  visibility.depth_tolerance = settings.depth_tolerance;
  visibility.shadow_map_size = settings.shadow_map_size;
  settings_.shadow_map_size = resolved_shadow_map_size(mesh, visibility);
  renderer = gl_.version_string();
  const Bounds b = compute_bounds(mesh);
  tolerance_ = settings.depth_tolerance * b.diagonal();
  if (mesh.vertex_count > 0) {
    for (int k = 0; k < 3; ++k) origin_[k] = 0.5f * (b.min[k] + b.max[k]);
    for (int c = 0; c < 8; ++c)
      for (int k = 0; k < 3; ++k) corners_[c][k] = ((c >> k) & 1 ? b.max[k] : b.min[k]) - origin_[k];
  }
  GlStateGuard guard(gl_);
  clear_gl_errors(gl_);
  try {
    check_size(settings_.shadow_map_size, settings_.shadow_map_size, "the shadow map");
    shade_program_ = build_program(gl_, kShadeVertexShader, kShadeFragmentShader, "the relighting pass");
    shadow_program_ = build_program(gl_, kShadowVertexShader, kShadowFragmentShader, "the relighting shadow map");
    upload(mesh, fits);
    check_gl_error(gl_, "the upload of the mesh for relighting");
  } catch (...) {
    release();  // the destructor does not run when the constructor throws
    throw;
  }
}

void RelightRenderer::Impl::upload(const MeshView &mesh, const std::vector<VertexFit> &fits) {
  const float alpha_default = typical_shininess(fits);
  std::vector<float> data(mesh.vertex_count * kFloatsPerVertex);
  float r2 = 0;
  for (size_t v = 0; v < mesh.vertex_count; ++v) {
    float *o = &data[v * kFloatsPerVertex];
    const VertexFit &f = fits[v];
    for (int k = 0; k < 3; ++k) {
      o[k] = mesh.positions[3 * v + k] - origin_[k];
      o[3 + k] = mesh.normals[3 * v + k];
      o[6 + k] = f.kd * f.color[k];
    }
    r2 = std::max(r2, o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
    o[9] = f.status == kFitNone ? 0.0f : 1.0f;
    o[10] = f.ks;
    o[11] = f.ks > 0 && f.shininess > 0 ? f.shininess : alpha_default;
  }
  radius_ = std::sqrt(r2);
  index_count_ = mesh.index_count;

  gl_.GenVertexArrays(1, &vao_);
  gl_.BindVertexArray(vao_);
  gl_.GenBuffers(1, &vbo_);
  gl_.BindBuffer(GL_ARRAY_BUFFER, vbo_);
  gl_.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(), GL_STATIC_DRAW);
  const GLsizei stride = kFloatsPerVertex * sizeof(float);
  const int sizes[4] = {3, 3, 4, 2}, offsets[4] = {0, 3, 6, 10};
  for (GLuint a = 0; a < 4; ++a) {
    gl_.VertexAttribPointer(a, sizes[a], GL_FLOAT, GL_FALSE, stride,
                            reinterpret_cast<const void *>(size_t(offsets[a]) * sizeof(float)));
    gl_.EnableVertexAttribArray(a);
  }
  gl_.GenBuffers(1, &ibo_);
  gl_.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo_);  // recorded in our VAO only
  gl_.BufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(mesh.index_count * sizeof(uint32_t)), mesh.indices,
                 GL_STATIC_DRAW);
}

void RelightRenderer::Impl::check_size(int width, int height, const std::string &what) const {
  GLint max_texture = 0, max_renderbuffer = 0, max_viewport[2] = {0, 0};
  gl_.GetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture);
  gl_.GetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_renderbuffer);
  gl_.GetIntegerv(GL_MAX_VIEWPORT_DIMS, max_viewport);
  const int limit_x = std::min(std::min(max_texture, max_renderbuffer), max_viewport[0]);
  const int limit_y = std::min(std::min(max_texture, max_renderbuffer), max_viewport[1]);
  if (width > limit_x || height > limit_y)
    throw ProcessingError("Relighting: " + what + " needs a " + std::to_string(width) + "x" + std::to_string(height) +
                          " render target, but this OpenGL (" + gl_.version_string() + ") allows at most " +
                          std::to_string(limit_x) + "x" + std::to_string(limit_y) + ".");
}

void RelightRenderer::Impl::ensure_target(Target &t, int width, int height, bool camera, const std::string &what) {
  if (t.fbo && t.width == width && t.height == height) return;
  check_size(width, height, what);
  if (!t.fbo) {
    gl_.GenFramebuffers(1, &t.fbo);
    gl_.GenTextures(1, &t.color);
    if (camera) gl_.GenTextures(1, &t.extra);
    gl_.GenRenderbuffers(1, &t.depth);
  }
  gl_.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);  // else the null data pointer is an offset into it
  auto texture = [&](GLuint name, GLint format, GLenum channels) {
    gl_.BindTexture(GL_TEXTURE_2D, name);
    gl_.TexImage2D(GL_TEXTURE_2D, 0, format, width, height, 0, channels, GL_FLOAT, nullptr);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
  };
  texture(t.color, camera ? GL_RGBA32F : GL_R32F, camera ? GL_RGBA : GL_RED);
  if (camera) texture(t.extra, GL_R32F, GL_RED);
  gl_.BindRenderbuffer(GL_RENDERBUFFER, t.depth);
  gl_.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, width, height);
  gl_.BindFramebuffer(GL_FRAMEBUFFER, t.fbo);
  gl_.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, t.color, 0);
  if (camera) gl_.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, t.extra, 0);
  gl_.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, t.depth);
  const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  gl_.DrawBuffers(camera ? 2 : 1, buffers);
  check_gl_error(gl_, "the allocation of the " + std::to_string(width) + "x" + std::to_string(height) +
                          " render target for " + what);
  check_framebuffer(gl_, GL_FRAMEBUFFER, what);
  t.width = width;
  t.height = height;
}

void RelightRenderer::Impl::release_target(Target &t) {
  if (t.fbo) gl_.DeleteFramebuffers(1, &t.fbo);
  if (t.color) gl_.DeleteTextures(1, &t.color);
  if (t.extra) gl_.DeleteTextures(1, &t.extra);
  if (t.depth) gl_.DeleteRenderbuffers(1, &t.depth);
  t = Target();
}

void RelightRenderer::Impl::release() {
  release_target(camera_target_);
  release_target(shadow_target_);
  if (vao_) gl_.DeleteVertexArrays(1, &vao_);
  if (vbo_) gl_.DeleteBuffers(1, &vbo_);
  if (ibo_) gl_.DeleteBuffers(1, &ibo_);
  if (shade_program_) gl_.DeleteProgram(shade_program_);
  if (shadow_program_) gl_.DeleteProgram(shadow_program_);
  vao_ = vbo_ = ibo_ = shade_program_ = shadow_program_ = 0;
}

void RelightRenderer::Impl::draw() {
  gl_.BindVertexArray(vao_);
  if (index_count_ > 0) gl_.DrawElements(GL_TRIANGLES, GLsizei(index_count_), GL_UNSIGNED_INT, nullptr);
}

// The light's view (light_view.h, shared with the visibility pass).
void RelightRenderer::Impl::shadow_pass(const LightView &lv) {
  const int size = settings_.shadow_map_size;
  ensure_target(shadow_target_, size, size, false, "the relighting shadow map");
  Mat4 view, projection;
  std::copy(lv.view, lv.view + 16, view.m);
  std::copy(lv.projection, lv.projection + 16, projection.m);
  gl_.BindFramebuffer(GL_FRAMEBUFFER, shadow_target_.fbo);
  gl_.Viewport(0, 0, size, size);
  set_plain_raster_state(gl_);
  gl_.Enable(GL_DEPTH_TEST);
  const float far_away[4] = {FLT_MAX, FLT_MAX, FLT_MAX, FLT_MAX}, clear_depth = 1.0f;
  gl_.ClearBufferfv(GL_COLOR, 0, far_away);
  gl_.ClearBufferfv(GL_DEPTH, 0, &clear_depth);
  gl_.UseProgram(shadow_program_);
  gl_.UniformMatrix4fv(gl_.GetUniformLocation(shadow_program_, "u_view"), 1, GL_FALSE, view.m);
  gl_.UniformMatrix4fv(gl_.GetUniformLocation(shadow_program_, "u_projection"), 1, GL_FALSE, projection.m);
  draw();
  check_gl_error(gl_, "the relighting shadow map pass");
}

void RelightRenderer::Impl::camera_pass(const Shot &shot, const LightSource &light, const LightView &lv,
                                        RelitImage &out) {
  const int width = shot.Intrinsics.ViewportPx[0], height = shot.Intrinsics.ViewportPx[1];
  ensure_target(camera_target_, width, height, true, "the relighting camera pass");
  // View matrix on recentred positions: the translation R (origin - C) in double.
  Mat4 view;
  gl_view_matrix(shot, view.m);
  float centre[3], eye[3];
  camera_centre(shot, centre);
  for (int row = 0; row < 3; ++row) {
    double t = 0;
    for (int k = 0; k < 3; ++k) t += double(view.at(row, k)) * (double(origin_[k]) - double(centre[k]));
    view.at(row, 3) = float(t);
    eye[row] = float(double(centre[row]) - double(origin_[row]));
  }
  float min_depth = FLT_MAX, max_depth = -FLT_MAX;
  for (const auto &c : corners_) {
    float z = view.at(2, 3);
    for (int k = 0; k < 3; ++k) z += view.at(2, k) * c[k];
    min_depth = std::min(min_depth, -z);
    max_depth = std::max(max_depth, -z);
  }
  const float far_dist = std::max(max_depth, 1e-6f) * 1.01f + tolerance_;
  const float near_dist = std::max(min_depth * 0.99f, far_dist * 1e-4f);
  Mat4 projection;
  gl_projection_matrix(shot, near_dist, far_dist, projection.m);

  gl_.BindFramebuffer(GL_FRAMEBUFFER, camera_target_.fbo);
  gl_.Viewport(0, 0, width, height);
  set_plain_raster_state(gl_);
  gl_.Enable(GL_DEPTH_TEST);
  const float zero[4] = {0, 0, 0, 0}, clear_depth = 1.0f;
  gl_.ClearBufferfv(GL_COLOR, 0, zero);
  gl_.ClearBufferfv(GL_COLOR, 1, zero);
  gl_.ClearBufferfv(GL_DEPTH, 0, &clear_depth);

  const GLuint p = shade_program_;
  gl_.UseProgram(p);
  gl_.UniformMatrix4fv(gl_.GetUniformLocation(p, "u_view"), 1, GL_FALSE, view.m);
  gl_.UniformMatrix4fv(gl_.GetUniformLocation(p, "u_projection"), 1, GL_FALSE, projection.m);
  const float *d = light.direction.data();
  gl_.Uniform3f(gl_.GetUniformLocation(p, "u_light_dir"), d[0], d[1], d[2]);
  gl_.UniformMatrix4fv(gl_.GetUniformLocation(p, "u_light_view"), 1, GL_FALSE, lv.view);
  gl_.Uniform1f(gl_.GetUniformLocation(p, "u_light_scale"), lv.scale);
  gl_.Uniform1i(gl_.GetUniformLocation(p, "u_light_perspective"), lv.perspective ? 1 : 0);
  gl_.Uniform3f(gl_.GetUniformLocation(p, "u_light_pos"), light.position[0] - origin_[0],
                light.position[1] - origin_[1], light.position[2] - origin_[2]);
  gl_.Uniform1f(gl_.GetUniformLocation(p, "u_light_reference"), std::max(light.reference_distance, 1e-12f));
  gl_.Uniform1f(gl_.GetUniformLocation(p, "u_light_intensity"), light.intensity);
  gl_.Uniform3f(gl_.GetUniformLocation(p, "u_eye"), eye[0], eye[1], eye[2]);
  gl_.Uniform1i(gl_.GetUniformLocation(p, "u_shadow_size"), settings_.shadow_map_size);
  gl_.Uniform1f(gl_.GetUniformLocation(p, "u_tolerance"), tolerance_);
  // The host's active texture unit: GlStateGuard restores that unit's binding.
  GLint unit = GL_TEXTURE0;
  gl_.GetIntegerv(GL_ACTIVE_TEXTURE, &unit);
  gl_.BindTexture(GL_TEXTURE_2D, shadow_target_.color);
  gl_.Uniform1i(gl_.GetUniformLocation(p, "u_shadow_map"), unit - GL_TEXTURE0);
  draw();

  const size_t n = size_t(width) * size_t(height);
  std::vector<float> rgba(4 * n), depth(n);
  gl_.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  gl_.PixelStorei(GL_PACK_ALIGNMENT, 4);
  gl_.PixelStorei(GL_PACK_ROW_LENGTH, 0);
  gl_.PixelStorei(GL_PACK_SKIP_ROWS, 0);
  gl_.PixelStorei(GL_PACK_SKIP_PIXELS, 0);
  gl_.ReadBuffer(GL_COLOR_ATTACHMENT0);
  gl_.ReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, rgba.data());
  gl_.ReadBuffer(GL_COLOR_ATTACHMENT1);
  gl_.ReadPixels(0, 0, width, height, GL_RED, GL_FLOAT, depth.data());
  gl_.ReadBuffer(GL_COLOR_ATTACHMENT0);
  check_gl_error(gl_, "the relighting camera pass");

  out.width = width;
  out.height = height;
  out.rgb.resize(3 * n);
  out.pixel_class.resize(n);
  out.depth.resize(n);
  for (int row = 0; row < height; ++row) {  // GL row 0 is the bottom of the image
    const size_t src = size_t(height - 1 - row) * size_t(width), dst = size_t(row) * size_t(width);
    for (int col = 0; col < width; ++col) {
      const float *s = &rgba[4 * (src + size_t(col))];
      for (int k = 0; k < 3; ++k) out.rgb[3 * (dst + size_t(col)) + size_t(k)] = s[k];
      out.pixel_class[dst + size_t(col)] = uint8_t(std::min(3.0f, std::max(0.0f, std::round(s[3]))));
      out.depth[dst + size_t(col)] = depth[src + size_t(col)];
    }
  }
}

RelitImage RelightRenderer::Impl::render(const Shot &shot, const LightSource &light_in) {
  if (!shot_is_valid(shot))
    throw InputError("Relighting: the camera is not valid (zero focal length, pixel size, viewport or rotation).");
  LightSource light = light_in;
  if (!light.positional) normalise(light_in.direction.data(), light.direction.data(), "light direction");
  LightView lv;
  try {
    lv = make_light_view(light, origin_, radius_ * 1.01f + tolerance_);
  } catch (const InputError &e) {
    throw InputError(std::string("Relighting: ") + e.what());
  }
  RelitImage out;
  GlStateGuard guard(gl_);
  clear_gl_errors(gl_);
  shadow_pass(lv);
  camera_pass(shot, light, lv, out);
  return out;
}

RelightRenderer::RelightRenderer(const MeshView &mesh, const std::vector<VertexFit> &fits,
                                 const GetProcAddressFn &get_proc, const RelightRenderSettings &settings)
    : impl_(new Impl(mesh, fits, get_proc, settings)) {}

RelightRenderer::~RelightRenderer() = default;

RelitImage RelightRenderer::render(const Shot &shot, const LightSource &light) {
  return impl_->render(shot, light);
}

const char *RelightRenderer::renderer_name() const { return impl_->renderer.c_str(); }

cv::Mat render_as_photographed(RelightRenderer &renderer, const Shot &shot, const LightSource &light,
                               int max_scale) {
  const int width = shot.Intrinsics.ViewportPx[0], height = shot.Intrinsics.ViewportPx[1];
  int s = std::max(1, max_scale);
  // Memory (16 bytes per subpixel) and GL limits (8192 per side everywhere).
  while (s > 1 && (double(width) * height * s * s > double(1 << 23) || width * s > 8192 || height * s > 8192)) --s;
  Shot fine = shot;  // the same camera with s x s smaller pixels (VCG pixels scale by s)
  fine.Intrinsics.ViewportPx[0] = width * s;
  fine.Intrinsics.ViewportPx[1] = height * s;
  for (int k = 0; k < 2; ++k) {
    fine.Intrinsics.PixelSizeMm[k] /= float(s);
    fine.Intrinsics.CenterPx[k] *= float(s);
  }
  const RelitImage image = renderer.render(fine, light);
  const cv::Mat fine_rgb(image.height, image.width, CV_32FC3, const_cast<float *>(image.rgb.data()));
  cv::Mat out;
  if (s == 1) fine_rgb.copyTo(out);
  else cv::resize(fine_rgb, out, cv::Size(width, height), 0, 0, cv::INTER_AREA);  // exact s x s box mean
  return out;
}

// ---------------------------------------------------------------------------------------------
// Comparison

void photo_to_linear(const Photo &photo, cv::Mat &linear_rgb, cv::Mat &clipped) {
  const int w = photo.width(), h = photo.height();
  linear_rgb.create(h, w, CV_32FC3);
  clipped.create(h, w, CV_8U);
  const bool wide = photo.pixels.depth() == CV_16U;
  for (int y = 0; y < h; ++y) {
    float *out = linear_rgb.ptr<float>(y);
    uint8_t *clip = clipped.ptr<uint8_t>(y);
    for (int x = 0; x < w; ++x) {
      bool any = false;
      for (int c = 0; c < 3; ++c) {
        const int code = wide ? photo.pixels.ptr<uint16_t>(y)[3 * x + c] : photo.pixels.ptr<uint8_t>(y)[3 * x + c];
        out[3 * x + c] = photo.lut[size_t(code)];
        any = any || code >= photo.saturation_code;
      }
      clip[x] = any ? 255 : 0;
    }
  }
}

namespace {

// True when every 8-neighbour of (x, y) is surface whose depth continues the pixel's surface.
bool interior_pixel(const RelitImage &r, int x, int y, float focal_px) {
  if (x < 1 || y < 1 || x >= r.width - 1 || y >= r.height - 1) return false;
  const size_t i = size_t(y) * size_t(r.width) + size_t(x);
  const float depth = r.depth[i];
  // Up to a 79-degree view angle (tan 5) over one pixel, as the visibility pass's footprint test.
  const float allowed = depth / std::max(focal_px, 1e-6f) * 5.0f + 1e-4f * depth;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const size_t j = size_t(y + dy) * size_t(r.width) + size_t(x + dx);
      if (r.pixel_class[j] == kRelitBackground || std::fabs(r.depth[j] - depth) > allowed) return false;
    }
  return true;
}

// Median and 95th percentile from the histogram (bin centres).
void histogram_stats(PixelComparison &c) {
  if (c.pixels == 0) return;
  const size_t median_rank = (c.pixels - 1) / 2, p95_rank = size_t(0.95 * double(c.pixels - 1) + 0.5);
  size_t seen = 0;
  bool median_done = false;
  for (size_t b = 0; b < c.histogram.size(); ++b) {
    seen += c.histogram[b];
    const double centre = (double(b) + 0.5) * kDeHistogramBin;
    if (!median_done && seen > median_rank) c.median_de2000 = centre, median_done = true;
    if (seen > p95_rank) {
      c.p95_de2000 = centre;
      break;
    }
  }
}

void finish_stats(PixelComparison &c, double de_sum) {
  if (c.pixels == 0) return;
  c.mean_de2000 = de_sum / double(c.pixels);
  histogram_stats(c);
  const double mse = c.squared_error / (3.0 * double(c.pixels));
  c.psnr_db = mse > 0 ? 10 * std::log10(1.0 / mse) : 99.0;
}

} // namespace

namespace {
// Compares the pixels `use` accepts; pixels of a triangle without a fit are predicted black.
template <class Use>
PixelComparison compare_pixels(const RelitImage &render, const cv::Mat &photo_linear, const cv::Mat &photo_clipped,
                               const Use &use) {
  if (photo_linear.cols != render.width || photo_linear.rows != render.height || photo_linear.type() != CV_32FC3 ||
      photo_clipped.size() != photo_linear.size())
    throw InputError("Relighting: the photo is " + std::to_string(photo_linear.cols) + "x" +
                     std::to_string(photo_linear.rows) + " but the camera's viewport is " +
                     std::to_string(render.width) + "x" + std::to_string(render.height) + ".");
  PixelComparison c;
  c.width = render.width;
  c.height = render.height;
  c.de2000.assign(size_t(render.width) * size_t(render.height), -1.0f);
  c.histogram.assign(kDeHistogramBins, 0);
  double de_sum = 0;
  for (int y = 0; y < render.height; ++y) {
    const float *photo = photo_linear.ptr<float>(y);
    const uint8_t *clip = photo_clipped.ptr<uint8_t>(y);
    for (int x = 0; x < render.width; ++x) {
      const size_t i = size_t(y) * size_t(render.width) + size_t(x);
      if (clip[x] || !use(x, y, i)) continue;
      float predicted[3] = {0, 0, 0};
      if (render.pixel_class[i] != kRelitNoFit)
        for (int k = 0; k < 3; ++k) predicted[k] = std::min(1.0f, std::max(0.0f, render.rgb[3 * i + size_t(k)]));
      const double de = delta_e2000_linear_srgb(predicted, photo + 3 * x);
      c.de2000[i] = float(de);
      de_sum += de;
      ++c.histogram[std::min(kDeHistogramBins - 1, size_t(de / kDeHistogramBin))];
      for (int k = 0; k < 3; ++k) {
        const double e = double(predicted[k]) - double(photo[3 * x + k]);
        c.squared_error += e * e;
      }
      ++c.pixels;
    }
  }
  finish_stats(c, de_sum);
  return c;
}
} // namespace

PixelComparison compare_with_photo(const RelitImage &render, const cv::Mat &photo_linear, const cv::Mat &photo_clipped,
                                   float focal_px) {
  return compare_pixels(render, photo_linear, photo_clipped, [&](int x, int y, size_t i) {
    return render.pixel_class[i] == kRelitLit && interior_pixel(render, x, y, focal_px);
  });
}

PixelComparison compare_whole_surface(const RelitImage &render, const cv::Mat &photo_linear,
                                      const cv::Mat &photo_clipped) {
  return compare_pixels(render, photo_linear, photo_clipped, [&](int, int, size_t i) {
    return render.pixel_class[i] == kRelitLit || render.pixel_class[i] == kRelitNoFit;
  });
}

PixelComparison pool_comparisons(const std::vector<const PixelComparison *> &parts) {
  PixelComparison c;
  c.histogram.assign(kDeHistogramBins, 0);
  double de_sum = 0;
  for (const PixelComparison *p : parts) {
    c.pixels += p->pixels;
    c.squared_error += p->squared_error;
    de_sum += p->mean_de2000 * double(p->pixels);
    for (size_t b = 0; b < std::min(p->histogram.size(), c.histogram.size()); ++b) c.histogram[b] += p->histogram[b];
  }
  finish_stats(c, de_sum);
  return c;
}

// ---------------------------------------------------------------------------------------------
// Images

cv::Mat display_image(const cv::Mat &linear_rgb) {
  cv::Mat out(linear_rgb.rows, linear_rgb.cols, CV_8UC3);
  for (int y = 0; y < linear_rgb.rows; ++y) {
    const float *in = linear_rgb.ptr<float>(y);
    uint8_t *o = out.ptr<uint8_t>(y);
    for (int x = 0; x < linear_rgb.cols; ++x)
      for (int c = 0; c < 3; ++c)  // RGB -> BGR
        o[3 * x + 2 - c] = uint8_t(std::lround(255.0f * linear_to_srgb(in[3 * x + c])));
  }
  return out;
}

cv::Mat display_image(const RelitImage &render) {
  const cv::Mat wrapped(render.height, render.width, CV_32FC3, const_cast<float *>(render.rgb.data()));
  cv::Mat out = display_image(wrapped);
  // Unfitted surface in a colour no relit surface has, so that it is not mistaken for shadow.
  for (int y = 0; y < render.height; ++y)
    for (int x = 0; x < render.width; ++x)
      if (render.pixel_class[size_t(y) * size_t(render.width) + size_t(x)] == kRelitNoFit)
        out.at<cv::Vec3b>(y, x) = cv::Vec3b(110, 40, 110);
  return out;
}

cv::Mat heat_map_image(const PixelComparison &comparison, const RelitImage &render, float max_de) {
  cv::Mat grey(render.height, render.width, CV_8U, cv::Scalar(0));
  for (size_t i = 0; i < comparison.de2000.size(); ++i)
    if (comparison.de2000[i] >= 0)
      grey.data[i] =
          uint8_t(std::lround(255.0 * std::min(1.0, double(comparison.de2000[i]) / std::max(max_de, 1e-6f))));
  cv::Mat heat;
  cv::applyColorMap(grey, heat, cv::COLORMAP_TURBO);
  for (int y = 0; y < render.height; ++y)
    for (int x = 0; x < render.width; ++x) {
      const size_t i = size_t(y) * size_t(render.width) + size_t(x);
      if (i < comparison.de2000.size() && comparison.de2000[i] >= 0) continue;
      const uint8_t cls = render.pixel_class[i];
      const uint8_t v = cls == kRelitBackground ? 0 : cls == kRelitLit ? 128 : 48;
      heat.at<cv::Vec3b>(y, x) = cv::Vec3b(v, v, v);
    }
  return heat;
}

namespace {

cv::Mat placeholder(int width, int height, const std::string &text) {
  cv::Mat m(height, width, CV_8UC3, cv::Scalar(40, 40, 40));
  cv::putText(m, text, cv::Point(width / 10, height / 2), cv::FONT_HERSHEY_SIMPLEX, std::max(0.5, width / 640.0),
              cv::Scalar(200, 200, 200), 1, cv::LINE_AA);
  return m;
}

// Colour bar with ticks at 0, max/2 and max under a panel of `width` pixels.
cv::Mat colour_bar(int width, float max_de, double font) {
  const int h = int(std::lround(28 * font / 0.5)), bar_h = h / 2;
  cv::Mat strip(h, width, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::Mat ramp(1, width, CV_8U);
  for (int x = 0; x < width; ++x) ramp.at<uint8_t>(0, x) = uint8_t(255 * x / std::max(1, width - 1));
  cv::Mat colours;
  cv::applyColorMap(ramp, colours, cv::COLORMAP_TURBO);
  for (int y = 0; y < bar_h; ++y) colours.row(0).copyTo(strip.row(y));
  char text[64];
  for (int t = 0; t <= 2; ++t) {
    std::snprintf(text, sizeof text, t == 2 ? "%.3g dE2000" : "%.3g", double(max_de) * t / 2);
    int base = 0;
    const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, font * 0.8, 1, &base);
    const int x = std::min(std::max(0, (width - 1) * t / 2 - size.width / 2), width - size.width);
    cv::putText(strip, text, cv::Point(x, h - 3), cv::FONT_HERSHEY_SIMPLEX, font * 0.8, cv::Scalar(230, 230, 230), 1,
                cv::LINE_AA);
  }
  return strip;
}

} // namespace

cv::Mat side_by_side(const cv::Mat &render_bgr, const cv::Mat &photo_bgr, const cv::Mat &heat_bgr,
                     const std::string &title, float max_de) {
  const cv::Mat &ref = !render_bgr.empty() ? render_bgr : !photo_bgr.empty() ? photo_bgr : heat_bgr;
  const int w = ref.empty() ? 320 : ref.cols, h = ref.empty() ? 240 : ref.rows;
  const double font = std::max(0.45, w / 1280.0);
  const int title_h = int(std::lround(30 * font / 0.5));
  const cv::Mat bar = colour_bar(w, max_de, font);
  cv::Mat out(title_h + h + bar.rows, 3 * w, CV_8UC3, cv::Scalar(0, 0, 0));
  const cv::Mat panels[3] = {render_bgr.empty() ? placeholder(w, h, "no render") : render_bgr,
                             photo_bgr.empty() ? placeholder(w, h, "no photo") : photo_bgr,
                             heat_bgr.empty() ? placeholder(w, h, "no comparison") : heat_bgr};
  const char *names[3] = {"model", "photo", "CIEDE2000"};
  for (int k = 0; k < 3; ++k) {
    cv::Mat panel;
    if (panels[k].size() == cv::Size(w, h)) panel = panels[k];
    else cv::resize(panels[k], panel, cv::Size(w, h));
    panel.copyTo(out(cv::Rect(k * w, title_h, w, h)));
    cv::putText(out, names[k], cv::Point(k * w + 6, title_h + int(22 * font / 0.5)), cv::FONT_HERSHEY_SIMPLEX, font,
                cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  cv::putText(out, title, cv::Point(6, title_h - int(8 * font / 0.5)), cv::FONT_HERSHEY_SIMPLEX, font,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  bar.copyTo(out(cv::Rect(2 * w, title_h + h, w, bar.rows)));
  return out;
}

cv::Mat contact_sheet(const std::vector<cv::Mat> &panels, int columns, int panel_width) {
  if (panels.empty()) return cv::Mat();
  columns = std::max(1, std::min(columns, int(panels.size())));
  panel_width = std::max(16, panel_width);
  std::vector<cv::Mat> scaled;
  int cell_h = 0;
  for (const cv::Mat &p : panels) {
    const int h = std::max(1, int(std::lround(double(p.rows) * panel_width / std::max(1, p.cols))));
    cv::Mat s;
    cv::resize(p, s, cv::Size(panel_width, h), 0, 0, cv::INTER_AREA);
    cell_h = std::max(cell_h, h);
    scaled.push_back(s);
  }
  const int rows = (int(scaled.size()) + columns - 1) / columns, gap = 4;
  cv::Mat sheet(rows * cell_h + (rows - 1) * gap, columns * panel_width + (columns - 1) * gap, CV_8UC3,
                cv::Scalar(24, 24, 24));
  for (size_t i = 0; i < scaled.size(); ++i) {
    const int r = int(i) / columns, c = int(i) % columns;
    scaled[i].copyTo(sheet(cv::Rect(c * (panel_width + gap), r * (cell_h + gap), panel_width, scaled[i].rows)));
  }
  return sheet;
}

void write_png_atomically(const std::string &path, const cv::Mat &image) {
  std::vector<uint8_t> bytes;
  if (image.empty() || !cv::imencode(".png", image, bytes))
    throw ProcessingError("Cannot encode the image '" + path + "' as PNG.");
  write_text_file_atomically(path, std::string(bytes.begin(), bytes.end()));
}

// ---------------------------------------------------------------------------------------------
// Tables and the per-raster loop

namespace {

std::string csv_field(const std::string &s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

struct RasterImages {
  cv::Mat render, photo, heat;
};

void ensure_folder(const std::string &folder) {
  if (!QDir().mkpath(QString::fromStdString(folder)))
    throw ProcessingError("Cannot create the output folder '" + folder + "': check the path and permissions.");
}

// Output paths of every file relight_rasters writes, checked against the inputs.
std::vector<std::string> output_paths(const std::vector<Raster> &rasters, const std::string &folder) {
  std::vector<std::string> paths;
  for (size_t r = 0; r < rasters.size(); ++r) {
    char prefix[32];
    std::snprintf(prefix, sizeof prefix, "relight_%03zu_", r);
    std::string label = rasters[r].label;  // "light_007.png" -> relight_007_light_007.png
    const size_t dot = label.find_last_of('.');
    if (dot != std::string::npos && dot > 0 && label.size() - dot <= 5) label.erase(dot);
    paths.push_back(join_path(folder, prefix + file_safe_label(label) + ".png"));
  }
  paths.push_back(join_path(folder, "contact_sheet.png"));
  paths.push_back(join_path(folder, "relight_table.csv"));
  for (const std::string &p : paths)
    for (const Raster &r : rasters)
      if (p == r.image_path)
        throw InputError("The relighting output '" + p + "' would overwrite the photo of raster '" + r.label +
                         "': choose another output folder.");
  return paths;
}

// The raster's photo as linear RGB and its clipped pixels; InputError names the raster.
void load_linear(const Raster &raster, const RelightOutputOptions &options, cv::Mat &linear, cv::Mat &clipped) {
  Photo photo;
  try {
    photo = load_photo(raster.image_path, options.encoding, options.saturation_level, raster.width(), raster.height());
  } catch (const InputError &e) {
    throw InputError("Raster '" + raster.label + "': " + e.what());
  }
  photo_to_linear(photo, linear, clipped);
}

// Per raster: the colour calibration of its viewpoint (null: uncorrected) and its photo index there.
struct ColorPlan {
  std::vector<ColorCalibration> viewpoints;
  std::vector<const ColorCalibration *> of_raster;
  std::vector<size_t> photo_of;
};

ColorSettings color_settings(const RelightOutputOptions &options, size_t viewpoint, size_t viewpoints) {
  const std::vector<float> &c = options.chart_corners;
  if (!c.empty() && c.size() != 8 && c.size() != 8 * viewpoints)
    throw InputError("Chart corners: " + std::to_string(c.size()) + " numbers for " + std::to_string(viewpoints) +
                     " viewpoint(s): give 8 (x y of the dark skin, bluish green, black and white patch centres) for "
                     "all viewpoints, 8 per viewpoint, or none to detect the chart.");
  ColorSettings s;
  s.require_chart = options.color_correction == RelightColorCorrection::Required;
  s.exposure = options.exposure;
  s.manual = !c.empty();
  const size_t first = c.size() == 8 ? 0 : 8 * viewpoint;
  if (s.manual) std::copy(c.begin() + long(first), c.begin() + long(first + 8), s.corners);
  return s;
}

// Calibrates each viewpoint from the chart in its photos, as the fit does (pipeline.cpp).
ColorPlan plan_colors(const std::vector<Raster> &rasters, const std::vector<std::array<float, 3>> &lights_world,
                      const RelightOutputOptions &options, std::vector<std::string> &log) {
  ColorPlan plan;
  plan.of_raster.assign(rasters.size(), nullptr);
  plan.photo_of.assign(rasters.size(), 0);
  if (options.color_correction == RelightColorCorrection::Off) return plan;
  const std::vector<std::vector<size_t>> groups = relight_viewpoints(rasters);
  plan.viewpoints.reserve(groups.size());  // of_raster points into it
  for (size_t v = 0; v < groups.size(); ++v) {
    const std::vector<size_t> &group = groups[v];
    std::vector<std::string> names;
    std::vector<std::array<double, 3>> lights_cam;
    for (size_t r : group) {
      names.push_back(rasters[r].label);
      float cam[3];
      world_to_camera_direction(rasters[r].shot, lights_world[r].data(), cam);
      lights_cam.push_back({{cam[0], cam[1], cam[2]}});
    }
    const RgbLoader load = [&](size_t i) {
      cv::Mat linear, clipped;
      load_linear(rasters[group[i]], options, linear, clipped);
      return linear;
    };
    const std::string where = "viewpoint " + std::to_string(v + 1) + " (" + std::to_string(group.size()) + " photos)";
    try {
      plan.viewpoints.push_back(
          calibrate_colors(group.size(), load, color_settings(options, v, groups.size()), &lights_cam, names));
    } catch (const InputError &e) {
      throw InputError("Colour correction is required but failed for " + where + ": " + e.what());
    }
    const ColorCalibration &cal = plan.viewpoints.back();
    for (const std::string &line : cal.log) log.push_back(where + ": " + line);
    if (!cal.corrected) log.push_back(where + ": no usable chart: photos compared as decoded.");
    for (size_t i = 0; i < group.size(); ++i) {
      plan.of_raster[group[i]] = cal.corrected ? &cal : nullptr;
      plan.photo_of[group[i]] = i;
    }
  }
  return plan;
}

PixelComparison relight_one(RelightRenderer &renderer, const Raster &raster, const LightSource &light,
                            const RelightOutputOptions &options, const ColorCalibration *color, size_t color_photo,
                            RasterImages *images, PixelComparison *whole_surface) {
  if (!shot_is_valid(raster.shot))
    throw InputError("Raster '" + raster.label + "' has no valid camera: check its <VCGCamera> in the project.");
  cv::Mat linear, clipped;
  load_linear(raster, options, linear, clipped);
  if (color) {  // as the fit corrects its samples: corrected = M(rgb / exposure), no negative light
    linear = apply_color_calibration(*color, color_photo, linear);
    cv::max(linear, 0.0, linear);
  }
  const RelitImage render = renderer.render(raster.shot, light);
  const float focal_px = raster.shot.Intrinsics.FocalMm / raster.shot.Intrinsics.PixelSizeMm[0];
  PixelComparison c = compare_with_photo(render, linear, clipped, focal_px);
  if (whole_surface) {
    *whole_surface = compare_whole_surface(render, linear, clipped);
    whole_surface->de2000.clear();
    whole_surface->de2000.shrink_to_fit();
  }
  if (images) {
    images->render = display_image(render);
    images->photo = display_image(linear);
    images->heat = heat_map_image(c, render, options.heat_map_max_de);
  }
  return c;
}

std::string title_of(const RelightRow &row) {
  const PixelComparison &c = row.comparison;
  if (c.pixels == 0) return row.label + ": no lit visible pixel to compare";
  return row.label + ": CIEDE2000 mean " + fixed(c.mean_de2000, 2) + ", p95 " + fixed(c.p95_de2000, 2) + ", PSNR " +
         fixed(c.psnr_db, 1) + " dB over " + std::to_string(c.pixels) + " lit pixels";
}

} // namespace

std::string relight_table_csv(const std::vector<RelightRow> &rows) {
  std::ostringstream out;
  out << "raster,photo,pixels,mean_de2000,median_de2000,p95_de2000,psnr_db,"
         "whole_surface_pixels,whole_surface_mean_de2000,whole_surface_median_de2000,whole_surface_p95_de2000,"
         "whole_surface_psnr_db\n";
  for (const RelightRow &r : rows) {
    const PixelComparison &c = r.comparison, &w = r.whole_surface;
    out << csv_field(r.label) << ',' << csv_field(r.photo) << ',' << c.pixels << ',' << fixed(c.mean_de2000, 4) << ','
        << fixed(c.median_de2000, 4) << ',' << fixed(c.p95_de2000, 4) << ',' << fixed(c.psnr_db, 3) << ','
        << w.pixels << ',' << fixed(w.mean_de2000, 4) << ',' << fixed(w.median_de2000, 4) << ','
        << fixed(w.p95_de2000, 4) << ',' << fixed(w.psnr_db, 3) << '\n';
  }
  return out.str();
}

RelightReport relight_rasters(RelightRenderer &renderer, const std::vector<Raster> &rasters,
                              const std::vector<LightSource> &lights,
                              const RelightOutputOptions &options, const ProgressFn &progress) {
  if (lights.size() != rasters.size())
    throw ProcessingError("internal: " + std::to_string(lights.size()) + " lights for " +
                          std::to_string(rasters.size()) + " rasters");
  const bool write = !options.folder.empty();
  std::vector<std::string> paths;
  if (write) {
    paths = output_paths(rasters, options.folder);
    ensure_folder(options.folder);
  }
  RelightReport report;
  const ColorPlan colors = plan_colors(rasters, light_directions(lights), options, report.color_log);
  std::vector<cv::Mat> panels;
  for (size_t r = 0; r < rasters.size(); ++r) {
    if (progress && !progress(float(r) / float(std::max<size_t>(1, rasters.size())), "relighting"))
      throw ProcessingError("cancelled");
    RasterImages images;
    RelightRow row;
    row.label = rasters[r].label;
    row.photo = rasters[r].image_path;
    row.comparison = relight_one(renderer, rasters[r], lights[r], options, colors.of_raster[r],
                                 colors.photo_of[r], write ? &images : nullptr, &row.whole_surface);
    if (write) {
      panels.push_back(side_by_side(images.render, images.photo, images.heat, title_of(row), options.heat_map_max_de));
      write_png_atomically(paths[r], panels.back());
      report.files.push_back(paths[r]);
    }
    row.comparison.de2000.clear();  // the per-pixel map is only needed for the image
    row.comparison.de2000.shrink_to_fit();
    report.rows.push_back(std::move(row));
  }
  std::vector<const PixelComparison *> parts;
  for (const RelightRow &row : report.rows) parts.push_back(&row.comparison);
  report.overall.label = "all";
  report.overall.comparison = pool_comparisons(parts);
  std::vector<const PixelComparison *> whole_parts;
  for (const RelightRow &row : report.rows) whole_parts.push_back(&row.whole_surface);
  report.overall.whole_surface = pool_comparisons(whole_parts);
  if (write) {
    write_png_atomically(paths[rasters.size()],
                         contact_sheet(panels, options.sheet_columns, options.sheet_panel_width));
    std::vector<RelightRow> table = report.rows;
    table.push_back(report.overall);
    write_text_file_atomically(paths[rasters.size() + 1], relight_table_csv(table));
    report.files.push_back(paths[rasters.size()]);
    report.files.push_back(paths[rasters.size() + 1]);
  }
  if (progress) progress(1.0f, "relighting");
  return report;
}

// ---------------------------------------------------------------------------------------------
// Cameras and names

namespace {

// Rodrigues rotation of v about the unit axis u by angle t (radians).
vcg::Point3f rotate(const vcg::Point3f &v, const vcg::Point3f &u, float t) {
  const float c = std::cos(t), s = std::sin(t);
  return v * c + (u ^ v) * s + u * ((u * v) * (1 - c));
}

} // namespace

std::vector<std::vector<size_t>> relight_viewpoints(const std::vector<Raster> &rasters) {
  std::vector<std::vector<size_t>> groups;
  for (size_t r = 0; r < rasters.size(); ++r) {
    auto it = std::find_if(groups.begin(), groups.end(), [&](const std::vector<size_t> &g) {
      return same_shot(rasters[g.front()].shot, rasters[r].shot);
    });
    if (it == groups.end()) it = groups.insert(groups.end(), std::vector<size_t>());
    it->push_back(r);
  }
  return groups;
}

Shot orbit_shot(const Shot &base, const float pivot[3], float azimuth_deg, float elevation_deg, float distance_scale) {
  if (!(distance_scale > 0) || !std::isfinite(distance_scale) || !std::isfinite(azimuth_deg) ||
      !std::isfinite(elevation_deg))
    throw InputError("Novel view: the distance scale must be positive and the angles finite.");
  const vcg::Matrix44f rot = base.Extrinsics.Rot();
  vcg::Point3f axis[3];
  for (int i = 0; i < 3; ++i) axis[i] = vcg::Point3f(rot[i][0], rot[i][1], rot[i][2]);
  const float deg = float(M_PI / 180.0);
  const vcg::Point3f p(pivot[0], pivot[1], pivot[2]);
  // Azimuth about the camera's up axis (y), then elevation about the rotated right axis (x):
  // positive elevation moves the camera up, i.e. a rotation by -elevation about x.
  auto apply = [&](vcg::Point3f v) {
    const vcg::Point3f up = axis[1];
    v = rotate(v, up, azimuth_deg * deg);
    const vcg::Point3f right = rotate(axis[0], up, azimuth_deg * deg);
    return rotate(v, right, -elevation_deg * deg);
  };
  Shot out = base;
  vcg::Matrix44f r;
  r.SetIdentity();
  for (int i = 0; i < 3; ++i) {
    const vcg::Point3f a = apply(axis[i]);
    for (int j = 0; j < 3; ++j) r[i][j] = a[j];
  }
  out.Extrinsics.SetRot(r);
  out.Extrinsics.SetTra(p + apply(base.GetViewPoint() - p) * distance_scale);
  return out;
}

std::string file_safe_label(const std::string &label) {
  std::string out;
  for (char c : label) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                    c == '-' || c == '_';
    out += ok ? c : '_';
  }
  return out.empty() ? std::string("raster") : out;
}

} // namespace vbrdf
