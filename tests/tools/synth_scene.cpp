#include "synth_scene.h"

#include <algorithm>
#include <cmath>
#include <functional>

namespace synth {
namespace {

// Scene layout (world units): plate [-1,1]^2 at y ~ 0, objects inside it.
const float kPlateHalf = 1.0f;
const V3 kSphereCentre(-0.42f, 0.0f, 0.30f);
const float kSphereRadius = 0.32f;
const V3 kTorusCentre(0.42f, 0.0f, 0.48f);
const float kTorusMajor = 0.27f, kTorusMinor = 0.095f;
const V3 kBoxCentre(0.30f, 0.0f, -0.38f);
const float kBoxHalf[3] = {0.21f, 0.30f, 0.17f};  // half sizes x, y, z before rotation
const float kBoxYawDeg = 28.0f;
const float kSink = 0.04f;                          // objects sink into the plate: no gaps

// Undulating heightfield: slopes up to ~20 degrees, so low lights cast shadows on the plate.
float plate_height(float x, float z) {
  return 0.028f * std::sin(6.0f * x + 1.0f) * std::sin(5.0f * z) +
         0.016f * std::sin(11.0f * x - 7.0f * z + 0.5f) + 0.035f * std::cos(2.3f * x + 1.4f * z);
}

// Smooth value noise in [0,1] on an integer lattice (fixed seed: part of the scene definition).
float lattice(int i, int j, int k) {
  const uint64_t h = hash_combine(hash_combine(hash_combine(0x5EED5EEDull, uint64_t(i + 4096)),
                                               uint64_t(j + 4096)), uint64_t(k + 4096));
  return float(hash_uniform(h));
}
float value_noise(V3 p, float freq) {
  const float x = p.x * freq, y = p.y * freq, z = p.z * freq;
  const int ix = int(std::floor(x)), iy = int(std::floor(y)), iz = int(std::floor(z));
  auto fade = [](float t) { return t * t * (3 - 2 * t); };
  const float fx = fade(x - ix), fy = fade(y - iy), fz = fade(z - iz);
  float acc = 0;
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
    const float w = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * (dz ? fz : 1 - fz);
    acc += w * lattice(ix + dx, iy + dy, iz + dz);
  }
  return acc;
}

// HSV with V = 1: the largest channel is exactly 1, as the model requires.
V3 hue_color(float h, float s) {
  h = h - std::floor(h);
  const float r = clampf(std::fabs(h * 6 - 3) - 1, 0, 1);
  const float g = clampf(2 - std::fabs(h * 6 - 2), 0, 1);
  const float b = clampf(2 - std::fabs(h * 6 - 4), 0, 1);
  return V3(1 - s + s * r, 1 - s + s * g, 1 - s + s * b);
}

struct Material {
  float kd, ks, shininess;
  V3 color;
  int region;
};

Material plate_material(V3 p) {
  const float n = value_noise(p, 3.0f);
  const float stripe = std::floor((0.8f * p.x + 0.6f * p.z + 2.0f) / 0.36f);
  const int kind = int(stripe) % 4;  // matte, glossy, matte, dark
  const V3 col = hue_color(0.12f * p.x + 0.08f * p.z + 0.3f * n, 0.55f);
  if (kind == 1) {
    const float t = clampf(0.5f + 0.5f * (0.6f * p.x - 0.8f * p.z), 0, 1);  // along the stripe
    return {0.30f + 0.30f * n, 0.25f + 0.25f * t, 10.0f + 110.0f * t, col, kPlateGlossy};
  }
  if (kind == 3) return {0.05f + 0.07f * n, 0.35f, 60.0f, col, kPlateDark};
  return {0.25f + 0.70f * n, 0.0f, 1.0f, col, kPlateMatte};
}

Material sphere_material(V3 p) {
  const V3 d = normalize(p - kSphereCentre);
  const float lat = std::acos(clampf(d.y, -1, 1)) / kPi;  // 0 top .. 1 bottom
  const float lon = std::atan2(d.z, d.x);                   // -pi..pi, continuous cos below
  const float ks = 0.8f - 0.7f * smoothstep(0.1f, 0.8f, lat);
  const float alpha = 2.0f * std::pow(100.0f, 0.5f - 0.5f * std::cos(lon));
  return {0.55f, ks, alpha, hue_color(0.03f, 0.6f), kSphere};
}

Material torus_material(V3 p) {
  const V3 d = p - kTorusCentre;
  const float ang = std::atan2(d.z, d.x);
  const V3 col = hue_color(0.5f + ang / (2 * kPi), 0.5f);
  const float kd = 0.6f + 0.2f * value_noise(p, 4.0f);
  if (d.x < 0) return {kd, 0.0f, 1.0f, col, kTorusMatte};
  return {kd, 0.4f, 25.0f, col, kTorusGlossy};
}

// Box sides: one constant diffuse material per face. With their flat normals this gives areas
// of exactly constant value per photo, where a pixel must equal the model at a vertex.
Material box_material(V3 n) {
  if (n.y > 0.9f) return {0.40f, 0.70f, 150.0f, hue_color(0.33f, 0.5f), kBoxTop};
  const int face = (int(std::lround(std::atan2(n.z, n.x) / (0.5f * kPi))) + 4) % 4;
  const float kd[4] = {0.30f, 0.55f, 0.80f, 0.65f}, hue[4] = {0.58f, 0.08f, 0.75f, 0.95f};
  return {kd[face], 0.0f, 1.0f, hue_color(hue[face], 0.45f), kBoxSide};
}

// Appends vertices and triangles, tagging them with a material function.
class Builder {
 public:
  explicit Builder(Scene &s) : s_(s) {}

  uint32_t vertex(V3 p) {
    s_.pos.push_back(p);
    return uint32_t(s_.pos.size() - 1);
  }
  void tri(uint32_t a, uint32_t b, uint32_t c) { s_.idx.insert(s_.idx.end(), {a, b, c}); }

  // (nu x nv) grid of P(i, j); wrap closes a direction. The triangle normal is
  // cross(dP/di, dP/dj), so callers order the parameters to make it point outwards.
  std::vector<uint32_t> grid(int nu, int nv, bool wrap_u, bool wrap_v,
                             const std::function<V3(int, int)> &P) {
    std::vector<uint32_t> ids(size_t(nu) * nv);
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) ids[size_t(j) * nu + i] = vertex(P(i, j));
    const int cu = wrap_u ? nu : nu - 1, cv = wrap_v ? nv : nv - 1;
    for (int j = 0; j < cv; ++j)
      for (int i = 0; i < cu; ++i) {
        const uint32_t a = ids[size_t(j) * nu + i], b = ids[size_t(j) * nu + (i + 1) % nu];
        const uint32_t d = ids[size_t((j + 1) % nv) * nu + i];
        const uint32_t c = ids[size_t((j + 1) % nv) * nu + (i + 1) % nu];
        tri(a, b, c);
        tri(a, c, d);
      }
    return ids;
  }

 private:
  Scene &s_;
};

V3 rotate_y(V3 p, float deg) {
  const float c = std::cos(deg2rad(deg)), s = std::sin(deg2rad(deg));
  return V3(c * p.x + s * p.z, p.y, -s * p.x + c * p.z);
}

void add_plate(Builder &b, int n) {
  b.grid(n, n, false, false, [n](int i, int j) {
    // First parameter along z, second along x: cross(z, x) = +y, normals up.
    const float z = -kPlateHalf + 2 * kPlateHalf * i / float(n - 1);
    const float x = -kPlateHalf + 2 * kPlateHalf * j / float(n - 1);
    return V3(x, plate_height(x, z), z);
  });
}

void add_sphere(Builder &b, int rings, int segs) {
  const V3 c = kSphereCentre + V3(0, kSphereRadius - kSink, 0);
  const float r = kSphereRadius;
  // Rings 1..rings-1 (poles added as fans). First parameter longitude, second colatitude:
  // cross(d/dlon, d/dcolat) points outwards.
  auto P = [&](int i, int j) {
    const float lon = 2 * kPi * i / segs, colat = kPi * (j + 1) / rings;
    return c + V3(std::sin(colat) * std::cos(lon), std::cos(colat), std::sin(colat) * std::sin(lon)) * r;
  };
  const std::vector<uint32_t> ids = b.grid(segs, rings - 1, true, false, P);
  const uint32_t north = b.vertex(c + V3(0, r, 0)), south = b.vertex(c - V3(0, r, 0));
  const size_t last = size_t(rings - 2) * segs;
  for (int i = 0; i < segs; ++i) {
    const int k = (i + 1) % segs;
    b.tri(north, ids[k], ids[i]);
    b.tri(south, ids[last + i], ids[last + k]);
  }
}

void add_torus(Builder &b, int tube, int around) {
  const V3 c = kTorusCentre + V3(0, kTorusMinor - kSink, 0);
  // First parameter around the tube, second around the ring axis: normals point outwards.
  b.grid(tube, around, true, true, [&](int i, int j) {
    const float t = 2 * kPi * i / tube, p = 2 * kPi * j / around;
    const float rr = kTorusMajor + kTorusMinor * std::cos(t);
    return c + V3(rr * std::cos(p), kTorusMinor * std::sin(t), rr * std::sin(p));
  });
}

// Open box (no bottom: it stands on the plate). Faces are separate grids so the normals stay
// flat (hard edges), as on a real box.
void add_box(Builder &b, int m) {
  const V3 c = kBoxCentre + V3(0, kBoxHalf[1] - kSink, 0);
  const V3 h(kBoxHalf[0], kBoxHalf[1], kBoxHalf[2]);
  struct Face { V3 n, a, b; };  // outward normal, tangents with cross(a, b) = n
  const Face faces[5] = {{V3(1, 0, 0), V3(0, 1, 0), V3(0, 0, 1)},
                         {V3(-1, 0, 0), V3(0, 0, 1), V3(0, 1, 0)},
                         {V3(0, 1, 0), V3(0, 0, 1), V3(1, 0, 0)},
                         {V3(0, 0, 1), V3(1, 0, 0), V3(0, 1, 0)},
                         {V3(0, 0, -1), V3(0, 1, 0), V3(1, 0, 0)}};
  auto scale = [&](V3 v) { return V3(v.x * h.x, v.y * h.y, v.z * h.z); };
  for (const Face &f : faces) {
    b.grid(m, m, false, false, [&](int i, int j) {
      const float u = -1 + 2.0f * i / (m - 1), v = -1 + 2.0f * j / (m - 1);
      return c + rotate_y(scale(f.n + f.a * u + f.b * v), kBoxYawDeg);
    });
  }
}

void compute_normals(Scene &s) {
  s.nrm.assign(s.pos.size(), V3());
  for (size_t t = 0; t < s.idx.size(); t += 3) {
    const uint32_t a = s.idx[t], b = s.idx[t + 1], c = s.idx[t + 2];
    const V3 n = cross(s.pos[b] - s.pos[a], s.pos[c] - s.pos[a]);  // |n| = 2 * area
    s.nrm[a] = s.nrm[a] + n;
    s.nrm[b] = s.nrm[b] + n;
    s.nrm[c] = s.nrm[c] + n;
  }
  for (V3 &n : s.nrm) n = normalize(n);
}

void assign_materials(Scene &s, const std::vector<int> &component) {
  const size_t n = s.pos.size();
  s.kd.resize(n);
  s.ks.resize(n);
  s.shininess.resize(n);
  s.color.resize(n);
  s.region.resize(n);
  for (size_t v = 0; v < n; ++v) {
    Material m;
    switch (component[v]) {
      case 0: m = plate_material(s.pos[v]); break;
      case 1: m = sphere_material(s.pos[v]); break;
      case 2: m = torus_material(s.pos[v]); break;
      default: m = box_material(s.nrm[v]); break;
    }
    s.kd[v] = clampf(m.kd, 0.05f, 0.9f);
    s.ks[v] = clampf(m.ks, 0.0f, 0.8f);
    // Shininess is meaningless without a lobe; store the lower bound for diffuse-only vertices.
    s.shininess[v] = s.ks[v] > 0 ? clampf(m.shininess, 2.0f, 200.0f) : 2.0f;
    s.color[v] = m.color;
    s.region[v] = m.region;
  }
}

void flag_boundaries(Scene &s) {
  s.boundary.assign(s.pos.size(), 0);
  for (size_t t = 0; t < s.idx.size(); t += 3)
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = s.idx[t + e], b = s.idx[t + (e + 1) % 3];
      if (s.region[a] != s.region[b]) s.boundary[a] = s.boundary[b] = 1;
    }
}

} // namespace

const char *region_name(int region) {
  static const char *names[kRegionCount] = {"plate_matte", "plate_glossy", "plate_dark",
                                            "sphere", "torus_matte", "torus_glossy",
                                            "box_side", "box_top"};
  return region >= 0 && region < kRegionCount ? names[region] : "unknown";
}

Scene make_scene(int target_vertices) {
  const double V = std::max(600, target_vertices);
  // Budget: plate 40 %, sphere 25 %, torus 20 %, box 15 % of the vertices.
  const int plate_n = std::max(8, int(std::lround(std::sqrt(0.40 * V))));
  const int rings = std::max(6, int(std::lround(std::sqrt(0.25 * V / 2))));
  const int tube = std::max(6, int(std::lround(std::sqrt(0.20 * V / 3))));
  const int box_m = std::max(3, int(std::lround(std::sqrt(0.15 * V / 5))));

  Scene s;
  Builder b(s);
  std::vector<int> component;
  auto mark = [&](int id) { component.resize(s.pos.size(), id); };
  add_plate(b, plate_n);
  mark(0);
  add_sphere(b, rings, 2 * rings);
  mark(1);
  add_torus(b, tube, 3 * tube);
  mark(2);
  add_box(b, box_m);
  mark(3);

  compute_normals(s);
  assign_materials(s, component);
  flag_boundaries(s);
  s.target = V3(0.0f, 0.15f, 0.0f);
  s.frame_radius = 1.1f;
  return s;
}

} // namespace synth
