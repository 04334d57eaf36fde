// GL depth passes (contract in visibility.h / visibility_gl.h). The mesh is uploaded once; each
// pass renders the linear view depth of the nearest surface into an R32F target, reads it back and
// tests every vertex on the CPU against the 2x2 texels around its projection.
#include "visibility/visibility_gl.h"

#include <algorithm>
#include <cfloat>
#include <climits>
#include <cmath>
#include <string>
#include <vector>

#include "base/errors.h"
#include "gl/gl_api.h"
#include "gl/gl_depth.h"
#include "gl/light_view.h"

namespace vbrdf {

namespace {

const char *const kWho = "OpenGL visibility";  // starts its GL error messages

// Background value: farther than anything, so vertices next to the mesh silhouette stay clear.
const float kFarAway = FLT_MAX;

void transform(const Mat4 &a, const float p[3], float out[4]) {
  for (int row = 0; row < 4; ++row)
    out[row] = a.at(row, 0) * p[0] + a.at(row, 1) * p[1] + a.at(row, 2) * p[2] + a.at(row, 3);
}

// True when `depth` is at most `tol` behind the farthest of the 2x2 texels nearest to the window
// point (wx, wy) (GL window coordinates, texel centres at integer + 0.5). Taking the farthest of
// the bilinear footprint forgives the half-pixel quantisation at silhouettes and steep slopes.
inline bool depth_clear(const float *map, int w, int h, float wx, float wy, float depth, float tol) {
  const int i0 = int(std::floor(wx - 0.5f)), j0 = int(std::floor(wy - 0.5f));
  const int xa = std::min(std::max(i0, 0), w - 1), xb = std::min(std::max(i0 + 1, 0), w - 1);
  const int ya = std::min(std::max(j0, 0), h - 1), yb = std::min(std::max(j0 + 1, 0), h - 1);
  const float *ra = map + size_t(ya) * size_t(w), *rb = map + size_t(yb) * size_t(w);
  const float far_depth = std::max(std::max(ra[xa], ra[xb]), std::max(rb[xa], rb[xb]));
  return depth <= far_depth + tol;
}

// The camera-pass code of a visible vertex at image point (ix, iy) (image pixels, y down):
// kCameraClear when every texel of its 2x2 bilinear footprint shows the vertex's own surface
// (depth within `allowed` of the vertex depth), else kFootprintPartial | the mask of those that do
// (visibility.h). The depth map is in GL window rows (row 0 = image row h - 1).
inline uint8_t footprint_code(const float *map, int w, int h, float ix, float iy, float depth, float allowed) {
  const int x0 = int(std::floor(ix - 0.5f)), y0 = int(std::floor(iy - 0.5f));
  uint8_t mask = 0;
  for (int k = 0; k < 4; ++k) {
    const int i = x0 + k % 2, row = h - 1 - (y0 + k / 2);
    if (i < 0 || row < 0 || i >= w || row >= h) continue;
    if (std::fabs(map[size_t(row) * size_t(w) + size_t(i)] - depth) <= allowed) mask |= footprint_texel_bit(k);
  }
  return camera_code_of(mask);
}

class GlVisibility : public VisibilityBackend {
public:
  GlVisibility(const MeshView &mesh, const GetProcAddressFn &get_proc, const VisibilitySettings &settings);
  ~GlVisibility() override;
  const char *name() const override { return "OpenGL"; }
  void camera_pass(const Shot &shot, uint8_t *out) override;
  void light_pass(const LightSource &light, uint8_t *out) override;

private:
  void upload_mesh();
  void release_gl();
  void render_depth(const GlRenderTarget &target, const Mat4 &view, const Mat4 &projection, const std::string &what);
  void fill(uint8_t *out, uint8_t value) const;

  MeshView mesh_;
  VisibilitySettings settings_;
  GlApi gl_;
  float origin_[3] = {0, 0, 0};  // bounding-box centre: positions are uploaded relative to it
  float corners_[8][3] = {};     // bounding-box corners, relative to origin_
  float radius_ = 0;             // bounding sphere radius around origin_
  float tolerance_ = 0;          // settings.depth_tolerance * bbox diagonal (world units)
  GLuint program_ = 0, vao_ = 0, vbo_ = 0, ibo_ = 0;
  GLint u_view_ = -1, u_projection_ = -1;
  GlRenderTarget camera_target_, light_target_;
  std::vector<float> depth_;     // read-back buffer, reused between passes
};

GlVisibility::GlVisibility(const MeshView &mesh, const GetProcAddressFn &get_proc, const VisibilitySettings &settings)
    : mesh_(mesh), settings_(settings), gl_(load_gl_api(get_proc)) {
  const GlMeshFrame frame = gl_mesh_frame(mesh, settings.depth_tolerance, kWho);
  std::copy(frame.origin, frame.origin + 3, origin_);
  std::copy(&frame.corners[0][0], &frame.corners[0][0] + 24, &corners_[0][0]);
  radius_ = frame.radius;
  tolerance_ = frame.tolerance;
  settings_.shadow_map_size = resolved_shadow_map_size(mesh, settings);
  check_gl_target_size(gl_, settings_.shadow_map_size, settings_.shadow_map_size, kWho, "the light-view shadow map");

  GlStateGuard guard(gl_);
  clear_gl_errors(gl_);  // errors left by the host are not ours
  try {
    program_ = build_program(gl_, kLinearDepthVertexShader, kLinearDepthFragmentShader, "the visibility depth pass");
    u_view_ = gl_.GetUniformLocation(program_, "u_view");
    u_projection_ = gl_.GetUniformLocation(program_, "u_projection");
    upload_mesh();
    check_gl_error(gl_, "the upload of the mesh for the visibility passes");
  } catch (...) {
    release_gl();  // the destructor does not run when the constructor throws
    throw;
  }
}

GlVisibility::~GlVisibility() { release_gl(); }

void GlVisibility::release_gl() {
  release_render_target(gl_, camera_target_);
  release_render_target(gl_, light_target_);
  if (vao_) gl_.DeleteVertexArrays(1, &vao_);
  if (vbo_) gl_.DeleteBuffers(1, &vbo_);
  if (ibo_) gl_.DeleteBuffers(1, &ibo_);
  if (program_) gl_.DeleteProgram(program_);
  vao_ = vbo_ = ibo_ = program_ = 0;
}

void GlVisibility::upload_mesh() {
  // Relative to the bounding-box centre so that far-from-origin (georeferenced) coordinates keep
  // their precision in the float vertex transform.
  std::vector<float> local(mesh_.vertex_count * 3);
  for (size_t v = 0; v < mesh_.vertex_count; ++v)
    for (int k = 0; k < 3; ++k) local[3 * v + k] = mesh_.positions[3 * v + k] - origin_[k];

  gl_.GenVertexArrays(1, &vao_);
  gl_.BindVertexArray(vao_);
  gl_.GenBuffers(1, &vbo_);
  gl_.BindBuffer(GL_ARRAY_BUFFER, vbo_);
  gl_.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(local.size() * sizeof(float)), local.data(), GL_STATIC_DRAW);
  gl_.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  gl_.EnableVertexAttribArray(0);
  gl_.GenBuffers(1, &ibo_);
  gl_.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo_);  // recorded in our VAO only
  gl_.BufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(mesh_.index_count * sizeof(uint32_t)), mesh_.indices,
                 GL_STATIC_DRAW);
}

// Renders the nearest linear depth into `t` and reads it back into depth_ (GL row order: row 0 is
// the bottom of the image). The caller holds a GlStateGuard.
void GlVisibility::render_depth(const GlRenderTarget &t, const Mat4 &view, const Mat4 &projection,
                                const std::string &what) {
  gl_.BindFramebuffer(GL_FRAMEBUFFER, t.fbo);
  gl_.Viewport(0, 0, t.width, t.height);
  set_plain_raster_state(gl_);
  gl_.Enable(GL_DEPTH_TEST);
  const float clear_color[4] = {kFarAway, kFarAway, kFarAway, kFarAway}, clear_depth = 1.0f;
  gl_.ClearBufferfv(GL_COLOR, 0, clear_color);
  gl_.ClearBufferfv(GL_DEPTH, 0, &clear_depth);

  gl_.UseProgram(program_);
  gl_.UniformMatrix4fv(u_view_, 1, GL_FALSE, view.m);
  gl_.UniformMatrix4fv(u_projection_, 1, GL_FALSE, projection.m);
  gl_.BindVertexArray(vao_);
  if (mesh_.index_count > 0) gl_.DrawElements(GL_TRIANGLES, GLsizei(mesh_.index_count), GL_UNSIGNED_INT, nullptr);

  depth_.resize(size_t(t.width) * size_t(t.height));
  gl_.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  gl_.PixelStorei(GL_PACK_ALIGNMENT, 4);
  gl_.PixelStorei(GL_PACK_ROW_LENGTH, 0);
  gl_.PixelStorei(GL_PACK_SKIP_ROWS, 0);
  gl_.PixelStorei(GL_PACK_SKIP_PIXELS, 0);
  gl_.ReadPixels(0, 0, t.width, t.height, GL_RED, GL_FLOAT, depth_.data());
  check_gl_error(gl_, what);
}

void GlVisibility::fill(uint8_t *out, uint8_t value) const { std::fill(out, out + mesh_.vertex_count, value); }

void GlVisibility::camera_pass(const Shot &shot, uint8_t *out) {
  if (!shot_is_valid(shot))
    throw InputError("OpenGL visibility: the camera of the raster is not valid (zero focal length, pixel size, "
                     "viewport or rotation): check the raster's <VCGCamera>.");
  const int width = shot.Intrinsics.ViewportPx[0], height = shot.Intrinsics.ViewportPx[1];

  // View matrix on recentred positions: the rotation of gl_view_matrix with the translation
  // R (origin - C) computed in double (no cancellation of large world coordinates).
  Mat4 world_view;
  gl_view_matrix(shot, world_view.m);
  float centre[3];
  camera_centre(shot, centre);
  Mat4 view = world_view;
  for (int row = 0; row < 3; ++row) {
    double t = 0;
    for (int k = 0; k < 3; ++k) t += double(world_view.at(row, k)) * (double(origin_[k]) - double(centre[k]));
    view.at(row, 3) = float(t);
  }

  // Near/far from the bounding box as seen from the camera; near > 0 even when the camera is inside.
  float min_depth = FLT_MAX, max_depth = -FLT_MAX;
  for (const auto &c : corners_) {
    float v[4];
    transform(view, c, v);
    min_depth = std::min(min_depth, -v[2]);
    max_depth = std::max(max_depth, -v[2]);
  }
  if (mesh_.vertex_count == 0 || !(max_depth > 0)) {  // everything behind the camera
    fill(out, 1);
    return;
  }
  const float far_dist = max_depth * 1.01f + tolerance_;
  const float near_dist = std::max(min_depth * 0.99f, far_dist * 1e-4f);
  Mat4 projection;
  gl_projection_matrix(shot, near_dist, far_dist, projection.m);

  {
    GlStateGuard guard(gl_);
    clear_gl_errors(gl_);
    ensure_render_target(gl_, camera_target_, width, height, RenderTargetKind::LinearDepth, kWho, "the camera depth pass");
    render_depth(camera_target_, view, projection, "the camera depth pass");
  }

  // GL rasterised without lens distortion: look vertices up with the undistorted projection.
  const bool distorted = shot.Intrinsics.k[0] != 0;
  Shot undistorted = shot;
  for (float &k : undistorted.Intrinsics.k) k = 0;
  const float *map = depth_.data();
  const float tol = tolerance_;
  const float focal_px = shot.Intrinsics.FocalMm / shot.Intrinsics.PixelSizeMm[0];
  const ptrdiff_t n = ptrdiff_t(mesh_.vertex_count);
#pragma omp parallel for schedule(static)
  for (ptrdiff_t v = 0; v < n; ++v) {
    const float *p = mesh_.positions + 3 * v;
    const ImagePoint ip = project_to_image(shot, p);
    if (!ip.in_front || !(ip.x >= 0 && ip.x < width && ip.y >= 0 && ip.y < height)) {
      out[v] = 1;
      continue;
    }
    const ImagePoint lp = distorted ? project_to_image(undistorted, p) : ip;
    // Image y down -> GL window y up (GL row 0 is image row height - 1).
    const float depth = view_depth(shot, p), wx = lp.x, wy = float(height) - lp.y;
    if (!depth_clear(map, width, height, wx, wy, depth, tol)) {
      out[v] = 0;
      continue;
    }
    out[v] = footprint_code(map, width, height, lp.x, lp.y, depth, own_surface_depth_slack(depth, focal_px, tol));
  }
}

// The shadow map from the light (light_view.h: orthographic for a directional light, a perspective
// frustum fitted to the bounding sphere for a point light), then every vertex against it.
void GlVisibility::light_pass(const LightSource &light, uint8_t *out) {
  if (mesh_.vertex_count == 0) return;
  LightView lv;
  try {
    lv = make_light_view(light, origin_, radius_ * 1.01f + tolerance_);
  } catch (const InputError &e) {
    throw InputError(std::string("OpenGL visibility: ") + e.what());
  }
  Mat4 view, projection;
  std::copy(lv.view, lv.view + 16, view.m);
  std::copy(lv.projection, lv.projection + 16, projection.m);
  const int size = settings_.shadow_map_size;
  {
    GlStateGuard guard(gl_);
    clear_gl_errors(gl_);
    ensure_render_target(gl_, light_target_, size, size, RenderTargetKind::LinearDepth, kWho, "the light-view shadow map");
    render_depth(light_target_, view, projection, "the light-view shadow map pass");
  }
  const float *map = depth_.data();
  const float tol = tolerance_;
  const ptrdiff_t n = ptrdiff_t(mesh_.vertex_count);
#pragma omp parallel for schedule(static)
  for (ptrdiff_t v = 0; v < n; ++v) {
    const float *p = mesh_.positions + 3 * v;
    const float local[3] = {p[0] - origin_[0], p[1] - origin_[1], p[2] - origin_[2]};
    float wx, wy, depth;
    if (!light_view_project(lv, local, size, wx, wy, depth)) {
      out[v] = 1;  // behind a point light: nothing between it and the light
      continue;
    }
    out[v] = depth_clear(map, size, size, wx, wy, depth, tol) ? 1 : 0;
  }
}

} // namespace

std::unique_ptr<VisibilityBackend> make_gl_visibility(const MeshView &mesh, const GetProcAddressFn &get_proc,
                                                      const VisibilitySettings &settings) {
  return std::unique_ptr<VisibilityBackend>(new GlVisibility(mesh, get_proc, settings));
}

} // namespace vbrdf
