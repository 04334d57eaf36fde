// Live relighting (contract in live_relight.h): one shading pass with the shared reflectance model
// (shaders/reflectance_model.glsl) into the caller's framebuffer, or an off-screen one for tests.
#include "relight/live_relight.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "base/errors.h"
#include "gl/gl_api.h"
#include "gl/gl_depth.h"
#include "relight/live_legend.h"
#include "relight/reflectance_model_source.h"

namespace vbrdf {

namespace {

const char *const kWho = "Live relighting";

// False colours are chosen per vertex and interpolated; the model is evaluated per fragment. After
// shaders/subpixel_grid.glsl: vertices on the 1/16-pixel grid, as the relight renderer puts them.
const char *const kLiveVertexMain = R"(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_rho_fitted;
layout(location = 3) in vec3 a_ks_alpha_coated;
layout(location = 4) in vec3 a_status_dq_sq;
uniform mat4 u_modelview;
uniform mat4 u_projection;
uniform vec2 u_viewport;
uniform int u_display;
uniform vec3 u_status_colors[5];
uniform vec3 u_quality_stops[3];
out vec3 v_position;
out vec3 v_normal;
out vec4 v_rho_fitted;
out vec2 v_ks_alpha;
out float v_coated;
out vec3 v_false_color;
vec3 quality_color(float q) {  // live_legend.cpp quality_color
  float t = clamp(q, 0.0, 2.0);
  return t >= 1.0 ? mix(u_quality_stops[1], u_quality_stops[2], t - 1.0) : mix(u_quality_stops[0], u_quality_stops[1], t);
}
void main() {
  v_position = a_position;
  v_normal = a_normal;
  v_rho_fitted = a_rho_fitted;
  v_ks_alpha = a_ks_alpha_coated.xy;
  v_coated = a_ks_alpha_coated.z;
  if (u_display == 3) v_false_color = u_status_colors[int(clamp(a_status_dq_sq.x, 0.0, 4.0) + 0.5)];
  else if (u_display == 4) v_false_color = quality_color(a_status_dq_sq.y);
  else v_false_color = quality_color(a_status_dq_sq.z);
  gl_Position = snap_to_subpixel_grid(u_projection * (u_modelview * vec4(a_position, 1.0)), u_viewport);
}
)";

const char *const kLiveFragmentMain = R"(
in vec3 v_position;
in vec3 v_normal;
in vec4 v_rho_fitted;
in vec2 v_ks_alpha;
in float v_coated;
in vec3 v_false_color;
uniform vec3 u_light_dir;
uniform vec3 u_eye;
uniform int u_eye_is_point;
uniform int u_display;
uniform float u_exposure;
uniform int u_encode_srgb;
layout(location = 0) out vec4 o_color;

void main() {
  vec3 n = unit_normal(v_normal);
  float footprint = pixel_footprint_variance(n);
  vec3 l = u_light_dir;
  float d = dot(n, l);
  vec3 c;
  if (u_display >= 3) {
    c = v_false_color * (0.35 + 0.65 * max(d, 0.0));
    o_color = vec4(c, 1.0);
    return;
  }
  if (v_rho_fitted.a < 0.999) {
    c = vec3(0.35) * (0.35 + 0.65 * max(d, 0.0));
    o_color = vec4(c, 1.0);
    return;
  }
  if (!(d > 0.0)) { o_color = vec4(0.0, 0.0, 0.0, 1.0); return; }
  vec3 e = u_eye_is_point != 0 ? normalize(u_eye - v_position) : u_eye;
  vec3 diffuse;
  float spec;
  reflectance_terms(v_rho_fitted.rgb, v_ks_alpha.x, v_ks_alpha.y, v_coated, n, l, e, footprint, diffuse, spec);
  c = u_display == 1 ? diffuse : u_display == 2 ? vec3(spec) : diffuse + vec3(spec);
  c *= u_exposure;
  o_color = vec4(u_encode_srgb != 0 ? srgb(c) : c, 1.0);
}
)";

// Inverse of the upper-left 3x3 of a column-major 4x4; false when singular.
bool invert_linear_part(const double m[16], double inv[9]) {
  auto a = [&](int r, int c) { return m[c * 4 + r]; };
  const double c00 = a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1), c01 = a(1, 2) * a(2, 0) - a(1, 0) * a(2, 2),
               c02 = a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0);
  const double det = a(0, 0) * c00 + a(0, 1) * c01 + a(0, 2) * c02;
  if (!(std::fabs(det) > 1e-300) || !std::isfinite(det)) return false;
  // inv[r * 3 + c], row-major
  inv[0] = c00 / det;
  inv[1] = (a(0, 2) * a(2, 1) - a(0, 1) * a(2, 2)) / det;
  inv[2] = (a(0, 1) * a(1, 2) - a(0, 2) * a(1, 1)) / det;
  inv[3] = c01 / det;
  inv[4] = (a(0, 0) * a(2, 2) - a(0, 2) * a(2, 0)) / det;
  inv[5] = (a(0, 2) * a(1, 0) - a(0, 0) * a(1, 2)) / det;
  inv[6] = c02 / det;
  inv[7] = (a(0, 1) * a(2, 0) - a(0, 0) * a(2, 1)) / det;
  inv[8] = (a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0)) / det;
  return true;
}

void apply3(const double inv[9], const double v[3], double out[3]) {
  for (int r = 0; r < 3; ++r) out[r] = inv[r * 3] * v[0] + inv[r * 3 + 1] * v[1] + inv[r * 3 + 2] * v[2];
}

bool normalise(double v[3]) {
  const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(len > 1e-300) || !std::isfinite(len)) return false;
  for (int k = 0; k < 3; ++k) v[k] /= len;
  return true;
}

} // namespace

bool eye_to_world_direction(const double modelview[16], const double eye_direction[3], double world_out[3]) {
  double inv[9];
  if (!invert_linear_part(modelview, inv)) return false;
  apply3(inv, eye_direction, world_out);
  return normalise(world_out);
}

class LiveRelight::Impl {
public:
  Impl(const MeshView &mesh, const std::vector<VertexFit> &fits, const GetProcAddressFn &get_proc, LobeForm lobe,
       const DiffuseForms &diffuse);
  void draw(const LiveView &view);
  std::vector<float> render_offscreen(const LiveView &view, int width, int height, bool read_back);
  size_t vertex_count = 0;

private:
  void upload(const MeshView &mesh, const std::vector<VertexFit> &fits);

  GlApi gl_;  // before the GL objects: they free themselves through it
  LobeForm lobe_;
  DiffuseForms diffuse_;
  ModelMeshBuffers mesh_;
  double origin_[3] = {0, 0, 0};
  GlObject program_;
  GlRenderTarget target_;
};

LiveRelight::Impl::Impl(const MeshView &mesh, const std::vector<VertexFit> &fits, const GetProcAddressFn &get_proc,
                        LobeForm lobe, const DiffuseForms &diffuse)
    : gl_(load_gl_api(get_proc)), lobe_(lobe), diffuse_(diffuse) {
  if (fits.size() != mesh.vertex_count)
    throw InputError("Live relighting: " + std::to_string(fits.size()) + " per-vertex fits for a mesh of " +
                     std::to_string(mesh.vertex_count) + " vertices: use the fit of this mesh.");
  const GlMeshFrame frame = gl_mesh_frame(mesh, 0.0f, kWho);
  for (int k = 0; k < 3; ++k) origin_[k] = frame.origin[k];
  vertex_count = mesh.vertex_count;
  GlStateGuard guard(gl_);
  clear_gl_errors(gl_);
  program_ = GlObject::adopt(gl_, GlKind::Program,
                             build_program(gl_, vertex_program_source(kLiveVertexMain).c_str(), reflectance_program_source(kLiveFragmentMain).c_str(),
                                           "the live relighting pass"));
  upload(mesh, fits);
  check_gl_error(gl_, "the upload of the mesh for live relighting");
}

void LiveRelight::Impl::upload(const MeshView &mesh, const std::vector<VertexFit> &fits) {
  mesh_ = upload_model_mesh(gl_, mesh, origin_, fits, diffuse_);
}

void LiveRelight::Impl::draw(const LiveView &view) {
  double inv[9];
  if (!invert_linear_part(view.modelview, inv))
    throw InputError("Live relighting: the view matrix is singular (zoomed to nothing?).");
  // The light: eye -> world (a direction; a position is taken as seen from the object's centre).
  double light[3], l_eye[3] = {view.light_eye[0], view.light_eye[1], view.light_eye[2]};
  if (view.light_eye[3] != 0.0f) {
    double rel[3];
    for (int k = 0; k < 3; ++k) rel[k] = l_eye[k] / double(view.light_eye[3]) - view.modelview[12 + k];
    apply3(inv, rel, light);
    for (int k = 0; k < 3; ++k) light[k] -= origin_[k];
  } else if (!eye_to_world_direction(view.modelview, l_eye, light)) {
    light[0] = light[1] = light[2] = 0;
  }
  if (!normalise(light)) throw InputError("Live relighting: the light direction is zero or not finite.");
  // The eye: the camera centre (perspective), or the direction towards the viewer (orthographic).
  const bool perspective = std::fabs(view.projection[11]) > 1e-12;
  double eye[3];
  if (perspective) {
    const double minus_t[3] = {-view.modelview[12], -view.modelview[13], -view.modelview[14]};
    apply3(inv, minus_t, eye);
    for (int k = 0; k < 3; ++k) eye[k] -= origin_[k];
  } else {
    const double back[3] = {0, 0, 1};
    eye_to_world_direction(view.modelview, back, eye);
  }
  // Modelview on recentred positions: M T(origin), the translation in double.
  float mv[16], proj[16];
  for (int i = 0; i < 16; ++i) mv[i] = float(view.modelview[i]), proj[i] = float(view.projection[i]);
  for (int r = 0; r < 3; ++r) {
    double t = view.modelview[12 + r];
    for (int k = 0; k < 3; ++k) t += view.modelview[k * 4 + r] * origin_[k];
    mv[12 + r] = float(t);
  }

  GlStateGuard guard(gl_);
  clear_gl_errors(gl_);
  set_plain_raster_state(gl_);
  gl_.Enable(GL_DEPTH_TEST);
  const GLuint p = program_;
  gl_.UseProgram(p);
  gl_.UniformMatrix4fv(gl_.GetUniformLocation(p, "u_modelview"), 1, GL_FALSE, mv);
  gl_.UniformMatrix4fv(gl_.GetUniformLocation(p, "u_projection"), 1, GL_FALSE, proj);
  GLint viewport[4] = {0, 0, 1, 1};  // the host's (MeshLab's view) or render_offscreen's
  gl_.GetIntegerv(GL_VIEWPORT, viewport);
  gl_.Uniform2f(gl_.GetUniformLocation(p, "u_viewport"), float(std::max(viewport[2], 1)), float(std::max(viewport[3], 1)));
  gl_.Uniform3f(gl_.GetUniformLocation(p, "u_light_dir"), float(light[0]), float(light[1]), float(light[2]));
  gl_.Uniform3f(gl_.GetUniformLocation(p, "u_eye"), float(eye[0]), float(eye[1]), float(eye[2]));
  gl_.Uniform1i(gl_.GetUniformLocation(p, "u_eye_is_point"), perspective ? 1 : 0);
  gl_.Uniform1i(gl_.GetUniformLocation(p, "u_display"), int(view.display));
  gl_.Uniform1f(gl_.GetUniformLocation(p, "u_exposure"), std::isfinite(view.exposure) ? view.exposure : 1.0f);
  gl_.Uniform1i(gl_.GetUniformLocation(p, "u_encode_srgb"), view.encode_srgb ? 1 : 0);
  set_reflectance_model_uniforms(gl_, p, lobe_);
  std::vector<float> colors;
  for (const LegendEntry &e : fit_status_legend()) colors.insert(colors.end(), e.rgb.begin(), e.rgb.end());
  gl_.Uniform3fv(gl_.GetUniformLocation(p, "u_status_colors"), GLsizei(colors.size() / 3), colors.data());
  colors.clear();
  for (const LegendEntry &e : quality_legend()) colors.insert(colors.end(), e.rgb.begin(), e.rgb.end());
  gl_.Uniform3fv(gl_.GetUniformLocation(p, "u_quality_stops"), GLsizei(colors.size() / 3), colors.data());
  gl_.BindVertexArray(mesh_.vao);
  if (mesh_.index_count > 0) gl_.DrawElements(GL_TRIANGLES, GLsizei(mesh_.index_count), GL_UNSIGNED_INT, nullptr);
  check_gl_error(gl_, "the live relighting pass");
}

std::vector<float> LiveRelight::Impl::render_offscreen(const LiveView &view, int width, int height, bool read_back) {
  GlStateGuard guard(gl_);
  ensure_render_target(gl_, target_, width, height, RenderTargetKind::ShadingAndDepth, kWho, "the off-screen view");
  gl_.BindFramebuffer(GL_FRAMEBUFFER, target_.fbo);
  gl_.Viewport(0, 0, width, height);
  gl_.DepthMask(GL_TRUE);
  const float zero[4] = {0, 0, 0, 0}, clear_depth = 1.0f;
  gl_.ClearBufferfv(GL_COLOR, 0, zero);
  gl_.ClearBufferfv(GL_DEPTH, 0, &clear_depth);
  draw(view);
  if (!read_back) {
    gl_.Finish();
    return {};
  }
  const size_t n = size_t(width) * size_t(height);
  std::vector<float> rgba(4 * n), out(4 * n);
  gl_.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  gl_.PixelStorei(GL_PACK_ALIGNMENT, 4);
  gl_.PixelStorei(GL_PACK_ROW_LENGTH, 0);
  gl_.PixelStorei(GL_PACK_SKIP_ROWS, 0);
  gl_.PixelStorei(GL_PACK_SKIP_PIXELS, 0);
  gl_.ReadBuffer(GL_COLOR_ATTACHMENT0);
  gl_.ReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, rgba.data());
  check_gl_error(gl_, "reading back the live relighting view");
  for (int row = 0; row < height; ++row)  // GL row 0 is the bottom
    std::copy_n(&rgba[4 * size_t(height - 1 - row) * size_t(width)], 4 * size_t(width), &out[4 * size_t(row) * size_t(width)]);
  return out;
}

LiveRelight::LiveRelight(const MeshView &mesh, const std::vector<VertexFit> &fits, const GetProcAddressFn &get_proc,
                         LobeForm lobe, const DiffuseForms &diffuse)
    : impl_(new Impl(mesh, fits, get_proc, lobe, diffuse)) {}
LiveRelight::~LiveRelight() = default;
void LiveRelight::draw(const LiveView &view) { impl_->draw(view); }
std::vector<float> LiveRelight::render_offscreen(const LiveView &view, int width, int height, bool read_back) {
  return impl_->render_offscreen(view, width, height, read_back);
}
size_t LiveRelight::vertex_count() const { return impl_->vertex_count; }

} // namespace vbrdf
