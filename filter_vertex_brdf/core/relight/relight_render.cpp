// Image-space relighting (contract in relight_render.h): a shadow-map pass from the light and a
// shading pass from the camera, both into float render targets that are read back; comparison and
// composition on the CPU with OpenCV.
#include "relight/relight_render.h"

#include <algorithm>
#include <cfloat>
#include <climits>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/color_difference.h"
#include "base/errors.h"
#include "base/file_util.h"
#include "gl/gl_api.h"
#include "gl/gl_depth.h"
#include "gl/light_view.h"
#include "relight/reflectance_model_source.h"
#include "inputs/viewpoints.h"
#include "base/vec3.h"
#include "visibility/visibility.h"  // resolved_shadow_map_size

namespace vbrdf {

namespace {

const char *const kWho = "Relighting";  // starts its GL error messages

// The shading pass's main() (after shaders/subpixel_grid.glsl): positions are uploaded relative to
// the bounding-box centre (precision of far-from-origin coordinates), view depth is written for the
// comparison, the projected vertex goes on the 1/16-pixel grid (so that the web viewer's rasteriser
// draws the same pixels, docs/web.md#checked-in-a-browser).
const char *const kShadeVertexMain = R"(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_rho_fitted;
layout(location = 3) in vec3 a_ks_alpha_coated;  // upload_model_mesh's layout (location 4 unused)
uniform mat4 u_view;
uniform mat4 u_projection;
uniform vec2 u_viewport;
out vec3 v_position;
out vec3 v_normal;
out vec4 v_rho_fitted;
out vec2 v_ks_alpha;
out float v_coated;
out float v_depth;
void main() {
  vec4 view_pos = u_view * vec4(a_position, 1.0);
  v_position = a_position;
  v_normal = a_normal;
  v_rho_fitted = a_rho_fitted;
  v_ks_alpha = a_ks_alpha_coated.xy;
  v_coated = a_ks_alpha_coated.z;
  v_depth = -view_pos.z;
  gl_Position = snap_to_subpixel_grid(u_projection * view_pos, u_viewport);
}
)";

// Output 0: linear RGB and the RelitPixel class in alpha; output 1: view depth.
// Shadow test as in the visibility pass: lit when the fragment is at most u_tolerance behind the
// farthest of the 2x2 shadow-map texels around it (forgives the map's quantisation).
// main() of the shading pass; the model (reflectance_terms) is shaders/reflectance_model.glsl, shared with the
// live view (reflectance_model_source.h).
const char *const kShadeFragmentMain = R"(
in vec3 v_position;
in vec3 v_normal;
in vec4 v_rho_fitted;
in vec2 v_ks_alpha;
in float v_coated;
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
  vec3 n = unit_normal(v_normal);
  float footprint = pixel_footprint_variance(n);  // before any return: derivatives need the whole quad
  if (v_rho_fitted.a < 0.999) { o_color = vec4(0.0, 0.0, 0.0, 3.0); return; }
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
  vec3 diffuse;
  float spec;
  reflectance_terms(v_rho_fitted.rgb, v_ks_alpha.x, v_ks_alpha.y, v_coated, n, l, e, footprint, diffuse, spec);
  o_color = vec4((diffuse + vec3(spec)) * irradiance, 1.0);
}
)";

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
  RelitImage render(const Shot &shot, const LightSource &light);
  std::string renderer;

private:
  void upload(const MeshView &mesh, const std::vector<VertexFit> &fits);
  void shadow_pass(const LightView &lv);
  void camera_pass(const Shot &shot, const LightSource &light, const LightView &lv, RelitImage &out);
  void draw();

  GlApi gl_;  // before the GL objects: they free themselves through it
  RelightRenderSettings settings_;
  ModelMeshBuffers mesh_;
  float origin_[3] = {0, 0, 0};
  float corners_[8][3] = {};
  float radius_ = 0, tolerance_ = 0;
  GlObject shade_program_, shadow_program_;
  GlRenderTarget camera_target_, shadow_target_;
};

RelightRenderer::Impl::Impl(const MeshView &mesh, const std::vector<VertexFit> &fits, const GetProcAddressFn &get_proc,
                            const RelightRenderSettings &settings)
    : gl_(load_gl_api(get_proc)), settings_(settings) {
  if (fits.size() != mesh.vertex_count)
    throw InputError("Relighting: " + std::to_string(fits.size()) + " per-vertex fits for a mesh of " +
                     std::to_string(mesh.vertex_count) + " vertices: use the fit of this mesh.");
  const GlMeshFrame frame = gl_mesh_frame(mesh, settings.depth_tolerance, kWho);
  std::copy(frame.origin, frame.origin + 3, origin_);
  std::copy(&frame.corners[0][0], &frame.corners[0][0] + 24, &corners_[0][0]);
  radius_ = frame.radius;
  tolerance_ = frame.tolerance;
  VisibilitySettings visibility;
  visibility.depth_tolerance = settings.depth_tolerance;
  visibility.shadow_map_size = settings.shadow_map_size;
  settings_.shadow_map_size = resolved_shadow_map_size(mesh, visibility);
  renderer = gl_.version_string();
  GlStateGuard guard(gl_);
  clear_gl_errors(gl_);
  check_gl_target_size(gl_, settings_.shadow_map_size, settings_.shadow_map_size, kWho, "the shadow map");
  shade_program_ = GlObject::adopt(
      gl_, GlKind::Program,
      build_program(gl_, vertex_program_source(kShadeVertexMain).c_str(), reflectance_program_source(kShadeFragmentMain).c_str(), "the relighting pass"));
  shadow_program_ = GlObject::adopt(
      gl_, GlKind::Program,
      build_program(gl_, kLinearDepthVertexShader, kLinearDepthFragmentShader, "the relighting shadow map"));
  upload(mesh, fits);
  check_gl_error(gl_, "the upload of the mesh for relighting");
}

void RelightRenderer::Impl::upload(const MeshView &mesh, const std::vector<VertexFit> &fits) {
  const double origin[3] = {origin_[0], origin_[1], origin_[2]};
  mesh_ = upload_model_mesh(gl_, mesh, origin, fits, settings_.diffuse);
}

void RelightRenderer::Impl::draw() {
  gl_.BindVertexArray(mesh_.vao);
  if (mesh_.index_count > 0) gl_.DrawElements(GL_TRIANGLES, GLsizei(mesh_.index_count), GL_UNSIGNED_INT, nullptr);
}

// The light's view (light_view.h, shared with the visibility pass).
void RelightRenderer::Impl::shadow_pass(const LightView &lv) {
  const int size = settings_.shadow_map_size;
  ensure_render_target(gl_, shadow_target_, size, size, RenderTargetKind::LinearDepth, kWho, "the relighting shadow map");
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
  ensure_render_target(gl_, camera_target_, width, height, RenderTargetKind::ShadingAndDepth, kWho, "the relighting camera pass");
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
  gl_.Uniform2f(gl_.GetUniformLocation(p, "u_viewport"), float(width), float(height));
  const float *d = light.direction.data();
  gl_.Uniform3f(gl_.GetUniformLocation(p, "u_light_dir"), d[0], d[1], d[2]);
  set_reflectance_model_uniforms(gl_, p, settings_.lobe);
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

} // namespace vbrdf
