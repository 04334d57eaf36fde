#pragma once
// The photo's pixel footprint of a vertex: how much the shading normal varies over the patch of
// surface that the vertex's sample averages (a pixel of the photo, then the bilinear sample at the
// vertex's projection). A sharp highlight seen through such a patch is broader and lower than the
// surface's own lobe (lobe.h ggx_lobe_through_footprint); Sample::footprint carries the variance so
// that the fits recover the surface's lobe and each camera is predicted through its own footprint.
//
//   v = kPhotoFootprintVariance * (|dN/dx|^2 + |dN/dy|^2)
//
// dN/dx: the change of the shading normal per image pixel along x (y likewise) at the vertex:
// the mesh's normal gradient (least squares over the 1-ring: the normals are interpolated
// linearly over each triangle, as renderers shade) times the surface step of one pixel (the
// pixel's ray moved by one pixel, met on the vertex's tangent plane). kPhotoFootprintVariance:
// the variance in pixels^2, per axis, of a box pixel (1/12) resampled bilinearly (a tent, 1/6).
// The GL renderer takes the same quantity from its own derivatives (shaders/reflectance_model.glsl,
// one box pixel: 1/12).
#include <cstddef>
#include <vector>

#include "base/mesh_view.h"
#include "inputs/camera.h"

namespace vbrdf {

constexpr float kPhotoFootprintVariance = 0.25f;

// Per vertex, the normal gradient G (row-major 3x3, world units): dN = G dp for a step dp in the
// vertex's tangent plane, fitted by least squares to the 1-ring's normal and position differences
// (one pass over the triangles' edges; no adjacency is built).
// Safeguards: a vertex with fewer than two non-collinear neighbours (isolated, a needle's tip) or
// non-finite data gets G = 0 (no footprint: the lobe as at the vertex).
std::vector<float> normal_gradients(const MeshView &mesh);

// What footprint_variance needs of a photo's camera (taken once per photo: the gatherer calls it
// for every sample): centre, image axes (x right, y up) and viewing direction in world
// coordinates, focal lengths in pixels.
struct FootprintCamera {
  double centre[3], x_axis[3], y_axis[3], forward[3];
  double fx = 0, fy = 0;
};
FootprintCamera footprint_camera(const Raster &raster);

// v (above) of the vertex at `position` with `normal` and 3x3 gradient `gradient` seen by
// `camera`, clamped to [0, kMaxFootprintVariance] (lobe.h): grazing views, where a pixel spans a
// long strip of surface, end at the clamp. 0 when back-facing or behind the camera, or for a zero
// normal or focal length.
float footprint_variance(const FootprintCamera &camera, const float position[3], const float normal[3],
                         const float gradient[9]);
inline float footprint_variance(const Raster &raster, const float position[3], const float normal[3],
                                const float gradient[9]) {
  return footprint_variance(footprint_camera(raster), position, normal, gradient);
}

} // namespace vbrdf
