#pragma once
// Occlusion tests for every vertex: from a camera (is another part of the mesh in front of it?)
// and from a directional light (is the vertex in cast shadow?). Two back ends share this contract:
// GL depth passes (visibility_gl.h) and a CPU ray-cast reference (visibility_cpu.h) used by tests.
// Frustum, back-facing and attached-shadow (N.L <= 0) tests are NOT done here (samples.cpp does
// them per vertex); these passes only answer "is other geometry in the way?".
#include <cstdint>
#include <memory>

#include "camera.h"
#include "mesh_view.h"

namespace vbrdf {

struct VisibilitySettings {
  // Depth tolerance as a fraction of the mesh bounding-box diagonal: a vertex counts as visible
  // when it is at most this much behind the first surface along the ray.
  float depth_tolerance = 0.002f;
  // Resolution (square) of the light-view orthographic depth map over the mesh bounds.
  // 0 = automatic (resolved_shadow_map_size).
  int shadow_map_size = 0;
};

// The shadow-map resolution to use: `settings.shadow_map_size` when positive; for 0, the power of
// two that makes a texel at most a quarter of the median edge length over the mesh's bounding
// sphere, clamped to [1024, 4096] (a shadow edge is then placed to within a fraction of a vertex
// spacing; finer maps cost time, quadratically, and change few vertices' flags). Throws InputError when negative.
int resolved_shadow_map_size(const MeshView &mesh, const VisibilitySettings &settings);

class VisibilityBackend {
public:
  virtual ~VisibilityBackend() = default;
  virtual const char *name() const = 0;
  // out[v] = 1 when no other geometry hides vertex v from the camera of `shot`, else 0;
  // 2 when it is not hidden but the 2x2 pixel footprint of its bilinear colour sample also
  // covers background or another surface (a mixed pixel at a silhouette or mesh border: the
  // colour is contaminated). Only back ends with a depth map report 2 (GL); the CPU ray caster
  // reports 1. Vertices outside the image or behind the camera get 1 (not this pass's concern).
  virtual void camera_pass(const Shot &shot, uint8_t *out) = 0;
  // out[v] = 1 when no geometry lies between vertex v and a directional light shining from
  // `dir_world` (unit vector towards the light), else 0 (cast shadow).
  virtual void light_pass(const float dir_world[3], uint8_t *out) = 0;
};

// CPU reference: rays from each vertex (offset along the ray by the tolerance) against a
// vcglib uniform grid over the triangles. Exact but slow; OpenMP-parallel.
std::unique_ptr<VisibilityBackend> make_cpu_visibility(const MeshView &mesh, const VisibilitySettings &settings);

} // namespace vbrdf
