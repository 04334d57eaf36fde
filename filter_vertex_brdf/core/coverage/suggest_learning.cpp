// Next-light suggestions that learn from the photos taken so far, and the per-vertex needs they
// serve (contract in coverage/suggest_learning.h).
#include "coverage/suggest_learning.h"

#include <algorithm>
#include <cmath>

#include "base/errors.h"
#include "base/directions.h"
#include "base/vec3.h"
#include "coverage/coverage_geometry.h"
#include "coverage/coverage_settings.h"

namespace vbrdf {

using coverage_geometry::covers_unit;
using coverage_geometry::eye_direction;
using coverage_geometry::unit_normal;

LightSuggestion suggest_light_with_tolerance(const MeshView &mesh, const Shot &viewpoint, const uint8_t *visible,
                                             const float *needs, CoverageKind kind, const LightSuggestionSettings &s,
                                             float tolerance_deg, size_t *robust_covered, bool brute_force) {
  if (robust_covered) *robust_covered = 0;
  const auto suggest = brute_force ? suggest_next_light_brute_force : suggest_next_light;
  if (tolerance_deg > 0) {
    const float tol = float(radians(tolerance_deg)), ts = std::acos(s.specular_threshold), td = std::acos(s.diffuse_threshold);
    LightSuggestionSettings tight = s;
    if (kind == CoverageKind::Specular) {
      tight.specular_threshold = std::cos(std::max(0.0f, ts - tol));
    } else {
      tight.diffuse_threshold = std::cos(std::max(0.0f, td - tol));
      tight.specular_threshold = std::cos(std::min(float(kPi / 2), ts + tol));
    }
    LightSuggestion robust = suggest(mesh, viewpoint, visible, needs, kind, tight);
    if (robust.valid) {
      if (robust_covered) *robust_covered = robust.covered_vertices;
      const LightSuggestion exact = suggest(mesh, viewpoint, visible, needs, kind, s);
      robust.needing_vertices = exact.needing_vertices, robust.uncoverable_vertices = exact.uncoverable_vertices;
      robust.covered_vertices = count_covered(mesh, viewpoint, visible, needs, kind, robust.dir_world, s);
      return robust;
    }
  }
  return suggest(mesh, viewpoint, visible, needs, kind, s);
}

namespace {
// The vertices that need samples (visible, weight > 0) with, as a bitmask over the taken lights,
// those that were predicted to give them one: each such light failed them (they still need it).
struct NeedingSet {
  std::vector<uint32_t> vertex;
  std::vector<float> n, e, w;     // unit normal and eye direction (3 floats each), weight
  size_t words = 0;               // 64-bit words per vertex in `failed`
  std::vector<uint64_t> failed;   // vertex-major: failed[i * words + t / 64] bit t % 64
  std::vector<uint8_t> any_failed;
  size_t size() const { return vertex.size(); }
};

NeedingSet needing_set(const MeshView &mesh, const Shot &viewpoint, const uint8_t *visible, const float *needs,
                       CoverageKind kind, const LightSuggestionSettings &s,
                       const std::vector<std::array<float, 3>> &taken) {
  NeedingSet out;
  for (size_t v = 0; v < mesh.vertex_count; ++v)
    if (needs[v] > 0 && visible[v]) out.vertex.push_back(uint32_t(v));
  const size_t m = out.size();
  out.words = (taken.size() + 63) / 64;
  out.n.resize(3 * m), out.e.resize(3 * m), out.w.resize(m), out.any_failed.assign(m, 0);
  out.failed.assign(m * out.words, 0);
  float centre[3];
  camera_centre(viewpoint, centre);
#pragma omp parallel for schedule(static)
  for (long long ii = 0; ii < (long long)m; ++ii) {
    const size_t i = size_t(ii), v = out.vertex[i];
    float *n = &out.n[3 * i], *e = &out.e[3 * i];
    unit_normal(mesh.normals + 3 * v, n);
    eye_direction(centre, mesh.positions + 3 * v, e);
    out.w[i] = needs[v];
    for (size_t t = 0; t < taken.size(); ++t)
      if (covers_unit(kind, n, e, taken[t].data(), s)) {
        out.failed[i * out.words + t / 64] |= uint64_t(1) << (t % 64);
        out.any_failed[i] = 1;
      }
  }
  return out;
}

// Bitmask of the taken lights within the cone around `l`.
std::vector<uint64_t> near_mask(const float *l, const std::vector<std::array<float, 3>> &taken, float cone_cos,
                                size_t words) {
  std::vector<uint64_t> mask(words, 0);
  for (size_t t = 0; t < taken.size(); ++t)
    if (dot3(taken[t].data(), l) >= cone_cos) mask[t / 64] |= uint64_t(1) << (t % 64);
  return mask;
}

// Whether light `l` (with its near_mask) is expected to give needing vertex i a sample: predicted,
// and no light that failed it lies within the cone.
bool counts_for(const NeedingSet &x, size_t i, const float *l, const std::vector<uint64_t> &near, CoverageKind kind,
                const LightSuggestionSettings &s) {
  if (!covers_unit(kind, &x.n[3 * i], &x.e[3 * i], l, s)) return false;
  if (!x.any_failed[i]) return true;
  for (size_t w = 0; w < x.words; ++w)
    if (x.failed[i * x.words + w] & near[w]) return false;
  return true;
}

// Leaves out, before the first search, the failed vertices whose own best light (the normal for
// diffuse, the mirror direction for specular) lies near a light that failed them: their ideal
// light (Algorithms 1 and 3) would point there again.
void drop_failed_ideals(const NeedingSet &x, CoverageKind kind, const std::vector<std::array<float, 3>> &taken,
                        float cone_cos, std::vector<float> &work) {
#pragma omp parallel for schedule(static)
  for (long long ii = 0; ii < (long long)x.size(); ++ii) {
    const size_t i = size_t(ii);
    if (!x.any_failed[i]) continue;
    const float *n = &x.n[3 * i], *e = &x.e[3 * i];
    const float ne = dot3(n, e);
    const float mirror[3] = {2 * ne * n[0] - e[0], 2 * ne * n[1] - e[1], 2 * ne * n[2] - e[2]};
    const float *ideal = kind == CoverageKind::Diffuse ? n : mirror;
    for (size_t t = 0; t < taken.size(); ++t)
      if (((x.failed[i * x.words + t / 64] >> (t % 64)) & 1u) && dot3(taken[t].data(), ideal) >= cone_cos) {
        work[x.vertex[i]] = 0;
        break;
      }
  }
}

// Best direction of a uniform set over the placeable hemisphere, scored with counts_for (the ideal
// lights of the vertices left all failed before: look elsewhere). Invalid when nothing counts.
LightSuggestion explore_directions(const NeedingSet &x, const Shot &viewpoint, CoverageKind kind,
                                   const LightSuggestionSettings &s, const std::vector<std::array<float, 3>> &taken,
                                   float cone_cos) {
  constexpr int kDirections = 600;
  constexpr size_t kMaxScored = 8000;  // larger sets are subsampled for the score
  const size_t stride = std::max<size_t>(1, (x.size() + kMaxScored - 1) / kMaxScored);
  const float zmin = std::sin(radians(s.min_elevation_deg));
  std::vector<double> score(kDirections, 0);
  std::vector<std::array<float, 3>> dirs(kDirections), cams(kDirections);
  for (int d = 0; d < kDirections; ++d) {
    fibonacci_cap_direction(d, kDirections, zmin, cams[size_t(d)].data());
    camera_to_world_direction(viewpoint, cams[size_t(d)].data(), dirs[size_t(d)].data());
  }
#pragma omp parallel for schedule(dynamic, 8)
  for (int d = 0; d < kDirections; ++d) {
    const std::vector<uint64_t> near = near_mask(dirs[size_t(d)].data(), taken, cone_cos, x.words);
    for (size_t i = 0; i < x.size(); i += stride)
      if (counts_for(x, i, dirs[size_t(d)].data(), near, kind, s)) score[size_t(d)] += x.w[i];
  }
  const size_t best = size_t(std::max_element(score.begin(), score.end()) - score.begin());
  LightSuggestion out;
  if (!(score[best] > 0)) return out;
  out.valid = true;
  std::copy(dirs[best].begin(), dirs[best].end(), out.dir_world);
  std::copy(cams[best].begin(), cams[best].end(), out.dir_cam);
  out.azimuth_deg = degrees_f(std::atan2(out.dir_cam[1], out.dir_cam[0]));
  out.elevation_deg = degrees_f(std::asin(std::min(1.0f, out.dir_cam[2])));
  const std::vector<uint64_t> near = near_mask(out.dir_world, taken, cone_cos, x.words);
  for (size_t i = 0; i < x.size(); ++i)
    if (counts_for(x, i, out.dir_world, near, kind, s)) ++out.covered_vertices, out.covered_weight += x.w[i];
  return out;
}
} // namespace

LightSuggestion suggest_light_learning(const MeshView &mesh, const Shot &viewpoint, const uint8_t *visible,
                                       const float *needs, CoverageKind kind, const LightSuggestionSettings &s,
                                       float tolerance_deg, const std::vector<std::array<float, 3>> &taken_lights,
                                       float failure_cone_deg, size_t *robust_covered, bool *repeats_failed,
                                       bool brute_force) {
  if (repeats_failed) *repeats_failed = false;
  const auto suggest = [&](const float *weights) {
    return suggest_light_with_tolerance(mesh, viewpoint, visible, weights, kind, s, tolerance_deg, robust_covered,
                                        brute_force);
  };
  const LightSuggestion plain = suggest(needs);
  if (taken_lights.empty() || failure_cone_deg <= 0 || plain.needing_vertices == 0) return plain;
  const float cone_cos = std::cos(radians(failure_cone_deg));
  const NeedingSet x = needing_set(mesh, viewpoint, visible, needs, kind, s, taken_lights);
  if (std::find(x.any_failed.begin(), x.any_failed.end(), 1) == x.any_failed.end()) return plain;  // nothing to learn
  std::vector<float> work(needs, needs + mesh.vertex_count);
  drop_failed_ideals(x, kind, taken_lights, cone_cos, work);
  LightSuggestion sg = suggest(work.data());
  constexpr int kRounds = 4;
  for (int round = 0; sg.valid; ++round) {
    // Vertices this light would not cover after all (a photo near it failed them).
    const std::vector<uint64_t> near = near_mask(sg.dir_world, taken_lights, cone_cos, x.words);
    size_t removed = 0;
#pragma omp parallel for reduction(+ : removed) schedule(static)
    for (long long ii = 0; ii < (long long)x.size(); ++ii) {
      const size_t i = size_t(ii), v = x.vertex[i];
      if (work[v] > 0 && x.any_failed[i] && covers_unit(kind, &x.n[3 * i], &x.e[3 * i], sg.dir_world, s) &&
          !counts_for(x, i, sg.dir_world, near, kind, s))
        work[v] = 0, ++removed;
    }
    // A few broken promises do not change the best light; many do: recompute without them.
    if (removed * 10 <= sg.covered_vertices) break;
    if (round + 1 == kRounds) {
      sg = LightSuggestion();  // still mostly broken promises: look elsewhere
      break;
    }
    sg = suggest(work.data());
  }
  if (!sg.valid) {
    sg = explore_directions(x, viewpoint, kind, s, taken_lights, cone_cos);
    if (robust_covered) *robust_covered = 0;
    if (!sg.valid) {  // every light that could help failed before: the best of them again
      if (repeats_failed) *repeats_failed = plain.valid;
      return plain;
    }
  }
  sg.needing_vertices = plain.needing_vertices, sg.uncoverable_vertices = plain.uncoverable_vertices;
  return sg;
}

float prediction_failure_weight(int failures) { return failures <= 0 ? 1.0f : std::pow(0.2f, float(failures)); }

CoverageNeeds coverage_needs(const std::vector<CoverageCounts> &counts, const float *dq, const float *sq,
                             const CoverageSettings &s, const uint16_t *diffuse_failures,
                             const uint16_t *specular_failures) {
  CoverageNeeds needs;
  const size_t n = counts.size();
  needs.diffuse.assign(n, 0.0f);
  needs.specular.assign(n, 0.0f);
  for (size_t v = 0; v < n; ++v) {
    const CoverageClass c = classify_coverage(counts[v], s.min_diffuse, s.min_specular);
    if (c == kUnseen) continue;  // no light of a registered viewpoint helps
    if (c == kSeenNotDiffuse) {
      needs.diffuse[v] = diffuse_failures ? prediction_failure_weight(diffuse_failures[v]) : 1.0f;
      continue;
    }
    if (dq && dq[v] < s.poor_dq && s.poor_dq > 0) {
      needs.diffuse[v] = std::min(1.0f, std::max(0.05f, (s.poor_dq - dq[v]) / s.poor_dq));
      ++needs.poor_diffuse;
    }
    if (c == kDiffuseNoSpecular) {
      needs.specular[v] = specular_failures ? prediction_failure_weight(specular_failures[v]) : 1.0f;
    } else if (sq && sq[v] < s.poor_sq && s.poor_sq > 0) {
      needs.specular[v] = std::min(1.0f, std::max(0.05f, (s.poor_sq - sq[v]) / s.poor_sq));
      ++needs.poor_specular;
    }
  }
  return needs;
}

void prediction_failures(const MeshView &mesh, const std::vector<uint8_t> &classes, const Viewpoint &viewpoint,
                         const std::vector<LightSource> &lights, const LightSuggestionSettings &s,
                         std::vector<uint16_t> &diffuse, std::vector<uint16_t> &specular) {
  const size_t n = mesh.vertex_count;
  diffuse.assign(n, 0);
  specular.assign(n, 0);
  float centre[3];
  camera_centre(viewpoint.shot, centre);
#pragma omp parallel for schedule(dynamic, 4096)
  for (long long vi = 0; vi < (long long)n; ++vi) {
    const size_t v = size_t(vi);
    const bool need_d = classes[v] == kSeenNotDiffuse, need_s = classes[v] == kDiffuseNoSpecular;
    if (!need_d && !need_s) continue;
    float e[3], nrm[3];
    eye_direction(centre, mesh.positions + 3 * v, e);
    unit_normal(mesh.normals + 3 * v, nrm);
    int fails = 0;
    for (size_t r : viewpoint.rasters) {
      float l[3];
      light_direction_at(lights[r], mesh.positions + 3 * v, l);  // a point light's direction at the vertex
      fails += covers_unit(need_d ? CoverageKind::Diffuse : CoverageKind::Specular, nrm, e, l, s);
    }
    (need_d ? diffuse : specular)[v] = uint16_t(std::min(fails, 65535));
  }
}

} // namespace vbrdf
