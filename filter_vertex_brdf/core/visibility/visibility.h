#pragma once
// Occlusion tests for every vertex: from a camera (is another part of the mesh in front of it?)
// and from a light, directional or point (is the vertex in cast shadow?). Two back ends share this contract:
// GL depth passes (visibility_gl.h) and a CPU ray-cast reference (visibility_cpu.h) used by tests.
// Frustum, back-facing and attached-shadow (N.L <= 0) tests are NOT done here (samples.cpp does
// them per vertex); these passes only answer "is other geometry in the way?".
#include <cstdint>
#include <memory>

#include "inputs/camera.h"
#include "inputs/light_source.h"
#include "base/mesh_view.h"
#include "model/defaults.h"

namespace vbrdf {

struct VisibilitySettings {
  // Depth tolerance as a fraction of the mesh bounding-box diagonal: a vertex counts as visible
  // when it is at most this much behind the first surface along the ray.
  float depth_tolerance = kDefaultDepthTolerance;
  // Resolution (square) of the light-view depth map over the mesh bounds. 0 = automatic: per
  // light, from the mesh's edges as the light sees them, at most resolved_shadow_map_size
  // (pass_size.h: light_pass_size).
  int shadow_map_size = kDefaultShadowMapSize;
  // GL camera pass: rendered at 1/d of the photo's resolution per axis. 0 = automatic (from the
  // mesh's edges as the camera sees them, pass_size.h: camera_pass_divisor); 1 = the photo's
  // resolution.
  int camera_pass_divisor = 0;
  // GL back end: test the vertices against each depth map in a compute shader, where the map
  // stays, and read back one byte per vertex (needs OpenGL 4.3). false, or a context without
  // compute shaders: read the map back and test on the CPU. Both give the same codes.
  bool depth_tests_on_gpu = true;
};

// The largest shadow map of a mesh: `settings.shadow_map_size` when positive; for 0, the power of
// two that makes a texel at most a quarter of the median edge length over the mesh's bounding
// sphere, clamped to [1024, 4096] (a shadow edge is then placed to within a fraction of a vertex
// spacing; finer maps cost time, quadratically, and change few vertices' flags). Throws InputError
// when negative. The relighting renderer uses it; the visibility light pass sizes each light's map
// below it (pass_size.h).
int resolved_shadow_map_size(const MeshView &mesh, const VisibilitySettings &settings);

// Camera-pass output codes (VisibilityBackend::camera_pass).
constexpr uint8_t kCameraHidden = 0;
constexpr uint8_t kCameraClear = 1;
constexpr uint8_t kFootprintPartial = 0x10;  // | 4-bit mask of own-surface footprint texels
constexpr uint8_t kAllFootprintTexels = 0xF;

// The bilinear footprint of image point (x, y) (image pixels, top-left origin, centres at +0.5)
// is the 2x2 block whose top-left texel is (floor(x - 0.5), floor(y - 0.5)). Bit k of a footprint
// mask stands for texel (x0 + k % 2, y0 + k / 2).
inline uint8_t footprint_texel_bit(int k) { return uint8_t(1u << k); }

// The camera-pass code of a vertex that is not hidden, from the mask of its own-surface texels.
inline uint8_t camera_code_of(uint8_t own_texels) {
  return own_texels == kAllFootprintTexels ? kCameraClear : uint8_t(kFootprintPartial | own_texels);
}

// How far a texel's surface depth may differ from the vertex's depth and still count as the
// vertex's own (continuous) surface: across 1.5 texels the depth of a surface seen at up to 79
// degrees from the view axis (slope tan = 5) changes by 1.5 * 5 * (world size of a texel), plus
// the depth tolerance. Creases and steep faces stay own surface; background and separate
// surfaces (depth jumps) do not.
inline float own_surface_depth_slack(float vertex_depth, float focal_px, float tolerance) {
  return tolerance + 1.5f * vertex_depth / focal_px * 5.0f;
}

// Whether light_pass's `only` asks for vertex v (every vertex without one).
inline bool light_test_wanted(const uint64_t *only, size_t v) { return !only || ((only[v / 64] >> (v % 64)) & 1u); }

class VisibilityBackend {
public:
  virtual ~VisibilityBackend() = default;
  virtual const char *name() const = 0;
  // out[v] = kCameraHidden when other geometry hides vertex v from the camera of `shot`;
  // kCameraClear when it is not hidden and every texel of the 2x2 footprint of its bilinear colour
  // sample shows the vertex's own surface; kFootprintPartial | mask when it is not hidden but the
  // footprint straddles a depth jump (silhouette, mesh border, contact with another surface):
  // `mask` (footprint_texel_bit) marks the texels that still show the vertex's own surface, 0 when
  // none does. A texel is "own surface" when the first surface along its pixel ray lies within
  // own_surface_depth_slack of the vertex's depth. Vertices outside the image or behind the camera
  // get kCameraClear (not this pass's concern). Both back ends implement the footprint test (GL
  // from its depth map, the CPU by casting the 4 texel rays).
  virtual void camera_pass(const Shot &shot, uint8_t *out) = 0;
  // out[v] = 1 when no geometry lies between vertex v and the light, else 0 (cast shadow). A
  // directional light shines from `light.direction` (an orthographic shadow map over the mesh; CPU:
  // rays along it); a point light from `light.position` (a perspective shadow map from there,
  // fitted to the mesh's bounding sphere; CPU: rays towards the position, stopping there).
  // `only` (optional): bit v % 64 of only[v / 64] marks the vertices whose answer is wanted (the
  // vertices a photo sees); the others are not tested and get 1. The shadow map is the same.
  virtual void light_pass(const LightSource &light, uint8_t *out, const uint64_t *only = nullptr) = 0;
  // The depth maps of the passes (GL back end; zeros elsewhere): the last camera pass's map size and
  // divisor (pass_size.h), the last light pass's side, and their ranges over all passes so far.
  struct PassSizes {
    int camera_width = 0, camera_height = 0, camera_divisor = 0, shadow_map = 0;
    int divisor_min = 0, divisor_max = 0, shadow_min = 0, shadow_max = 0;
  };
  virtual PassSizes last_pass_sizes() const { return PassSizes(); }
};

// CPU reference: rays from each vertex (offset along the ray by the tolerance) against a
// vcglib uniform grid over the triangles. Exact but slow; OpenMP-parallel.
std::unique_ptr<VisibilityBackend> make_cpu_visibility(const MeshView &mesh, const VisibilitySettings &settings);

} // namespace vbrdf
