// CPU reference for the visibility contract (visibility.h): one ray per vertex and pass (plus, for
// a vertex the camera sees, one per texel of its bilinear footprint), traced through a vcglib
// uniform grid over the triangles. Slow but exact up to floating point; the GL
// passes are tested against it.
//
// Why the offset: a ray starting exactly on the vertex hits the vertex's own triangles at t ~ 0
// (rounding decides), so it starts `tolerance` along the ray. This also gives the same meaning as
// the GL depth test: the vertex is clear when the first surface along the ray is at most
// `tolerance` in front of it. Thin features closer than the tolerance (a sheet of paper lying on
// the surface) therefore do not occlude.
//
// Grazing angles: when the ray is nearly tangent to the surface, the offset start point is only
// tolerance * sin(angle) above the surface, and the curved (or bumpy) surface next to the vertex can
// block it: vertices near the terminator / silhouette may be reported in cast shadow / occluded.
// Those vertices have N.L (or N.V) close to 0 and are rejected by the attached-shadow / back-facing
// tests anyway (samples.cpp). A ray lying exactly in a triangle's plane does not hit that triangle.
#include "visibility/visibility.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <vcg/space/box3.h>
#include <vcg/space/index/grid_closest.h>
#include <vcg/space/index/grid_static_ptr.h>
#include <vcg/space/index/space_iterators.h>
#include <vcg/space/ray3.h>

#include "base/errors.h"

namespace vbrdf {

namespace {

// The minimal object vcg::GridStaticPtr indexes: a triangle that can report its bounding box.
struct GridTriangle {
  typedef float ScalarType;
  vcg::Point3f p[3];
  void GetBBox(vcg::Box3f &b) const {
    b.Set(p[0]);
    b.Add(p[1]);
    b.Add(p[2]);
  }
  bool IsD() const { return false; }
};
using TriangleGrid = vcg::GridStaticPtr<GridTriangle, float>;

// Double-precision Moller-Trumbore, both faces. vcglib's IntersectionLineTriangle rejects
// |det| < 1e-6 in absolute terms, which silently misses small triangles of dense meshes.
struct RayTriangleHit {
  bool operator()(const GridTriangle &f, const vcg::Ray3f &ray, float &t) const {
    const double eps = 1e-9;  // slightly inclusive edges: rays through shared edges do not leak
    double o[3], d[3], a[3], e1[3], e2[3];
    for (int k = 0; k < 3; ++k) {
      o[k] = ray.Origin()[k];
      d[k] = ray.Direction()[k];
      a[k] = f.p[0][k];
      e1[k] = double(f.p[1][k]) - a[k];
      e2[k] = double(f.p[2][k]) - a[k];
    }
    const double pv[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]};
    const double det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
    if (det == 0) return false;  // ray parallel to the triangle's plane
    const double inv = 1.0 / det;
    const double tv[3] = {o[0] - a[0], o[1] - a[1], o[2] - a[2]};
    const double u = (tv[0] * pv[0] + tv[1] * pv[1] + tv[2] * pv[2]) * inv;
    if (u < -eps || u > 1 + eps) return false;
    const double qv[3] = {tv[1] * e1[2] - tv[2] * e1[1], tv[2] * e1[0] - tv[0] * e1[2], tv[0] * e1[1] - tv[1] * e1[0]};
    const double v = (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]) * inv;
    if (v < -eps || u + v > 1 + eps) return false;
    const double hit_t = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) * inv;
    if (hit_t < 0) return false;
    t = float(hit_t);
    return true;
  }
};

// Per-thread "already tested" marks for the ray iterator (a triangle spans several cells).
// vcglib's FaceTmark writes into the shared mesh, which is not thread-safe.
struct MarkState {
  std::vector<uint32_t> stamps;
  uint32_t current = 0;
};

class StampMarker {
public:
  StampMarker() = default;
  StampMarker(MarkState *state, const GridTriangle *base) : state_(state), base_(base) {}
  void UnMarkAll() {
    if (++state_->current == 0) {  // wrapped: forget every old stamp
      std::fill(state_->stamps.begin(), state_->stamps.end(), 0u);
      state_->current = 1;
    }
  }
  bool IsMarked(const GridTriangle *f) const { return state_->stamps[size_t(f - base_)] == state_->current; }
  void Mark(const GridTriangle *f) { state_->stamps[size_t(f - base_)] = state_->current; }

private:
  MarkState *state_ = nullptr;
  const GridTriangle *base_ = nullptr;
};

class CpuVisibility : public VisibilityBackend {
public:
  CpuVisibility(const MeshView &mesh, const VisibilitySettings &settings);
  const char *name() const override { return "CPU ray casting"; }
  void camera_pass(const Shot &shot, uint8_t *out) override;
  void light_pass(const LightSource &light, uint8_t *out, const uint64_t *only) override;

private:
  // True when a triangle lies on the ray from `from` along unit `dir` within (0, max_dist].
  bool blocked(MarkState &marks, const vcg::Point3f &from, const vcg::Point3f &dir, float max_dist);
  // True when a triangle lies between vertex position `pos` and the point `target` (a camera
  // centre, a point light): the segment starts `tolerance_` off the vertex and stops at the target
  // (geometry beyond it is not in the way). A target within the tolerance is not blocked.
  bool blocked_towards(MarkState &marks, const vcg::Point3f &pos, const vcg::Point3f &target);
  // vcglib's grid walk misses hits on rays that start outside the grid's box (e.g. above a flat
  // mesh): such rays are started where they enter the box, just inside it. False when the ray
  // misses the box within max_dist; `skipped` is the distance moved.
  bool clip_to_grid(const vcg::Point3f &from, const vcg::Point3f &dir, float max_dist, vcg::Point3f &start,
                    float &skipped) const;
  // Distance to the first triangle along the ray within max_dist, or +infinity when none.
  float first_hit(MarkState &marks, const vcg::Point3f &from, const vcg::Point3f &dir, float max_dist);
  // kCameraClear or kFootprintPartial | mask for a visible vertex (visibility.h): one ray per
  // footprint texel centre, own surface when its first hit lies within the depth slack.
  uint8_t footprint_code(MarkState &marks, const Shot &shot, const vcg::Point3f &centre, const ImagePoint &ip,
                         float vertex_depth, float focal_px);

  MeshView mesh_;
  float tolerance_ = 0;
  float diagonal_ = 0;
  std::vector<GridTriangle> triangles_;
  TriangleGrid grid_;
};

CpuVisibility::CpuVisibility(const MeshView &mesh, const VisibilitySettings &settings) : mesh_(mesh) {
  diagonal_ = compute_bounds(mesh).diagonal();
  tolerance_ = settings.depth_tolerance * diagonal_;
  triangles_.reserve(mesh.index_count / 3);
  for (size_t i = 0; i + 2 < mesh.index_count; i += 3) {
    GridTriangle t;
    for (int c = 0; c < 3; ++c) {
      const uint32_t v = mesh.indices[i + c];
      if (v >= mesh.vertex_count)
        throw InputError("CPU visibility: face " + std::to_string(i / 3) + " references vertex " +
                         std::to_string(v) + " which does not exist.");
      const float *p = mesh.positions + 3 * size_t(v);
      t.p[c] = vcg::Point3f(p[0], p[1], p[2]);
    }
    triangles_.push_back(t);
  }
  if (!triangles_.empty()) grid_.Set(triangles_.begin(), triangles_.end());
}

bool CpuVisibility::clip_to_grid(const vcg::Point3f &from, const vcg::Point3f &dir, float max_dist,
                                 vcg::Point3f &start, float &skipped) const {
  skipped = 0;
  start = from;
  if (grid_.bbox.IsIn(from)) return true;
  float t_enter = 0, t_exit = max_dist;
  for (int k = 0; k < 3; ++k) {
    // Shrunk by a hair so that the start point lies strictly inside (IsIn) after rounding.
    const float pad = 1e-6f * (grid_.bbox.max[k] - grid_.bbox.min[k]);
    const float lo = grid_.bbox.min[k] + pad, hi = grid_.bbox.max[k] - pad;
    if (std::fabs(dir[k]) < 1e-30f) {
      if (from[k] < lo || from[k] > hi) return false;
      continue;
    }
    float a = (lo - from[k]) / dir[k], b = (hi - from[k]) / dir[k];
    if (a > b) std::swap(a, b);
    t_enter = std::max(t_enter, a);
    t_exit = std::min(t_exit, b);
  }
  if (!(t_enter <= t_exit)) return false;
  skipped = t_enter;
  start = from + dir * t_enter;
  return true;
}

bool CpuVisibility::blocked(MarkState &marks, const vcg::Point3f &from, const vcg::Point3f &dir, float max_dist) {
  return first_hit(marks, from, dir, max_dist) < std::numeric_limits<float>::infinity();
}

bool CpuVisibility::blocked_towards(MarkState &marks, const vcg::Point3f &pos, const vcg::Point3f &target) {
  vcg::Point3f dir = target - pos;
  const float dist = dir.Norm();
  if (!(dist > tolerance_)) return false;
  dir /= dist;
  return blocked(marks, pos + dir * tolerance_, dir, dist - tolerance_);
}

float CpuVisibility::first_hit(MarkState &marks, const vcg::Point3f &from, const vcg::Point3f &dir, float max_dist) {
  const float none = std::numeric_limits<float>::infinity();
  if (triangles_.empty() || !(max_dist > 0)) return none;
  vcg::Point3f start;
  float skipped = 0;
  if (!clip_to_grid(from, dir, max_dist, start, skipped)) return none;
  RayTriangleHit hit;
  StampMarker marker(&marks, triangles_.data());
  float t = 0;
  return vcg::GridDoRay(grid_, hit, marker, vcg::Ray3f(start, dir), max_dist - skipped, t) ? skipped + t : none;
}

uint8_t CpuVisibility::footprint_code(MarkState &marks, const Shot &shot, const vcg::Point3f &centre,
                                      const ImagePoint &ip, float vertex_depth, float focal_px) {
  const int width = shot.Intrinsics.ViewportPx[0], height = shot.Intrinsics.ViewportPx[1];
  const int x0 = int(std::floor(ip.x - 0.5f)), y0 = int(std::floor(ip.y - 0.5f));
  const float slack = own_surface_depth_slack(vertex_depth, focal_px, tolerance_);
  uint8_t mask = 0;
  for (int k = 0; k < 4; ++k) {
    const int i = x0 + k % 2, j = y0 + k / 2;
    if (i < 0 || j < 0 || i >= width || j >= height) continue;
    // The texel centre's pixel ray in the camera frame (x right, y up, z towards the viewer; VCG
    // pixels have y up), scaled so that its view depth is 1.
    const auto &in = shot.Intrinsics;
    const float cam[3] = {(float(i) + 0.5f - in.CenterPx[0]) * in.PixelSizeMm[0] / in.FocalMm,
                          (float(height - j) - 0.5f - in.CenterPx[1]) * in.PixelSizeMm[1] / in.FocalMm, -1.0f};
    float world[3];
    camera_to_world_direction(shot, cam, world);  // normalised
    const float len = std::sqrt(cam[0] * cam[0] + cam[1] * cam[1] + 1.0f);  // distance per unit view depth
    // Own surface: a surface within the slack of the vertex's depth along the texel ray, and none
    // in front of that window. Both rays start at the window's near end, next to the mesh (vcglib's
    // grid walk is reliable from there, as for the vertex rays).
    const vcg::Point3f dir(world[0], world[1], world[2]);
    const float near_depth = std::max(vertex_depth - slack, 0.0f);
    const vcg::Point3f window = centre + dir * (near_depth * len);
    const bool surface_in_window = first_hit(marks, window, dir, (vertex_depth + slack - near_depth) * len) <
                                   std::numeric_limits<float>::infinity();
    if (surface_in_window && !blocked(marks, window, -dir, near_depth * len)) mask |= footprint_texel_bit(k);
  }
  return camera_code_of(mask);
}

void CpuVisibility::camera_pass(const Shot &shot, uint8_t *out) {
  if (!shot_is_valid(shot))
    throw InputError("CPU visibility: the camera of the raster is not valid (zero focal length, pixel size, "
                     "viewport or rotation): check the raster's <VCGCamera>.");
  float c[3];
  camera_centre(shot, c);
  const vcg::Point3f centre(c[0], c[1], c[2]);
  const int width = shot.Intrinsics.ViewportPx[0], height = shot.Intrinsics.ViewportPx[1];
  const float focal_px = shot.Intrinsics.FocalMm / shot.Intrinsics.PixelSizeMm[0];
  const ptrdiff_t n = ptrdiff_t(mesh_.vertex_count);
#pragma omp parallel
  {
    MarkState marks;
    marks.stamps.assign(triangles_.size(), 0u);
#pragma omp for schedule(dynamic, 256)
    for (ptrdiff_t v = 0; v < n; ++v) {
      const float *p = mesh_.positions + 3 * v;
      const ImagePoint ip = project_to_image(shot, p);
      if (!ip.in_front || !(ip.x >= 0 && ip.x < width && ip.y >= 0 && ip.y < height)) {
        out[v] = 1;
        continue;
      }
      if (blocked_towards(marks, vcg::Point3f(p[0], p[1], p[2]), centre)) {
        out[v] = kCameraHidden;
        continue;
      }
      out[v] = footprint_code(marks, shot, centre, ip, view_depth(shot, p), focal_px);
    }
  }
}

void CpuVisibility::light_pass(const LightSource &light, uint8_t *out, const uint64_t *only) {
  const ptrdiff_t n = ptrdiff_t(mesh_.vertex_count);
  if (light.positional) {  // segments towards the light, stopping there
    for (float c : light.position)
      if (!std::isfinite(c)) throw InputError("CPU visibility: the light position is not finite.");
    const vcg::Point3f light_pos(light.position[0], light.position[1], light.position[2]);
#pragma omp parallel
    {
      MarkState marks;
      marks.stamps.assign(triangles_.size(), 0u);
#pragma omp for schedule(dynamic, 256)
      for (ptrdiff_t v = 0; v < n; ++v) {
        if (!light_test_wanted(only, size_t(v))) {
          out[v] = 1;
          continue;
        }
        const float *p = mesh_.positions + 3 * v;
        out[v] = blocked_towards(marks, vcg::Point3f(p[0], p[1], p[2]), light_pos) ? 0 : 1;
      }
    }
    return;
  }
  vcg::Point3f dir(light.direction[0], light.direction[1], light.direction[2]);
  const float len = dir.Norm();
  if (!(len > 1e-12f) || !std::isfinite(len)) throw InputError("CPU visibility: the light direction is zero or not finite.");
  dir /= len;
  // Any occluder lies within the bounding box, hence within one diagonal of the vertex.
  const float max_dist = 2 * diagonal_ + tolerance_;
#pragma omp parallel
  {
    MarkState marks;
    marks.stamps.assign(triangles_.size(), 0u);
#pragma omp for schedule(dynamic, 256)
    for (ptrdiff_t v = 0; v < n; ++v) {
      if (!light_test_wanted(only, size_t(v))) {
        out[v] = 1;
        continue;
      }
      const float *p = mesh_.positions + 3 * v;
      const vcg::Point3f pos(p[0], p[1], p[2]);
      out[v] = blocked(marks, pos + dir * tolerance_, dir, max_dist) ? 0 : 1;
    }
  }
}

} // namespace

std::unique_ptr<VisibilityBackend> make_cpu_visibility(const MeshView &mesh, const VisibilitySettings &settings) {
  return std::unique_ptr<VisibilityBackend>(new CpuVisibility(mesh, settings));
}

} // namespace vbrdf
