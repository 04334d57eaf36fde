// Sizes of the visibility depth passes (pass_size.h).
#include "visibility/pass_size.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "base/errors.h"

namespace vbrdf {

namespace {

const size_t kSampledEdges = 4096;

float median_of(std::vector<float> &v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// A column-major 4x4 matrix applied to a point (w = 1) or a vector (w = 0).
void apply(const float *m, const float *p, float w, float out[3]) {
  for (int row = 0; row < 3; ++row)
    out[row] = m[row] * p[0] + m[4 + row] * p[1] + m[8 + row] * p[2] + m[12 + row] * w;
}

int round_up(float value, int step) { return int(std::ceil(value / float(step))) * step; }

} // namespace

int resolved_shadow_map_size(const MeshView &mesh, const VisibilitySettings &settings) {
  if (settings.shadow_map_size > 0) return settings.shadow_map_size;
  if (settings.shadow_map_size < 0)
    throw InputError("The shadow map size must be positive, or 0 for automatic (got " +
                     std::to_string(settings.shadow_map_size) + ").");
  const size_t triangles = mesh.index_count / 3;
  if (triangles == 0) return 1024;
  // Median edge length over at most ~4096 triangles spread over the mesh.
  std::vector<float> edges;
  const size_t step = std::max<size_t>(1, triangles / kSampledEdges);
  for (size_t t = 0; t < triangles; t += step) {
    const float *a = mesh.positions + 3 * size_t(mesh.indices[3 * t]);
    const float *b = mesh.positions + 3 * size_t(mesh.indices[3 * t + 1]);
    const float d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    edges.push_back(std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
  }
  const float median_edge = median_of(edges);
  const float radius = 0.5f * compute_bounds(mesh).diagonal();
  if (!(median_edge > 0) || !(radius > 0)) return 1024;
  const float wanted = 8.0f * radius / median_edge;  // texel = 2 radius / size <= edge / 4
  int size = 1024;
  while (size < kMaxShadowMapSize && float(size) < wanted) size *= 2;
  return size;
}

EdgeSample sample_edges(const MeshView &mesh, const float origin[3]) {
  EdgeSample s;
  const size_t triangles = mesh.index_count / 3;
  const size_t step = std::max<size_t>(1, triangles / kSampledEdges);
  for (size_t t = 0; t < triangles; t += step) {
    const float *p[3];
    for (int k = 0; k < 3; ++k) p[k] = mesh.positions + 3 * size_t(mesh.indices[3 * t + size_t(k)]);
    // One edge per face, rotating through the three so that no direction is favoured.
    const int e = int((t / step) % 3);
    const float *a = p[e], *b = p[(e + 1) % 3];
    float u[3], v[3], n[3];
    for (int k = 0; k < 3; ++k) u[k] = p[1][k] - p[0][k], v[k] = p[2][k] - p[0][k];
    n[0] = u[1] * v[2] - u[2] * v[1], n[1] = u[2] * v[0] - u[0] * v[2], n[2] = u[0] * v[1] - u[1] * v[0];
    const float nl = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int k = 0; k < 3; ++k) {
      s.mid.push_back(0.5f * (a[k] + b[k]) - origin[k]);
      s.vec.push_back(b[k] - a[k]);
      s.normal.push_back(nl > 0 && std::isfinite(nl) ? n[k] / nl : 0.0f);
    }
  }
  return s;
}

int light_pass_size(const EdgeSample &edges, const LightView &lv, const VisibilitySettings &settings, int max_size) {
  if (settings.shadow_map_size > 0) return settings.shadow_map_size;
  // Edge length in texels of a map of size S: |edge_xy| * scale * S / (2 w), w = depth (point
  // light) or 1: the median of |edge_xy| / w over the faces turned to the light.
  std::vector<float> facing, all;
  for (size_t i = 0; i < edges.size(); ++i) {
    float m[3], e[3], n[3];
    apply(lv.view, &edges.mid[3 * i], 1, m);
    apply(lv.view, &edges.vec[3 * i], 0, e);
    apply(lv.view, &edges.normal[3 * i], 0, n);
    const float w = lv.perspective ? -m[2] : 1.0f;
    if (!(w > 0)) continue;
    const float len = std::sqrt(e[0] * e[0] + e[1] * e[1]) / w;
    // Towards the light: +z in the view (orthographic), -m for a point light at the view origin.
    const float towards = lv.perspective ? -(n[0] * m[0] + n[1] * m[1] + n[2] * m[2]) : n[2];
    all.push_back(len);
    if (towards > 0) facing.push_back(len);
  }
  const float median = median_of(facing.size() >= 16 ? facing : all);
  const int upper = std::max(max_size, kMinShadowMapSize);
  if (!(median > 0) || !std::isfinite(median) || !(lv.scale > 0)) return upper;
  const float wanted = 2.0f * kShadowTexelsPerEdge / (lv.scale * median);
  if (!(wanted < float(upper))) return upper;
  return std::min(upper, std::max(kMinShadowMapSize, round_up(wanted, 64)));
}

int camera_pass_divisor(const EdgeSample &edges, const Shot &shot, const float view[16],
                        const VisibilitySettings &settings) {
  if (settings.camera_pass_divisor < 0)
    throw InputError("The camera pass divisor must be positive, or 0 for automatic (got " +
                     std::to_string(settings.camera_pass_divisor) + ").");
  if (settings.camera_pass_divisor > 0) return settings.camera_pass_divisor;
  const int width = shot.Intrinsics.ViewportPx[0], height = shot.Intrinsics.ViewportPx[1];
  const float fx = shot.Intrinsics.FocalMm / shot.Intrinsics.PixelSizeMm[0];
  const float fy = shot.Intrinsics.FocalMm / shot.Intrinsics.PixelSizeMm[1];
  const float cx = shot.Intrinsics.CenterPx[0], cy = shot.Intrinsics.CenterPx[1];
  std::vector<float> lengths;
  for (size_t i = 0; i < edges.size(); ++i) {
    float m[3], e[3], n[3];
    apply(view, &edges.mid[3 * i], 1, m);
    apply(view, &edges.vec[3 * i], 0, e);
    apply(view, &edges.normal[3 * i], 0, n);
    const float depth = -m[2];
    if (!(depth > 0)) continue;
    if (!(n[0] * m[0] + n[1] * m[1] + n[2] * m[2] < 0)) continue;  // turned away from the camera
    const float px = fx * m[0] / depth + cx, py = fy * m[1] / depth + cy;
    if (!(px >= 0 && py >= 0 && px < float(width) && py < float(height))) continue;
    // The edge's image length to first order: the part across the line of sight, over depth.
    const float along = (e[0] * m[0] + e[1] * m[1] + e[2] * m[2]) / (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    const float ex = e[0] - along * m[0], ey = e[1] - along * m[1];
    lengths.push_back(std::sqrt(fx * ex * fx * ex + fy * ey * fy * ey) / depth);
  }
  if (lengths.size() < 16) return 1;  // too little of the mesh in view to measure: photo resolution
  const float median = median_of(lengths);
  if (!(median > 0) || !std::isfinite(median)) return 1;
  int d = std::min(kMaxCameraDivisor, std::max(1, int(std::floor(median / kCameraPixelsPerEdge))));
  while (d > 1 && (std::max(width, height) + d - 1) / d < kMinCameraPassSide) --d;
  return d;
}

std::string describe_pass_sizes(const VisibilityBackend::PassSizes &s) {
  std::string text;
  if (s.divisor_max > 0) {
    text = "camera " + std::to_string(s.camera_width) + "x" + std::to_string(s.camera_height) + " (photo / " +
           std::to_string(s.divisor_min) +
           (s.divisor_max != s.divisor_min ? "-" + std::to_string(s.divisor_max) : std::string()) + ")";
  }
  if (s.shadow_max > 0) {
    text += (text.empty() ? "" : ", ") + std::string("shadow maps ") + std::to_string(s.shadow_min) +
            (s.shadow_max != s.shadow_min ? "-" + std::to_string(s.shadow_max) : std::string());
  }
  return text;
}

Shot divided_shot(const Shot &shot, int divisor) {
  Shot s = shot;
  if (divisor <= 1) return s;
  const int width = shot.Intrinsics.ViewportPx[0], height = shot.Intrinsics.ViewportPx[1];
  s.Intrinsics.ViewportPx[0] = (width + divisor - 1) / divisor;
  s.Intrinsics.ViewportPx[1] = (height + divisor - 1) / divisor;
  s.Intrinsics.PixelSizeMm[0] *= float(divisor);
  s.Intrinsics.PixelSizeMm[1] *= float(divisor);
  s.Intrinsics.CenterPx[0] /= float(divisor);
  s.Intrinsics.CenterPx[1] /= float(divisor);
  return s;
}

} // namespace vbrdf
