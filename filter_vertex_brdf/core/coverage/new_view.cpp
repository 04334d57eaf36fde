#include "coverage/new_view.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "base/directions.h"
#include "base/vec3.h"
#include "coverage/coverage_geometry.h"

namespace vbrdf {

using coverage_geometry::covers_unit;
using coverage_geometry::eye_direction;
using coverage_geometry::unit_normal;

namespace {

// Whether some placeable light gives vertex (n, e) a sample of `kind` from `viewpoint`: the cheap
// sufficient cases first (the normal, the mirror direction), else Algorithm 1/3's search.
bool coverable(CoverageKind kind, const float *n, const float *e, const Shot &viewpoint, const float cam_z[3],
               const LightSuggestionSettings &s) {
  const float zmin = std::sin(radians(s.min_elevation_deg));
  // Largest cosine between `v` and a placeable direction (the cap z >= zmin around cam_z).
  const auto best_cos = [&](const float *v) {
    const float theta = std::acos(std::max(-1.0f, std::min(1.0f, dot3(v, cam_z)))), edge = std::acos(zmin);
    return theta <= edge ? 1.0f : std::cos(theta - edge);
  };
  const float ne = dot3(n, e);
  if (ne <= 0) return false;
  if (kind == CoverageKind::Diffuse) {
    if (dot3(n, cam_z) >= zmin && covers_unit(kind, n, e, n, s)) return true;
    if (best_cos(n) < s.diffuse_threshold) return false;  // N.L >= T_d is out of reach
  } else {
    const float mirror[3] = {2 * ne * n[0] - e[0], 2 * ne * n[1] - e[1], 2 * ne * n[2] - e[2]};
    if (dot3(mirror, cam_z) >= zmin) return true;
    if (best_cos(mirror) <= s.specular_threshold) return false;  // R.E = L.mirror > T_s is out of reach
  }
  float l[3];
  return kind == CoverageKind::Diffuse ? ideal_diffuse_light(n, e, viewpoint, s, l)
                                       : ideal_specular_light(n, e, viewpoint, s, l);
}

void camera_axis_z(const Shot &shot, float out[3]) {
  const float towards_viewer[3] = {0, 0, 1};
  camera_to_world_direction(shot, towards_viewer, out);
}

} // namespace

std::vector<uint8_t> new_view_reasons(const MeshView &mesh, const std::vector<uint8_t> &classes,
                                      const std::vector<std::vector<uint8_t>> &visible,
                                      const std::vector<Viewpoint> &viewpoints, const LightSuggestionSettings &s) {
  const size_t n = mesh.vertex_count;
  std::vector<uint8_t> reasons(n, 0);
  std::vector<std::array<float, 3>> centres(viewpoints.size()), axes(viewpoints.size());
  for (size_t i = 0; i < viewpoints.size(); ++i) {
    camera_centre(viewpoints[i].shot, centres[i].data());
    camera_axis_z(viewpoints[i].shot, axes[i].data());
  }
#pragma omp parallel for schedule(dynamic, 4096)
  for (long long vi = 0; vi < (long long)n; ++vi) {
    const size_t v = size_t(vi);
    const uint8_t c = classes[v];
    if (c == kUnseen) {
      reasons[v] = kNewViewUnseen;
      continue;
    }
    if (c == kFullyCovered) continue;
    const bool diffuse = c == kSeenNotDiffuse;
    bool ok = false;
    for (size_t i = 0; i < viewpoints.size() && !ok; ++i) {
      if (!visible[i][v]) continue;
      float e[3], nrm[3];
      eye_direction(centres[i].data(), mesh.positions + 3 * v, e);
      unit_normal(mesh.normals + 3 * v, nrm);
      ok = coverable(diffuse ? CoverageKind::Diffuse : CoverageKind::Specular, nrm, e, viewpoints[i].shot,
                     axes[i].data(), s);
    }
    if (!ok) reasons[v] = diffuse ? kNewViewDiffuse : kNewViewSpecular;
  }
  return reasons;
}

bool new_view_hint(const MeshView &mesh, const std::vector<uint32_t> &vertices, float out[3], size_t &facing) {
  constexpr int kRes = 32, kCandidates = 400;
  std::vector<std::array<double, 4>> cells(size_t(kRes) * kRes, std::array<double, 4>{{0, 0, 0, 0}});
  for (uint32_t v : vertices) {
    const float *n = mesh.normals + 3 * size_t(v);
    auto &c = cells[size_t(octahedral_cell(n, kRes))];
    c[0] += n[0], c[1] += n[1], c[2] += n[2], c[3] += 1;
  }
  std::vector<std::array<float, 4>> groups;  // mean normal, count
  for (const auto &c : cells)
    if (c[3] > 0) {
      const double l = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
      if (l > 0) groups.push_back({{float(c[0] / l), float(c[1] / l), float(c[2] / l), float(c[3])}});
    }
  double best = 0;
  for (int i = 0; i < kCandidates; ++i) {
    float d[3];
    fibonacci_sphere_direction(i, kCandidates, d);
    double score = 0;
    for (const auto &g : groups)
      if (dot3(g.data(), d) >= 0.5f) score += g[3];
    if (score > best) best = score, out[0] = d[0], out[1] = d[1], out[2] = d[2];
  }
  facing = size_t(best + 0.5);
  return best > 0;
}

} // namespace vbrdf
