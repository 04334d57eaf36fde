#pragma once
// The view from a light, for shadow maps: one definition for the visibility pass (visibility_gl)
// and the relighting renderer (relight_render), so that both put a shadow edge in the same place.
//
// Positions are relative to `origin` (the mesh's bounding-box centre: the GL passes upload them
// that way) and the mesh lies within `radius` of it.
//  - Directional light: an orthographic view along -direction over the bounding sphere; depth in
//    [-radius, radius] around the origin.
//  - Point light: a perspective view from the light's position towards the origin whose frustum
//    just holds the bounding sphere (the light lies outside it: resolve_lights checks that), so one
//    map sees the whole mesh and no cube map is needed.
// Depth is the linear distance along the view axis in both cases (what the depth shaders write).
#include "inputs/light_source.h"

namespace vbrdf {

struct LightView {
  float view[16] = {0};        // column-major, on origin-relative positions
  float projection[16] = {0};  // column-major GL projection
  bool perspective = false;
  // Window mapping for a map of `size` texels: wx = (scale * vx / w + 1) * size / 2 with
  // w = depth (perspective) or 1 (orthographic); likewise wy with vy.
  float scale = 1;
};

// Builds the view of `light` over the sphere (origin, radius). Throws InputError for a zero or
// non-finite direction, a non-finite position, or a point light within the sphere.
LightView make_light_view(const LightSource &light, const float origin[3], float radius);

// Projects an origin-relative point into a `size` x `size` map of the view: window coordinates
// (texels, GL convention, centres at + 0.5) and linear depth. Returns false when the point lies
// behind a point light (depth <= 0: it cannot be shadowed from there).
bool light_view_project(const LightView &v, const float local[3], int size, float &wx, float &wy, float &depth);

} // namespace vbrdf
