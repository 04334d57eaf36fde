#include "coverage/coverage.h"
#include "base/directions.h"
#include "base/vec3.h"

#include <algorithm>
#include <cmath>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace vbrdf {

namespace {
constexpr float kDeg = kRadiansPerDegreeF;  // float maths here

// Camera axes in world coordinates (rows of the shot rotation).
Vec3 camera_axis(const Shot &shot, int row) {
  const vcg::Matrix44f r = shot.Extrinsics.Rot();
  return normalized({r[row][0], r[row][1], r[row][2]});
}

Vec3 eye_direction(const Shot &shot, const float *p) {
  float c[3];
  camera_centre(shot, c);
  return normalized({c[0] - p[0], c[1] - p[1], c[2] - p[2]});
}

bool placeable(Vec3 light_dir, Vec3 cam_z, float min_elevation_deg) {
  return dot(light_dir, cam_z) >= std::sin(min_elevation_deg * kDeg);
}

bool covers(CoverageKind kind, Vec3 n, Vec3 e, Vec3 l, const LightSuggestionSettings &s) {
  const float d = dot(n, l);
  if (d <= 0) return false;
  const float spec = dot(reflect_about(l, n), e);
  if (kind == CoverageKind::Specular) return spec > s.specular_threshold;
  return d >= s.diffuse_threshold && spec <= s.specular_threshold;
}

// Moves `l` towards the camera axis in 2-degree steps until it is placeable and still covers the
// vertex; false when no such light exists on that arc.
bool make_placeable(Vec3 &l, Vec3 n, Vec3 e, Vec3 cam_z, CoverageKind kind, const LightSuggestionSettings &s) {
  const Vec3 start = l;
  for (float t = 0; t <= 1.0001f; t += 1.0f / 45) {
    const Vec3 cand = normalized(add(scale(start, 1 - t), scale(cam_z, t)));
    if (placeable(cand, cam_z, s.min_elevation_deg) && covers(kind, n, e, cand, s)) {
      l = cand;
      return true;
    }
  }
  return false;
}

// Any unit vector perpendicular to n.
Vec3 perpendicular(Vec3 n) {
  const Vec3 a = std::fabs(n.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  return normalized(add(a, scale(n, -dot(a, n))));
}

bool ideal_light(CoverageKind kind, Vec3 n, Vec3 e, const Shot &viewpoint, const LightSuggestionSettings &s, Vec3 &l) {
  if (dot(n, e) <= 0) return false;  // back-facing: no light helps from this viewpoint
  const Vec3 cam_z = camera_axis(viewpoint, 2);
  if (kind == CoverageKind::Specular) {
    l = reflect_about(e, n);  // Algorithm 3: mirror direction, R = E, s = 1
  } else {
    // Algorithm 1: the normal, tilted towards E just enough to leave the highlight
    // (R.E = cos(phi + theta) <= T_s - margin), keeping N.L = cos(theta) >= T_d.
    const float phi = std::acos(std::min(1.0f, dot(n, e)));
    const float limit = std::acos(std::min(1.0f, s.specular_threshold)) + s.margin_deg * kDeg;
    const float theta = std::max(0.0f, limit - phi);
    Vec3 towards_e = add(e, scale(n, -dot(n, e)));
    towards_e = dot(towards_e, towards_e) > 1e-12f ? normalized(towards_e) : perpendicular(n);
    l = normalized(add(scale(n, std::cos(theta)), scale(towards_e, std::sin(theta))));
  }
  return make_placeable(l, n, e, cam_z, kind, s);
}

// Vertices sharing quantised normal and image tile (hence eye direction) behave alike.
struct Group {
  float n[3] = {0, 0, 0}, e[3] = {0, 0, 0};
  double weight = 0;
  uint32_t count = 0;
};
constexpr int kNormalRes = 64, kTiles = 8;

#ifdef _OPENMP
int max_threads() { return omp_get_max_threads(); }
int thread_index() { return omp_get_thread_num(); }
#else
int max_threads() { return 1; }
int thread_index() { return 0; }
#endif

std::vector<Group> group_vertices(const MeshView &mesh, const Shot &viewpoint, const uint8_t *visible,
                                  const float *needs) {
  const size_t cells = size_t(kNormalRes) * kNormalRes * kTiles * kTiles;
  std::vector<std::vector<Group>> partial(static_cast<size_t>(max_threads()));
  const float w = float(viewpoint.Intrinsics.ViewportPx[0]), h = float(viewpoint.Intrinsics.ViewportPx[1]);
#pragma omp parallel
  {
    std::vector<Group> &mine = partial[size_t(thread_index())];
    mine.assign(cells, Group());
#pragma omp for schedule(static)
    for (long long vi = 0; vi < (long long)mesh.vertex_count; ++vi) {
      const size_t v = size_t(vi);
      if (!visible[v] || !(needs[v] > 0)) continue;
      const float *p = mesh.positions + 3 * v;
      const Vec3 n = normalized(vec3_of(mesh.normals + 3 * v));
      const float n_cell[3] = {n.x, n.y, n.z};
      const Vec3 e = eye_direction(viewpoint, p);
      const ImagePoint ip = project_to_image(viewpoint, p);
      const int tx = std::min(kTiles - 1, std::max(0, int(ip.x / w * kTiles)));
      const int ty = std::min(kTiles - 1, std::max(0, int(ip.y / h * kTiles)));
      Group &g = mine[size_t(octahedral_cell(n_cell, kNormalRes)) * kTiles * kTiles + size_t(ty * kTiles + tx)];
      g.n[0] += n.x, g.n[1] += n.y, g.n[2] += n.z;
      g.e[0] += e.x, g.e[1] += e.y, g.e[2] += e.z;
      g.weight += needs[v];
      ++g.count;
    }
  }
  std::vector<Group> groups;
  for (size_t c = 0; c < cells; ++c) {
    Group sum;
    for (const auto &p : partial) {
      const Group &g = p[c];
      for (int k = 0; k < 3; ++k) sum.n[k] += g.n[k], sum.e[k] += g.e[k];
      sum.weight += g.weight, sum.count += g.count;
    }
    if (sum.count == 0) continue;
    store(normalized(vec3_of(sum.n)), sum.n);
    store(normalized(vec3_of(sum.e)), sum.e);
    groups.push_back(sum);
  }
  return groups;
}

LightSuggestion describe(Vec3 l, const Shot &viewpoint) {
  LightSuggestion out;
  out.valid = true;
  store(l, out.dir_world);
  world_to_camera_direction(viewpoint, out.dir_world, out.dir_cam);
  out.azimuth_deg = std::atan2(out.dir_cam[1], out.dir_cam[0]) / kDeg;
  out.elevation_deg = std::asin(std::max(-1.0f, std::min(1.0f, out.dir_cam[2]))) / kDeg;
  return out;
}

// Latitude/longitude bins in the camera frame with running-average representatives (Alg. 2).
class LightBins {
public:
  explicit LightBins(int parts) : parts_(parts), sum_(size_t(parts) * parts, Vec3{0, 0, 0}), weight_(sum_.size(), 0) {}

  void insert(Vec3 l_cam, double w) {
    const int lat = lat_index(l_cam), lon = lon_index(l_cam);
    int best = lat * parts_ + lon;
    float best_cos = -2;
    for (int dl = -1; dl <= 1; ++dl)
      for (int dm = -1; dm <= 1; ++dm) {
        const int la = lat + dl;
        if (la < 0 || la >= parts_) continue;
        const int idx = la * parts_ + (lon + dm + parts_) % parts_;
        const float c = weight_[size_t(idx)] > 0 ? dot(l_cam, normalized(sum_[size_t(idx)])) : (dl == 0 && dm == 0 ? 1.5f : -2);
        if (c > best_cos) best_cos = c, best = idx;
      }
    sum_[size_t(best)] = add(sum_[size_t(best)], scale(l_cam, float(w)));
    weight_[size_t(best)] += w;
  }

  std::vector<Vec3> representatives() const {
    std::vector<Vec3> reps;
    for (size_t i = 0; i < sum_.size(); ++i)
      if (weight_[i] > 0) reps.push_back(normalized(sum_[i]));
    return reps;
  }

private:
  int lat_index(Vec3 l) const {
    const float lat = std::asin(std::max(-1.0f, std::min(1.0f, l.z)));  // elevation
    return std::min(parts_ - 1, std::max(0, int((lat / kPiF + 0.5f) * parts_)));
  }
  int lon_index(Vec3 l) const {
    const float lon = std::atan2(l.y, l.x);
    return std::min(parts_ - 1, std::max(0, int((lon / (2 * kPiF) + 0.5f) * parts_)));
  }
  int parts_;
  std::vector<Vec3> sum_;
  std::vector<double> weight_;
};

Vec3 to_camera(const Shot &shot, Vec3 w) {
  float in[3], out[3];
  store(w, in);
  world_to_camera_direction(shot, in, out);
  return vec3_of(out);
}
Vec3 to_world(const Shot &shot, Vec3 c) {
  float in[3], out[3];
  store(c, in);
  camera_to_world_direction(shot, in, out);
  return vec3_of(out);
}
} // namespace

const char *coverage_class_name(CoverageClass c) {
  switch (c) {
  case kUnseen: return "not seen by any photo (needs another viewpoint)";
  case kSeenNotDiffuse: return "seen, not diffusely covered";
  case kDiffuseNoSpecular: return "diffusely covered, no specular sample";
  default: return "fully covered";
  }
}

std::array<uint8_t, 4> coverage_class_color(CoverageClass c) {
  switch (c) {
  case kUnseen: return {{128, 0, 128, 255}};         // purple
  case kSeenNotDiffuse: return {{40, 90, 220, 255}}; // blue (MeshLab draws its selection in red)
  case kDiffuseNoSpecular: return {{240, 200, 0, 255}}; // yellow
  default: return {{40, 180, 60, 255}};               // green
  }
}

void count_coverage_chunk(const SampleChunk &chunk, CoverageCounts *out) {
  for (uint32_t i = 0; i < chunk.vertex_count; ++i) {
    CoverageCounts c;
    for (uint32_t k = chunk.offsets[i]; k < chunk.offsets[i + 1]; ++k) {
      const Sample &s = chunk.samples[k];
      c.seen = uint16_t(std::min(65535, c.seen + 1));
      if (is_diffuse_sample(s)) c.diffuse = uint16_t(std::min(65535, c.diffuse + 1));
      if (is_specular_sample(s)) c.specular = uint16_t(std::min(65535, c.specular + 1));
    }
    out[i] = c;
  }
}

CoverageClass classify_coverage(const CoverageCounts &c, int min_diffuse, int min_specular) {
  if (c.seen == 0) return kUnseen;
  if (c.diffuse < min_diffuse) return kSeenNotDiffuse;
  if (c.specular < min_specular) return kDiffuseNoSpecular;
  return kFullyCovered;
}

bool light_is_placeable(const Shot &viewpoint, const float dir_world[3], float min_elevation_deg) {
  return placeable(normalized(vec3_of(dir_world)), camera_axis(viewpoint, 2), min_elevation_deg);
}

bool ideal_diffuse_light(const float normal[3], const float eye[3], const Shot &viewpoint,
                         const LightSuggestionSettings &s, float out[3]) {
  Vec3 l;
  if (!ideal_light(CoverageKind::Diffuse, normalized(vec3_of(normal)), normalized(vec3_of(eye)), viewpoint, s, l)) return false;
  store(l, out);
  return true;
}

bool ideal_specular_light(const float normal[3], const float eye[3], const Shot &viewpoint,
                          const LightSuggestionSettings &s, float out[3]) {
  Vec3 l;
  if (!ideal_light(CoverageKind::Specular, normalized(vec3_of(normal)), normalized(vec3_of(eye)), viewpoint, s, l)) return false;
  store(l, out);
  return true;
}

bool light_covers_diffuse(const float n[3], const float e[3], const float l[3], const LightSuggestionSettings &s) {
  return covers(CoverageKind::Diffuse, normalized(vec3_of(n)), normalized(vec3_of(e)), normalized(vec3_of(l)), s);
}
bool light_covers_specular(const float n[3], const float e[3], const float l[3], const LightSuggestionSettings &s) {
  return covers(CoverageKind::Specular, normalized(vec3_of(n)), normalized(vec3_of(e)), normalized(vec3_of(l)), s);
}

size_t count_covered(const MeshView &mesh, const Shot &viewpoint, const uint8_t *visible, const float *needs,
                     CoverageKind kind, const float dir_world[3], const LightSuggestionSettings &s) {
  const Vec3 l = normalized(vec3_of(dir_world));
  size_t n = 0;
#pragma omp parallel for reduction(+ : n) schedule(static)
  for (long long vi = 0; vi < (long long)mesh.vertex_count; ++vi) {
    const size_t v = size_t(vi);
    if (!visible[v] || !(needs[v] > 0)) continue;
    const Vec3 e = eye_direction(viewpoint, mesh.positions + 3 * v);
    if (covers(kind, normalized(vec3_of(mesh.normals + 3 * v)), e, l, s)) ++n;
  }
  return n;
}

LightSuggestion suggest_next_light(const MeshView &mesh, const Shot &viewpoint, const uint8_t *visible,
                                   const float *needs, CoverageKind kind, const LightSuggestionSettings &s) {
  const std::vector<Group> groups = group_vertices(mesh, viewpoint, visible, needs);
  LightBins bins(s.bins);
  size_t needing = 0, uncoverable = 0;
  for (const Group &g : groups) {
    needing += g.count;
    Vec3 l;
    if (ideal_light(kind, vec3_of(g.n), vec3_of(g.e), viewpoint, s, l)) bins.insert(to_camera(viewpoint, l), g.weight);
    else uncoverable += g.count;
  }
  const std::vector<Vec3> reps = bins.representatives();
  double best_score = 0;
  Vec3 best{0, 0, 0};
  for (const Vec3 &rep_cam : reps) {
    const Vec3 l = to_world(viewpoint, rep_cam);
    if (!placeable(l, camera_axis(viewpoint, 2), s.min_elevation_deg)) continue;
    double score = 0;
    for (const Group &g : groups)
      if (covers(kind, vec3_of(g.n), vec3_of(g.e), l, s)) score += g.weight;
    if (score > best_score) best_score = score, best = l;
  }
  LightSuggestion out;
  if (best_score > 0) {
    out = describe(best, viewpoint);
    out.covered_weight = best_score;
    out.covered_vertices = count_covered(mesh, viewpoint, visible, needs, kind, out.dir_world, s);
  }
  out.needing_vertices = needing;
  out.uncoverable_vertices = uncoverable;
  return out;
}

LightSuggestion suggest_next_light_brute_force(const MeshView &mesh, const Shot &viewpoint, const uint8_t *visible,
                                               const float *needs, CoverageKind kind, const LightSuggestionSettings &s) {
  std::vector<size_t> needing;
  for (size_t v = 0; v < mesh.vertex_count; ++v)
    if (visible[v] && needs[v] > 0) needing.push_back(v);
  std::vector<Vec3> normals, eyes;
  for (size_t v : needing) {
    normals.push_back(normalized(vec3_of(mesh.normals + 3 * v)));
    eyes.push_back(eye_direction(viewpoint, mesh.positions + 3 * v));
  }
  LightSuggestion out;
  double best_score = 0;
  for (size_t i = 0; i < needing.size(); ++i) {
    Vec3 l;
    if (!ideal_light(kind, normals[i], eyes[i], viewpoint, s, l)) {
      ++out.uncoverable_vertices;
      continue;
    }
    double score = 0;
    for (size_t j = 0; j < needing.size(); ++j)
      if (covers(kind, normals[j], eyes[j], l, s)) score += needs[needing[j]];
    if (score > best_score) {
      const size_t unc = out.uncoverable_vertices;
      out = describe(l, viewpoint);
      out.uncoverable_vertices = unc;
      best_score = score;
    }
  }
  out.covered_weight = best_score;
  if (out.valid) out.covered_vertices = count_covered(mesh, viewpoint, visible, needs, kind, out.dir_world, s);
  out.needing_vertices = needing.size();
  return out;
}

} // namespace vbrdf
