// Visibility back ends (visibility.h): the CPU ray-cast reference against analytic answers and a
// brute-force ray caster, and the GL depth passes (OSMesa) against the CPU reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "inputs/camera.h"
#include "test_scenes.h"
#include "base/errors.h"
#include "gl/gl_api.h"
#include "base/mesh_view.h"
#include "osmesa_context.h"
#include "visibility/camera_pass_cache.h"
#include "visibility/pass_size.h"
#include "visibility/visibility.h"
#include "visibility/visibility_gl.h"

namespace vbrdf {
namespace {

// ---------------------------------------------------------------------------------------------
// Small vector helpers and scene construction.

struct V3 {
  double x = 0, y = 0, z = 0;
};
V3 v3(const float *p) { return {p[0], p[1], p[2]}; }
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 operator*(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double norm(V3 a) { return std::sqrt(dot(a, a)); }
V3 normalized(V3 a) { return a * (1.0 / norm(a)); }

void add_vertex(MeshData &m, V3 p) {
  m.positions.insert(m.positions.end(), {float(p.x), float(p.y), float(p.z)});
  m.normals.insert(m.normals.end(), {0.f, 0.f, 0.f});
}
void add_triangle(MeshData &m, uint32_t a, uint32_t b, uint32_t c) { m.indices.insert(m.indices.end(), {a, b, c}); }
uint32_t vertex_count(const MeshData &m) { return uint32_t(m.positions.size() / 3); }

// A (nu+1) x (nv+1) vertex grid over the parallelogram o + s u + t v, s, t in [0, 1];
// `height(s, t)` displaces it along u x v.
void add_patch(MeshData &m, V3 o, V3 u, V3 v, int nu, int nv,
               const std::function<double(double, double)> &height = nullptr) {
  const uint32_t base = vertex_count(m);
  const V3 n = normalized(cross(u, v));
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      const double s = double(i) / nu, t = double(j) / nv;
      add_vertex(m, o + u * s + v * t + n * (height ? height(s, t) : 0.0));
    }
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const uint32_t a = base + uint32_t(j * (nu + 1) + i), b = a + 1, c = a + uint32_t(nu + 1), d = c + 1;
      add_triangle(m, a, b, d);
      add_triangle(m, a, d, c);
    }
}

// Closed axis-aligned box made of six subdivided faces.
void add_box(MeshData &m, V3 lo, V3 hi, int n) {
  const V3 ex{hi.x - lo.x, 0, 0}, ey{0, hi.y - lo.y, 0}, ez{0, 0, hi.z - lo.z};
  add_patch(m, lo, ey, ex, n, n);            // bottom
  add_patch(m, lo + ez, ex, ey, n, n);       // top
  add_patch(m, lo, ex, ez, n, n);            // front (y = lo)
  add_patch(m, lo + ey, ez, ex, n, n);       // back
  add_patch(m, lo, ez, ey, n, n);            // x = lo
  add_patch(m, lo + ex, ey, ez, n, n);       // x = hi
}

void add_sphere(MeshData &m, V3 c, double r, int rings, int segments) {
  const uint32_t base = vertex_count(m);
  for (int i = 0; i <= rings; ++i) {
    const double theta = M_PI * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double phi = 2 * M_PI * j / segments;
      add_vertex(m, c + V3{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)} * r);
    }
  }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const uint32_t a = base + uint32_t(i * segments + j), b = base + uint32_t(i * segments + (j + 1) % segments);
      add_triangle(m, a, a + uint32_t(segments), b);
      add_triangle(m, b, a + uint32_t(segments), b + uint32_t(segments));
    }
}

// Area-weighted vertex normals.
void compute_normals(MeshData &m) {
  std::vector<V3> acc(vertex_count(m));
  for (size_t f = 0; f + 2 < m.indices.size(); f += 3) {
    const uint32_t *t = &m.indices[f];
    const V3 a = v3(&m.positions[3 * t[0]]), b = v3(&m.positions[3 * t[1]]), c = v3(&m.positions[3 * t[2]]);
    const V3 n = cross(b - a, c - a);
    for (int k = 0; k < 3; ++k) acc[t[k]] = acc[t[k]] + n;
  }
  for (size_t v = 0; v < acc.size(); ++v) {
    const double l = norm(acc[v]);
    const V3 n = l > 0 ? acc[v] * (1 / l) : V3{0, 0, 1};
    m.normals[3 * v] = float(n.x), m.normals[3 * v + 1] = float(n.y), m.normals[3 * v + 2] = float(n.z);
  }
}

// Perspective shot at `eye` looking at `target`. cx, cy: principal point in VCG pixels (y up).
Shot look_at(V3 eye, V3 target, V3 up, float focal_px, int width, int height, float cx, float cy,
             float pixel_aspect = 1.0f) {
  const V3 back = normalized(eye - target), right = normalized(cross(up, back)), upv = cross(back, right);
  Shot s;
  s.Intrinsics.FocalMm = focal_px * 0.01f;
  s.Intrinsics.PixelSizeMm = vcg::Point2f(0.01f, 0.01f * pixel_aspect);
  s.Intrinsics.ViewportPx = vcg::Point2i(width, height);
  s.Intrinsics.CenterPx = vcg::Point2f(cx, cy);
  vcg::Matrix44f r;
  r.SetIdentity();
  const V3 rows[3] = {right, upv, back};
  for (int i = 0; i < 3; ++i) r[i][0] = float(rows[i].x), r[i][1] = float(rows[i].y), r[i][2] = float(rows[i].z);
  s.Extrinsics.SetRot(r);
  s.Extrinsics.SetTra(vcg::Point3f(float(eye.x), float(eye.y), float(eye.z)));
  return s;
}
Shot look_at(V3 eye, V3 target, V3 up, float focal_px, int width, int height) {
  return look_at(eye, target, up, focal_px, width, height, width * 0.5f, height * 0.5f);
}

V3 centre_of(const Shot &s) {
  float c[3];
  camera_centre(s, c);
  return v3(c);
}

bool in_image(const Shot &s, const float *p) {
  const ImagePoint ip = project_to_image(s, p);
  return ip.in_front && ip.x >= 0 && ip.y >= 0 && ip.x < s.Intrinsics.ViewportPx[0] &&
         ip.y < s.Intrinsics.ViewportPx[1];
}

// Segment p->q against an axis-aligned box (slab test).
bool segment_hits_box(V3 p, V3 q, V3 lo, V3 hi) {
  double t0 = 0, t1 = 1;
  const double pa[3] = {p.x, p.y, p.z}, d[3] = {q.x - p.x, q.y - p.y, q.z - p.z};
  const double l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
  for (int k = 0; k < 3; ++k) {
    if (std::fabs(d[k]) < 1e-15) {
      if (pa[k] < l[k] || pa[k] > h[k]) return false;
      continue;
    }
    double a = (l[k] - pa[k]) / d[k], b = (h[k] - pa[k]) / d[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) return false;
  }
  return true;
}

double segment_point_distance(V3 p, V3 q, V3 c) {
  const V3 d = q - p;
  const double t = std::min(1.0, std::max(0.0, dot(c - p, d) / dot(d, d)));
  return norm(p + d * t - c);
}

// Brute-force occlusion (every triangle, double-precision Moller-Trumbore), independent of vcglib.
bool brute_blocked(const MeshData &m, V3 from, V3 dir, double max_dist) {
  for (size_t f = 0; f + 2 < m.indices.size(); f += 3) {
    const V3 a = v3(&m.positions[3 * m.indices[f]]);
    const V3 e1 = v3(&m.positions[3 * m.indices[f + 1]]) - a, e2 = v3(&m.positions[3 * m.indices[f + 2]]) - a;
    const V3 pv = cross(dir, e2);
    const double det = dot(e1, pv);
    if (det == 0) continue;
    const V3 tv = from - a, qv = cross(tv, e1);
    const double u = dot(tv, pv) / det, v = dot(dir, qv) / det, t = dot(e2, qv) / det;
    if (u >= -1e-9 && v >= -1e-9 && u + v <= 1 + 1e-9 && t >= 0 && t <= max_dist) return true;
  }
  return false;
}

// ---------------------------------------------------------------------------------------------
// Expectations and comparisons.

enum class Expect { kClear, kBlocked, kAny };

// Number of vertices whose result contradicts a definite expectation; prints the first few.
int count_violations(const std::vector<uint8_t> &result, const std::vector<Expect> &expect, const MeshData &m,
                     const std::string &label) {
  int bad = 0, definite = 0;
  for (size_t v = 0; v < expect.size(); ++v) {
    if (expect[v] == Expect::kAny) continue;
    ++definite;
    const bool want = expect[v] == Expect::kClear;
    if (bool(result[v]) != want) {
      if (++bad <= 5)
        std::printf("  %s: vertex %zu (%.3f %.3f %.3f) is %s, expected %s\n", label.c_str(), v, m.positions[3 * v],
                    m.positions[3 * v + 1], m.positions[3 * v + 2], result[v] ? "clear" : "blocked",
                    want ? "clear" : "blocked");
    }
  }
  std::printf("  %s: %d definite expectations, %d violated\n", label.c_str(), definite, bad);
  return bad;
}

int count_blocked(const std::vector<uint8_t> &r, const std::vector<Expect> &expect, Expect which) {
  int n = 0;
  for (size_t v = 0; v < r.size(); ++v) n += (expect[v] == which && !r[v]);
  return n;
}

// Every output must be written with 0 or 1, or kFootprintPartial | mask for a camera pass's mixed
// footprint (the buffers
// start at 7).
void expect_all_written(const std::vector<uint8_t> &out, const char *backend, bool camera = false) {
  const long unwritten = std::count_if(out.begin(), out.end(), [&](uint8_t o) {
    return !(o <= 1 || (camera && (o & kFootprintPartial) && o <= (kFootprintPartial | kAllFootprintTexels)));
  });
  EXPECT_EQ(unwritten, 0) << backend << " left outputs unwritten";
}

std::vector<uint8_t> run_camera(VisibilityBackend &b, const MeshData &m, const Shot &s) {
  std::vector<uint8_t> out(vertex_count(m), 7);
  b.camera_pass(s, out.data());
  expect_all_written(out, b.name(), true);
  return out;
}

std::vector<uint8_t> run_point_light(VisibilityBackend &b, const MeshData &m, V3 position) {
  std::vector<uint8_t> out(vertex_count(m), 7);
  LightSource light;
  light.positional = true;
  light.position = {{float(position.x), float(position.y), float(position.z)}};
  b.light_pass(light, out.data());
  expect_all_written(out, b.name());
  return out;
}

std::vector<uint8_t> run_light(VisibilityBackend &b, const MeshData &m, V3 dir) {
  std::vector<uint8_t> out(vertex_count(m), 7);
  b.light_pass(LightSource::directional({{float(dir.x), float(dir.y), float(dir.z)}}), out.data());
  expect_all_written(out, b.name());
  return out;
}


// ---------------------------------------------------------------------------------------------
// Scenes.

// Ground z = 0 over [-1, 1]^2 (41 x 41 vertices, first in the vertex list) and a box floating above
// its centre.
const V3 kBoxLo{-0.27, -0.27, 0.3}, kBoxHi{0.27, 0.27, 0.6};
const uint32_t kGroundVertices = 41 * 41;

MeshData box_scene() {
  MeshData m;
  add_patch(m, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 40, 40);
  add_box(m, kBoxLo, kBoxHi, 8);
  compute_normals(m);
  return m;
}

Shot box_scene_camera() { return look_at({0.2, -2.5, 1.2}, {0, 0, 0.2}, {0, 0, 1}, 500, 640, 480); }

// Ground vertices: blocked when the segment towards `far_point(p)` crosses the box shrunk by a
// margin, clear when it misses the grown box. Box top vertices: clear when `top_clear`.
std::vector<Expect> box_scene_expect(const MeshData &m, const std::function<V3(V3)> &far_point, bool top_clear) {
  const double margin = 0.02;
  const V3 g{margin, margin, margin};
  std::vector<Expect> e(vertex_count(m), Expect::kAny);
  for (uint32_t v = 0; v < vertex_count(m); ++v) {
    const V3 p = v3(&m.positions[3 * v]);
    if (v < kGroundVertices) {
      const V3 q = far_point(p);
      if (segment_hits_box(p, q, kBoxLo + g, kBoxHi - g)) e[v] = Expect::kBlocked;
      else if (!segment_hits_box(p, q, kBoxLo - g, kBoxHi + g)) e[v] = Expect::kClear;
    } else if (top_clear && std::fabs(p.z - kBoxHi.z) < 1e-6) {
      e[v] = Expect::kClear;
    }
  }
  return e;
}

// Wall y = 0 over x, z in [-1, 1] (41 x 41 vertices, first), a sphere in front of it, camera on -y.
const V3 kSphereCentre{0.2, -0.6, 0.1};
const double kSphereRadius = 0.25;

MeshData wall_scene() {
  MeshData m;
  add_patch(m, {-1, 0, -1}, {2, 0, 0}, {0, 0, 2}, 40, 40);
  add_sphere(m, kSphereCentre, kSphereRadius, 24, 48);
  compute_normals(m);
  return m;
}

Shot wall_scene_camera() { return look_at({0, -3, 0}, {0, 0, 0}, {0, 0, 1}, 500, 640, 480); }

// Wall: blocked when the segment towards far_point(p) passes well inside the (tessellated) sphere,
// clear when it misses it. Sphere vertices: clear when `towards(p)` (direction to the camera /
// light) leaves the surface well above the tangent plane, blocked when it dives well below it.
// The margin (about 17 degrees) covers the tessellation and the GL pass's one-pixel slack at the
// silhouette, where the sphere's horizon is compressed into a few pixels.
std::vector<Expect> wall_scene_expect(const MeshData &m, const std::function<V3(V3)> &far_point,
                                      const std::function<V3(V3)> &towards) {
  std::vector<Expect> e(vertex_count(m), Expect::kAny);
  for (uint32_t v = 0; v < vertex_count(m); ++v) {
    const V3 p = v3(&m.positions[3 * v]);
    if (v < kGroundVertices) {
      const double d = segment_point_distance(p, far_point(p), kSphereCentre);
      if (d < 0.96 * kSphereRadius) e[v] = Expect::kBlocked;
      else if (d > 1.02 * kSphereRadius) e[v] = Expect::kClear;
    } else {
      const double c = dot(normalized(p - kSphereCentre), normalized(towards(p)));
      if (c > 0.3) e[v] = Expect::kClear;
      else if (c < -0.3) e[v] = Expect::kBlocked;
    }
  }
  return e;
}

// Bumpy heightfield (n x n vertices, jittered) with a ball floating above it: self-occlusion,
// self-shadowing and cast shadows of every kind.
MeshData dense_scene(int n, int ball_rings) {
  std::mt19937 rng(1234);
  const double spacing = 2.0 / (n - 1);  // noise of 5% of the vertex spacing
  std::uniform_real_distribution<double> jitter(-0.05 * spacing, 0.05 * spacing);
  MeshData m;
  add_patch(m, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, n - 1, n - 1, [&](double s, double t) {
    const double x = 2 * s - 1, y = 2 * t - 1;
    return 0.15 * std::sin(3 * x) * std::cos(2 * y) + 0.08 * std::sin(7 * x + 1) * std::sin(5 * y) +
           0.25 * std::exp(-((x + 0.4) * (x + 0.4) + (y - 0.3) * (y - 0.3)) / 0.02) + jitter(rng);
  });
  add_sphere(m, {0.3, 0.2, 0.55}, 0.2, ball_rings, 2 * ball_rings);
  compute_normals(m);
  return m;
}

Shot dense_scene_camera(int width = 800, int height = 600) {
  return look_at({1.6, -2.2, 1.4}, {0, 0, 0.1}, {0, 0, 1}, 0.9f * width, width, height);
}

// Light directions used on every scene: overhead, oblique, low (long shadows).
const V3 kLights[] = {{0, 0, 1}, {0.55, 0.2, 0.81}, {-0.45, -0.83, 0.33}};

// ---------------------------------------------------------------------------------------------
// GL vs CPU comparison. Every disagreement is classified: "near a boundary" when the vertex is
// within 2 pixels / texels (in the pass's raster, at a similar depth) of a vertex with the other
// CPU answer, or when the CPU answer flips under a small perturbation of the camera centre / light
// direction (an occluder's silhouette or a shadow edge passes close by); else "grazing" when
// |N.dir| < 0.2 (the CPU's offset ray skims the vertex's own polygonal surface: see
// visibility_cpu.cpp); else "unexplained". Agreement is also counted over the front-facing
// vertices (N.dir > 0), the only ones samples.cpp keeps (it rejects back-facing / attached-shadow
// vertices itself).

// Where each vertex lands in a pass's raster (pixels or texels) and at which depth.
struct Footprint {
  std::vector<float> x, y, depth;
  std::vector<uint8_t> valid;
  float depth_gap = 0;  // neighbours farther apart in depth than this are another surface
};

Footprint camera_footprint(const MeshData &m, const Shot &shot) {
  Footprint f;
  for (uint32_t v = 0; v < vertex_count(m); ++v) {
    const ImagePoint ip = project_to_image(shot, &m.positions[3 * v]);
    f.x.push_back(ip.x);
    f.y.push_back(ip.y);
    f.depth.push_back(view_depth(shot, &m.positions[3 * v]));
    f.valid.push_back(ip.in_front);
  }
  f.depth_gap = 0.02f * compute_bounds(m.view()).diagonal();
  return f;
}

Footprint light_footprint(const MeshData &m, V3 l, int map_size) {
  const V3 a = normalized(cross(l, std::fabs(l.x) < 0.6 ? V3{1, 0, 0} : V3{0, 1, 0})), b = cross(l, a);
  const float diagonal = compute_bounds(m.view()).diagonal();
  const double texel = diagonal / map_size;  // the GL map spans the bounding sphere
  Footprint f;
  for (uint32_t v = 0; v < vertex_count(m); ++v) {
    const V3 p = v3(&m.positions[3 * v]);
    f.x.push_back(float(dot(p, a) / texel));
    f.y.push_back(float(dot(p, b) / texel));
    f.depth.push_back(float(-dot(p, l)));
    f.valid.push_back(1);
  }
  f.depth_gap = 0.02f * diagonal;
  return f;
}

bool answer_changes_nearby(const Footprint &f, const std::vector<uint8_t> &cpu, size_t v) {
  for (size_t u = 0; u < cpu.size(); ++u) {
    if (!f.valid[u] || bool(cpu[u]) == bool(cpu[v])) continue;
    const float dx = f.x[u] - f.x[v], dy = f.y[u] - f.y[v];
    if (dx * dx + dy * dy <= 4.0f && std::fabs(f.depth[u] - f.depth[v]) <= f.depth_gap) return true;
  }
  return false;
}

struct Comparison {
  size_t vertices = 0, front = 0;        // all vertices, front-facing ones
  size_t total = 0, front_total = 0;     // disagreements among them
  size_t near_boundary = 0, grazing = 0, unexplained = 0;
  size_t cpu_blocked = 0;                // disagreements where the CPU says blocked (and GL clear)
  double front_fraction() const { return front ? double(front_total) / front : 0; }
};

Comparison compare(const MeshData &m, const std::vector<uint8_t> &gl, const std::vector<uint8_t> &cpu,
                   const std::vector<std::vector<uint8_t>> &perturbed, const Footprint *footprint,
                   const std::function<V3(size_t)> &dir_of) {
  Comparison b;
  b.vertices = gl.size();
  for (size_t v = 0; v < gl.size(); ++v) {
    const double facing = dot(v3(&m.normals[3 * v]), normalized(dir_of(v)));
    b.front += facing > 0;
    if (bool(gl[v]) == bool(cpu[v])) continue;
    ++b.total;
    b.front_total += facing > 0;
    b.cpu_blocked += !cpu[v];
    bool flips = false;
    for (const auto &p : perturbed) flips = flips || bool(p[v]) != bool(cpu[v]);
    if (flips || (footprint && answer_changes_nearby(*footprint, cpu, v))) ++b.near_boundary;
    else if (std::fabs(facing) < 0.2) ++b.grazing;
    else ++b.unexplained;
  }
  return b;
}

void print_comparison(const std::string &label, const Comparison &b) {
  std::printf("  %-26s %6zu vertices: %5zu disagree (%.2f%%), %4zu of %6zu front-facing (%.2f%%); "
              "%zu near a boundary, %zu grazing, %zu unexplained; %zu blocked only on the CPU\n",
              label.c_str(), b.vertices, b.total, 100.0 * b.total / b.vertices, b.front_total, b.front,
              100.0 * b.front_fraction(), b.near_boundary, b.grazing, b.unexplained, b.cpu_blocked);
}

// The GL pass agrees with the reference on >= 98% of the vertices that matter, and every
// disagreement but a handful is explained.
void expect_agreement(const std::string &label, const Comparison &b) {
  print_comparison(label, b);
  EXPECT_LE(b.front_fraction(), 0.02) << label;
  EXPECT_LE(b.unexplained, std::max<size_t>(3, b.total / 20)) << label;
}

std::vector<std::vector<uint8_t>> perturbed_camera_runs(VisibilityBackend &cpu, const MeshData &m, const Shot &s,
                                                        double pixels) {
  // Moving the centre by `pixels` (at the scene's distance) sideways moves silhouettes by as much.
  vcg::Matrix44f r;
  s.Extrinsics.Rot().ToMatrix(r);
  const V3 right{r[0][0], r[0][1], r[0][2]}, up{r[1][0], r[1][1], r[1][2]};
  const double focal_px = s.Intrinsics.FocalMm / s.Intrinsics.PixelSizeMm[0];
  const double step = pixels * norm(centre_of(s)) / focal_px;
  std::vector<std::vector<uint8_t>> runs;
  for (V3 d : {right, right * -1.0, up, up * -1.0}) {
    Shot moved = s;
    const V3 c = centre_of(s) + d * step;
    moved.Extrinsics.SetTra(vcg::Point3f(float(c.x), float(c.y), float(c.z)));
    runs.push_back(run_camera(cpu, m, moved));
  }
  return runs;
}

std::vector<std::vector<uint8_t>> perturbed_light_runs(VisibilityBackend &cpu, const MeshData &m, V3 dir,
                                                       double radians) {
  const V3 l = normalized(dir);
  const V3 a = normalized(cross(l, std::fabs(l.x) < 0.6 ? V3{1, 0, 0} : V3{0, 1, 0})), b = cross(l, a);
  std::vector<std::vector<uint8_t>> runs;
  for (V3 d : {a, a * -1.0, b, b * -1.0}) runs.push_back(run_light(cpu, m, normalized(l + d * radians)));
  return runs;
}

// `pixels`: how far (photo pixels) a silhouette may move and still explain a disagreement: 2 for
// a pass at photo resolution; a camera pass at 1/d of it (pass_size.h) moves silhouettes by up to
// a map texel more (the caller passes 2 d).
Comparison compare_camera(VisibilityBackend &gl, VisibilityBackend &cpu, const MeshData &m, const Shot &shot,
                          std::vector<uint8_t> *gl_out = nullptr, double pixels = 2.0) {
  const auto g = run_camera(gl, m, shot), c = run_camera(cpu, m, shot);
  if (gl_out) *gl_out = g;
  const V3 centre = centre_of(shot);
  Footprint f = camera_footprint(m, shot);
  for (size_t v = 0; v < f.x.size(); ++v) f.x[v] *= float(2.0 / pixels), f.y[v] *= float(2.0 / pixels);
  return compare(m, g, c, perturbed_camera_runs(cpu, m, shot, pixels), &f,
                 [&](size_t v) { return centre - v3(&m.positions[3 * v]); });
}

Comparison compare_light(VisibilityBackend &gl, VisibilityBackend &cpu, const MeshData &m, V3 dir,
                         std::vector<uint8_t> *gl_out = nullptr) {
  const V3 l = normalized(dir);
  const auto g = run_light(gl, m, l), c = run_light(cpu, m, l);
  if (gl_out) *gl_out = g;
  // 0.01 rad moves a shadow edge cast from 0.1 away by about one shadow-map texel; "nearby" is
  // within 2 texels of the map this pass used (its size varies with the light: pass_size.h).
  const Footprint f = light_footprint(m, l, gl.last_pass_sizes().shadow_map);
  return compare(m, g, c, perturbed_light_runs(cpu, m, l, 0.01), &f, [&](size_t) { return l; });
}

std::string light_label(const char *scene, V3 l) {
  char label[64];
  std::snprintf(label, sizeof label, "%s light (%.2f %.2f %.2f)", scene, l.x, l.y, l.z);
  return label;
}

// ---------------------------------------------------------------------------------------------
// CPU reference.

TEST(CpuVisibility, BoxCastsShadowStraightDownForOverheadLight) {
  const MeshData m = box_scene();
  auto cpu = make_cpu_visibility(m.view(), VisibilitySettings());
  const auto r = run_light(*cpu, m, {0, 0, 1});
  const auto e = box_scene_expect(m, [](V3 p) { return p + V3{0, 0, 10}; }, true);
  EXPECT_EQ(count_violations(r, e, m, "overhead light"), 0);
  EXPECT_GT(count_blocked(r, e, Expect::kBlocked), 100);  // the shadow is really there
  // Bottom face of the box: shadowed by its own top.
  for (uint32_t v = kGroundVertices; v < vertex_count(m); ++v) {
    const float *p = &m.positions[3 * v];
    if (std::fabs(p[2] - 0.3f) < 1e-6f && std::fabs(p[0]) < 0.25f && std::fabs(p[1]) < 0.25f) {
      EXPECT_EQ(r[v], 0) << "bottom vertex " << v;
    }
  }
}

TEST(CpuVisibility, SideLightMovesShadowAwayFromUnderTheBox) {
  const MeshData m = box_scene();
  auto cpu = make_cpu_visibility(m.view(), VisibilitySettings());
  const V3 light = normalized({1, 0, 0.5});
  const auto r = run_light(*cpu, m, light);
  const auto e = box_scene_expect(m, [&](V3 p) { return p + light * 10; }, true);
  EXPECT_EQ(count_violations(r, e, m, "side light"), 0);
  // Right under the box the ground is lit; the shadow lies on the -x side.
  for (uint32_t v = 0; v < kGroundVertices; ++v) {
    const float *p = &m.positions[3 * v];
    if (std::fabs(p[0]) < 0.25f && std::fabs(p[1]) < 0.25f) {
      EXPECT_EQ(r[v], 1) << "under the box: " << v;
    }
    if (p[0] < -0.4f && p[0] > -0.95f && std::fabs(p[1]) < 0.25f) {
      EXPECT_EQ(r[v], 0) << "in the shadow: " << v;
    }
  }
}

// A point light above the box casts a shadow larger than the box (the rays diverge from the
// light), unlike an overhead directional light: ground vertices just outside the box's own
// footprint are in shadow, and the analytic answer (segment from the vertex to the light against
// the box) holds everywhere away from the shadow's edge.
TEST(CpuVisibility, PointLightCastsAPerspectiveShadow) {
  const MeshData m = box_scene();
  auto cpu = make_cpu_visibility(m.view(), VisibilitySettings());
  const V3 light{0, 0, 2.0};
  const auto r = run_point_light(*cpu, m, light);
  const auto e = box_scene_expect(m, [&](V3) { return light; }, true);
  EXPECT_EQ(count_violations(r, e, m, "point light"), 0);
  int enlarged = 0;
  for (uint32_t v = 0; v < kGroundVertices; ++v) {
    const float *p = &m.positions[3 * v];
    // Outside the box's footprint (half-width 0.27) but inside its perspective shadow: the top
    // face's edge projects to half-width 0.27 * 2 / (2 - 0.6) = 0.386 on the ground.
    if (std::fabs(p[0]) > 0.30f && std::fabs(p[0]) < 0.37f && std::fabs(p[1]) < 0.2f) {
      EXPECT_EQ(r[v], 0) << "ground vertex " << v << " under the enlarged shadow";
      ++enlarged;
    }
  }
  EXPECT_GT(enlarged, 4);
  // A low light to the side: the analytic answer (segments to the light, not parallel rays).
  const auto side = run_point_light(*cpu, m, V3{2.0, 0, 0.8});
  const auto side_expect = box_scene_expect(m, [&](V3) { return V3{2.0, 0, 0.8}; }, false);
  EXPECT_EQ(count_violations(side, side_expect, m, "side point light"), 0);
}

TEST(CpuVisibility, PointLightMatchesBruteForceRayCasting) {
  const MeshData m = dense_scene(50, 12);
  const VisibilitySettings settings;
  auto cpu = make_cpu_visibility(m.view(), settings);
  const double tol = settings.depth_tolerance * compute_bounds(m.view()).diagonal();
  for (V3 light : {V3{0.2, -0.3, 2.2}, V3{-2.4, 0.4, 0.9}, V3{1.7, 1.7, 1.0}}) {
    const auto lit = run_point_light(*cpu, m, light);
    int diff = 0, blocked = 0;
    for (uint32_t v = 0; v < vertex_count(m); ++v) {
      const V3 p = v3(&m.positions[3 * v]);
      const V3 d = normalized(light - p);
      const bool clear = !brute_blocked(m, p + d * tol, d, norm(light - p) - tol);
      diff += clear != bool(lit[v]);
      blocked += !clear;
    }
    std::printf("  point light (%.2f %.2f %.2f): %d blocked, %d differ from brute force\n", light.x, light.y, light.z,
                blocked, diff);
    EXPECT_EQ(diff, 0);
    EXPECT_GT(blocked, 10);
  }
}

TEST(CpuVisibility, BoxHidesTheGroundBehindIt) {
  const MeshData m = box_scene();
  const Shot shot = box_scene_camera();
  auto cpu = make_cpu_visibility(m.view(), VisibilitySettings());
  const auto r = run_camera(*cpu, m, shot);
  const V3 c = centre_of(shot);
  auto e = box_scene_expect(m, [&](V3) { return c; }, true);
  for (uint32_t v = 0; v < vertex_count(m); ++v)
    if (!in_image(shot, &m.positions[3 * v])) e[v] = Expect::kClear;  // contract: outside the image = 1
  EXPECT_EQ(count_violations(r, e, m, "box camera"), 0);
  EXPECT_GT(count_blocked(r, e, Expect::kBlocked), 50);
}

TEST(CpuVisibility, SphereHidesTheWallAndItsOwnBack) {
  const MeshData m = wall_scene();
  const Shot shot = wall_scene_camera();
  auto cpu = make_cpu_visibility(m.view(), VisibilitySettings());
  const auto r = run_camera(*cpu, m, shot);
  const V3 c = centre_of(shot);
  const auto e = wall_scene_expect(m, [&](V3) { return c; }, [&](V3 p) { return c - p; });
  EXPECT_EQ(count_violations(r, e, m, "wall camera"), 0);
  EXPECT_GT(count_blocked(r, e, Expect::kBlocked), 100);
}

TEST(CpuVisibility, SphereCastsShadowOnTheWall) {
  const MeshData m = wall_scene();
  auto cpu = make_cpu_visibility(m.view(), VisibilitySettings());
  const V3 light = normalized({0.3, -1, 0.4});
  const auto r = run_light(*cpu, m, light);
  const auto e = wall_scene_expect(m, [&](V3 p) { return p + light * 10; }, [&](V3) { return light; });
  EXPECT_EQ(count_violations(r, e, m, "wall light"), 0);
  EXPECT_GT(count_blocked(r, e, Expect::kBlocked), 30);
}

TEST(CpuVisibility, OutsideTheImageAndBehindTheCameraIsClear) {
  const MeshData m = wall_scene();
  auto cpu = make_cpu_visibility(m.view(), VisibilitySettings());
  // Looking away from the scene: everything is behind the camera.
  const auto away = run_camera(*cpu, m, look_at({0, -3, 0}, {0, -6, 0}, {0, 0, 1}, 500, 640, 480));
  EXPECT_EQ(std::count(away.begin(), away.end(), 1), long(away.size()));
  // Narrow view of an unoccluded bit of the wall: the wall the sphere hides lies outside the image.
  const auto narrow = run_camera(*cpu, m, look_at({0, -3, 0}, {0.6, 0, 0.6}, {0, 0, 1}, 5000, 64, 48));
  for (uint32_t v = 0; v < kGroundVertices; ++v) EXPECT_EQ(narrow[v], 1);
}

TEST(CpuVisibility, MatchesBruteForceRayCasting) {
  const MeshData m = dense_scene(50, 12);
  const VisibilitySettings settings;
  auto cpu = make_cpu_visibility(m.view(), settings);
  const double tol = settings.depth_tolerance * compute_bounds(m.view()).diagonal();
  const Shot shot = dense_scene_camera(320, 240);
  const V3 c = centre_of(shot);
  const auto cam = run_camera(*cpu, m, shot);
  int cam_diff = 0, cam_blocked = 0;
  for (uint32_t v = 0; v < vertex_count(m); ++v) {
    const V3 p = v3(&m.positions[3 * v]);
    const V3 d = normalized(c - p);
    const bool clear = !in_image(shot, &m.positions[3 * v]) || !brute_blocked(m, p + d * tol, d, norm(c - p) - tol);
    cam_diff += clear != bool(cam[v]);
    cam_blocked += !clear;
  }
  std::printf("  camera: %d of %u vertices blocked, %d differ from brute force\n", cam_blocked, vertex_count(m),
              cam_diff);
  EXPECT_EQ(cam_diff, 0);
  EXPECT_GT(cam_blocked, 50);
  for (V3 light : kLights) {
    const V3 l = normalized(light);
    const auto lit = run_light(*cpu, m, l);
    int diff = 0, blocked = 0;
    for (uint32_t v = 0; v < vertex_count(m); ++v) {
      const bool clear = !brute_blocked(m, v3(&m.positions[3 * v]) + l * tol, l, 1e9);
      diff += clear != bool(lit[v]);
      blocked += !clear;
    }
    std::printf("  light (%.2f %.2f %.2f): %d blocked, %d differ from brute force\n", l.x, l.y, l.z, blocked, diff);
    EXPECT_EQ(diff, 0);
  }
}

// ---------------------------------------------------------------------------------------------
// GL passes (OSMesa).

class GlVisibilityTest : public ::testing::Test {
protected:
  void SetUp() override {
    std::string why;
    context_ = test::OsMesaContext::try_create(&why);
    if (!context_) GTEST_SKIP() << "no OSMesa OpenGL context: " << why;
  }
  std::unique_ptr<VisibilityBackend> gl(const MeshData &m, VisibilitySettings s = VisibilitySettings()) {
    return make_gl_visibility(m.view(), context_->get_proc_address(), s);
  }
  std::unique_ptr<test::OsMesaContext> context_;
};

TEST_F(GlVisibilityTest, ContextIsCoreProfile33OrNewer) {
  std::printf("  OSMesa: %s on %s\n", context_->version().c_str(), context_->renderer().c_str());
  EXPECT_GE(context_->major_version() * 10 + context_->minor_version(), 33);
  const GlApi api = load_gl_api(context_->get_proc_address());
  EXPECT_EQ(api.has_compute, api.version_at_least(4, 3));
}

TEST_F(GlVisibilityTest, MatchesExactAnswersAndCpuOnConstructedScenes) {
  const MeshData box = box_scene(), wall = wall_scene();
  const Shot box_shot = box_scene_camera(), wall_shot = wall_scene_camera();
  const V3 overhead{0, 0, 1}, side = normalized({1, 0, 0.5}), wall_light = normalized({0.3, -1, 0.4});
  std::vector<uint8_t> g;
  {
    auto gl_box = gl(box), cpu = make_cpu_visibility(box.view(), VisibilitySettings());
    expect_agreement("box overhead light", compare_light(*gl_box, *cpu, box, overhead, &g));
    EXPECT_EQ(count_violations(g, box_scene_expect(box, [](V3 p) { return p + V3{0, 0, 10}; }, true), box,
                               "box overhead light (GL)"), 0);
    expect_agreement("box side light", compare_light(*gl_box, *cpu, box, side, &g));
    EXPECT_EQ(count_violations(g, box_scene_expect(box, [&](V3 p) { return p + side * 10; }, true), box,
                               "box side light (GL)"), 0);
    expect_agreement("box camera", compare_camera(*gl_box, *cpu, box, box_shot, &g));
    const V3 cc = centre_of(box_shot);
    auto e = box_scene_expect(box, [&](V3) { return cc; }, true);
    for (uint32_t v = 0; v < vertex_count(box); ++v)
      if (!in_image(box_shot, &box.positions[3 * v])) e[v] = Expect::kClear;
    EXPECT_EQ(count_violations(g, e, box, "box camera (GL)"), 0);
  }
  {
    auto gl_wall = gl(wall), cpu = make_cpu_visibility(wall.view(), VisibilitySettings());
    const V3 cc = centre_of(wall_shot);
    expect_agreement("wall camera", compare_camera(*gl_wall, *cpu, wall, wall_shot, &g));
    EXPECT_EQ(count_violations(g, wall_scene_expect(wall, [&](V3) { return cc; }, [&](V3 p) { return cc - p; }),
                               wall, "wall camera (GL)"), 0);
    expect_agreement("wall light", compare_light(*gl_wall, *cpu, wall, wall_light, &g));
    EXPECT_EQ(count_violations(g, wall_scene_expect(wall, [&](V3 p) { return p + wall_light * 10; },
                                                    [&](V3) { return wall_light; }),
                               wall, "wall light (GL)"), 0);
  }
}

TEST_F(GlVisibilityTest, AgreesWithCpuOnDenseBumpyMesh) {
  const MeshData m = dense_scene(160, 24);
  auto g = gl(m);
  auto cpu = make_cpu_visibility(m.view(), VisibilitySettings());
  std::vector<uint8_t> cam;
  expect_agreement("dense camera 800x600", compare_camera(*g, *cpu, m, dense_scene_camera(), &cam));
  EXPECT_GT(std::count(cam.begin(), cam.end(), 0), long(vertex_count(m) / 50));  // real occlusion happens
  for (V3 light : kLights) {
    std::vector<uint8_t> lit;
    expect_agreement(light_label("dense", normalized(light)), compare_light(*g, *cpu, m, light, &lit));
    EXPECT_GT(std::count(lit.begin(), lit.end(), 0), 10);
  }
}

// Georeferenced meshes: coordinates far from the origin (the positions themselves are then
// quantised to ~0.002 here, a third of the tolerance) must not cost the GL passes more precision.
// The GL pass's perspective shadow map from a point light (light_view.h) against the CPU rays
// towards the light: the analytic box answer, and agreement on a dense bumpy mesh except within a
// shadow-map texel of shadow edges (a few vertices).
TEST_F(GlVisibilityTest, PointLightShadowsAgreeWithCpu) {
  const MeshData box = box_scene();
  auto gl_box = gl(box);
  const V3 over{0, 0, 2.0};
  EXPECT_EQ(count_violations(run_point_light(*gl_box, box, over), box_scene_expect(box, [&](V3) { return over; }, true),
                             box, "point light (GL)"),
            0);
  const MeshData m = dense_scene(160, 24);
  auto g = gl(m);
  auto cpu = make_cpu_visibility(m.view(), VisibilitySettings());
  for (V3 light : {V3{0.2, -0.3, 2.2}, V3{-2.4, 0.4, 0.9}, V3{1.7, 1.7, 1.0}}) {
    const auto a = run_point_light(*g, m, light), b = run_point_light(*cpu, m, light);
    // As for directional lights (perturbed_light_runs): a disagreement is explained when the CPU
    // gives the GL answer with the light turned by 0.01 rad about the object's centre (about a
    // shadow-map texel at the shadow's distance from its caster).
    const V3 axis = normalized(light), side1 = normalized(cross(axis, std::fabs(axis.z) < 0.9 ? V3{0, 0, 1} : V3{1, 0, 0}));
    const V3 side2 = cross(axis, side1);
    const double step = 0.01 * norm(light);
    std::vector<std::vector<uint8_t>> moved;
    for (V3 d : {side1, side1 * -1.0, side2, side2 * -1.0}) moved.push_back(run_point_light(*cpu, m, light + d * step));
    size_t diff = 0, facing = 0, facing_diff = 0, unexplained = 0, blocked = 0;
    for (size_t v = 0; v < a.size(); ++v) {
      blocked += b[v] == 0;
      const V3 p = v3(&m.positions[3 * v]), n = v3(&m.normals[3 * v]);
      const bool faces = dot(n, light - p) > 0;
      facing += faces;
      if (a[v] == b[v]) continue;
      ++diff;
      if (!faces) continue;  // facing away: in attached shadow whatever the map says (samples.h)
      ++facing_diff;
      unexplained += std::none_of(moved.begin(), moved.end(), [&](const std::vector<uint8_t> &r) { return r[v] == a[v]; });
    }
    std::printf("  point light (%.2f %.2f %.2f): %zu of %zu blocked (CPU); GL vs CPU: %zu differ, %zu of %zu facing "
                "the light, of them %zu not explained by turning the light by 0.01 rad\n",
                light.x, light.y, light.z, blocked, a.size(), diff, facing_diff, facing, unexplained);
    // The reference: the (long-tested) orthographic pass for a directional light from the same
    // direction, scored the same way. Grazing lights disagree more in both (depth slopes within a
    // texel); the perspective map must not add to it.
    size_t directional_unexplained = 0;
    {
      const V3 dl = normalized(light - V3{0, 0, 0.2});
      const auto ga = run_light(*g, m, dl), cb = run_light(*cpu, m, dl);
      size_t fd = 0, un = 0;
      std::vector<std::vector<uint8_t>> mv;
      for (V3 d : {side1, side1 * -1.0, side2, side2 * -1.0}) mv.push_back(run_light(*cpu, m, normalized(dl + d * 0.01)));
      for (size_t v = 0; v < ga.size(); ++v) {
        const V3 n = v3(&m.normals[3 * v]);
        if (ga[v] == cb[v] || dot(n, dl) <= 0) continue;
        ++fd;
        un += std::none_of(mv.begin(), mv.end(), [&](const std::vector<uint8_t> &r) { return r[v] == ga[v]; });
      }
      std::printf("    directional light from there: %zu facing differ, %zu not explained\n", fd, un);
      directional_unexplained = un;
    }
    EXPECT_GT(blocked, 50u);
    EXPECT_LE(facing_diff, facing / 50) << "more than 2 % of the vertices facing the light disagree";
    EXPECT_LE(unexplained, 3 + directional_unexplained * 5 / 4);
  }
  // A light inside the mesh's bounding sphere cannot be one perspective map: refused by name.
  std::vector<uint8_t> out(vertex_count(m));
  LightSource inside;
  inside.positional = true;
  inside.position = {{0, 0, 0.1f}};
  EXPECT_THROW(g->light_pass(inside, out.data()), InputError);
}

TEST_F(GlVisibilityTest, AgreesWithCpuFarFromTheOrigin) {
  const V3 offset{20000, -30000, 5000};
  MeshData m = wall_scene();
  for (size_t i = 0; i < m.positions.size(); i += 3) {
    m.positions[i] += float(offset.x), m.positions[i + 1] += float(offset.y), m.positions[i + 2] += float(offset.z);
  }
  auto g = gl(m), cpu = make_cpu_visibility(m.view(), VisibilitySettings());
  const Shot shot = look_at(V3{0, -3, 0} + offset, offset, {0, 0, 1}, 500, 640, 480);
  std::vector<uint8_t> cam, lit;
  expect_agreement("far wall camera", compare_camera(*g, *cpu, m, shot, &cam));
  expect_agreement("far wall light", compare_light(*g, *cpu, m, normalized({0.3, -1, 0.4}), &lit));
  EXPECT_GT(std::count(cam.begin(), cam.end(), 0), 300);
  EXPECT_GT(std::count(lit.begin(), lit.end(), 0), 300);
}

// The camera pass must put every vertex on the depth-map texel GL rasterised it to: a square
// occluder parallel to the image plane, in front of a dense wall, must hide exactly the wall
// vertices whose 2x2 texel footprint (from project_to_image) lies inside the square's projection.
TEST_F(GlVisibilityTest, CameraPassPixelMappingMatchesProjectToImage) {
  const int width = 320, height = 240;
  // Off-centre principal point and non-square pixels catch swapped or flipped axes.
  const Shot shot = look_at({0, -3, 0}, {0, 0, 0}, {0, 0, 1}, 500, width, height, 141.3f, 133.7f, 1.25f);
  const V3 c = centre_of(shot);
  const V3 occ{0.31, -0.4, 0.22};  // occluder centre, far from the image centre
  const V3 on_wall = c + (occ - c) * (3.0 / 2.6);
  MeshData m;
  const double wall_half = 0.09, occ_half = 0.035;
  add_patch(m, on_wall + V3{-wall_half, 0, -wall_half}, {2 * wall_half, 0, 0}, {0, 0, 2 * wall_half}, 150, 150);
  const uint32_t wall_vertices = vertex_count(m);
  add_patch(m, occ + V3{-occ_half, 0, -occ_half}, {2 * occ_half, 0, 0}, {0, 0, 2 * occ_half}, 1, 1);
  compute_normals(m);

  // Projected square (image pixels): axis-aligned since it is parallel to the image plane.
  float x0 = 1e9f, x1 = -1e9f, y0 = 1e9f, y1 = -1e9f;
  for (uint32_t v = wall_vertices; v < vertex_count(m); ++v) {
    const ImagePoint ip = project_to_image(shot, &m.positions[3 * v]);
    x0 = std::min(x0, ip.x), x1 = std::max(x1, ip.x), y0 = std::min(y0, ip.y), y1 = std::max(y1, ip.y);
  }
  std::printf("  occluder covers image x [%.2f, %.2f], y [%.2f, %.2f]\n", x0, x1, y0, y1);
  ASSERT_GT(x0, 0);
  ASSERT_LT(x1, width);
  ASSERT_GT(y0, 0);
  ASSERT_LT(y1, height);

  auto g = gl(m);
  const auto r = run_camera(*g, m, shot);
  // Texel (i, j) in image pixels (row j from the top) is covered when its centre is in the square.
  const float eps = 0.02f;
  auto ambiguous = [&](float centre, float lo, float hi) {
    return std::fabs(centre - lo) < eps || std::fabs(centre - hi) < eps;
  };
  int checked = 0, expected_hidden = 0, wrong = 0;
  for (uint32_t v = 0; v < wall_vertices; ++v) {
    const ImagePoint ip = project_to_image(shot, &m.positions[3 * v]);
    const float fx = ip.x - 0.5f, fy = ip.y - 0.5f;
    if (std::fabs(fx - std::round(fx)) < eps || std::fabs(fy - std::round(fy)) < eps) continue;  // on a texel edge
    const float cx[2] = {std::floor(fx) + 0.5f, std::floor(fx) + 1.5f};
    const float cy[2] = {std::floor(fy) + 0.5f, std::floor(fy) + 1.5f};
    bool all_covered = true, skip = false;
    for (float tx : cx)
      for (float ty : cy) {
        skip = skip || ambiguous(tx, x0, x1) || ambiguous(ty, y0, y1);
        all_covered = all_covered && tx > x0 && tx < x1 && ty > y0 && ty < y1;
      }
    if (skip) continue;
    ++checked;
    expected_hidden += all_covered;
    if (bool(r[v]) == all_covered && ++wrong <= 5)
      std::printf("  wall vertex at image (%.2f, %.2f): %s, expected %s\n", ip.x, ip.y, r[v] ? "clear" : "hidden",
                  all_covered ? "hidden" : "clear");
  }
  std::printf("  %d wall vertices checked, %d expected hidden, %d wrong\n", checked, expected_hidden, wrong);
  EXPECT_GT(expected_hidden, 200);
  EXPECT_EQ(wrong, 0);
}

TEST_F(GlVisibilityTest, LeavesTheHostGlStateAsItFoundIt) {
  const MeshData m = box_scene();
  const Shot shot = box_scene_camera();
  auto g = gl(m);
  const auto cam_ref = run_camera(*g, m, shot), lit_ref = run_light(*g, m, {0, 0, 1});

  // Host state that would spoil the passes if they inherited it.
  const GlApi api = load_gl_api(context_->get_proc_address());
  ASSERT_EQ(api.GetError(), GLenum(GL_NO_ERROR));
  {
    GlStateGuard guard(api);  // its queries must all be legal in a core context
    EXPECT_EQ(api.GetError(), GLenum(GL_NO_ERROR));
  }
  EXPECT_EQ(api.GetError(), GLenum(GL_NO_ERROR));
  api.Viewport(1, 2, 3, 4);
  api.Enable(GL_CULL_FACE);
  api.Enable(GL_BLEND);
  api.Enable(GL_SCISSOR_TEST);
  api.Enable(GL_CLIP_DISTANCE0);
  api.PixelStorei(GL_PACK_ALIGNMENT, 1);
  api.DepthFunc(GL_GREATER);
  api.DepthMask(GL_FALSE);
  api.ColorMask(GL_FALSE, GL_TRUE, GL_TRUE, GL_TRUE);
  api.ClampColor(GL_CLAMP_READ_COLOR, GL_TRUE);  // would clamp read-back depths to [0, 1]
  GLuint unpack = 0;  // a host's bound unpack buffer would feed the render targets' allocation
  api.GenBuffers(1, &unpack);
  api.BindBuffer(GL_PIXEL_UNPACK_BUFFER, unpack);
  auto fresh = gl(m);  // allocates its targets with the host state above
  EXPECT_EQ(run_camera(*fresh, m, shot), cam_ref);
  EXPECT_EQ(run_light(*fresh, m, {0, 0, 1}), lit_ref);
  fresh.reset();
  EXPECT_EQ(run_camera(*g, m, shot), cam_ref);
  EXPECT_EQ(run_light(*g, m, {0, 0, 1}), lit_ref);

  GLint viewport[4], fbo = -1, program = -1, vao = -1, align = 0, func = 0, clamp = 0;
  GLboolean depth_mask = GL_TRUE, color_mask[4] = {GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE};
  api.GetIntegerv(GL_VIEWPORT, viewport);
  api.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &fbo);
  api.GetIntegerv(GL_CURRENT_PROGRAM, &program);
  api.GetIntegerv(GL_VERTEX_ARRAY_BINDING, &vao);
  api.GetIntegerv(GL_PACK_ALIGNMENT, &align);
  api.GetIntegerv(GL_DEPTH_FUNC, &func);
  api.GetIntegerv(GL_CLAMP_READ_COLOR, &clamp);
  api.GetBooleanv(GL_DEPTH_WRITEMASK, &depth_mask);
  api.GetBooleanv(GL_COLOR_WRITEMASK, color_mask);
  EXPECT_EQ(viewport[0], 1);
  EXPECT_EQ(viewport[3], 4);
  EXPECT_EQ(fbo, 0);
  EXPECT_EQ(program, 0);
  EXPECT_EQ(vao, 0);
  EXPECT_EQ(align, 1);
  EXPECT_EQ(func, GL_GREATER);
  EXPECT_EQ(clamp, GL_TRUE);
  GLint unpack_binding = 0;
  api.GetIntegerv(GL_PIXEL_UNPACK_BUFFER_BINDING, &unpack_binding);
  EXPECT_EQ(GLuint(unpack_binding), unpack);
  EXPECT_EQ(depth_mask, GL_FALSE);
  EXPECT_EQ(color_mask[0], GL_FALSE);
  for (GLenum cap : {GL_CULL_FACE, GL_BLEND, GL_SCISSOR_TEST, GL_CLIP_DISTANCE0}) EXPECT_TRUE(api.IsEnabled(cap));
  EXPECT_FALSE(api.IsEnabled(GL_DEPTH_TEST));
  EXPECT_EQ(api.GetError(), GLenum(GL_NO_ERROR));
  g.reset();
  EXPECT_EQ(api.GetError(), GLenum(GL_NO_ERROR));
  api.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
  api.DeleteBuffers(1, &unpack);
}

// MeshLab gives filters a compatibility context, where fixed-function state such as the alpha test
// still applies to shader output.
TEST(GlVisibilityCompatibility, PassesIgnoreFixedFunctionStateAndRestoreIt) {
  std::string why;
  auto context = test::OsMesaContext::try_create(&why, test::OsMesaContext::Profile::kCompatibility);
  if (!context) GTEST_SKIP() << "no OSMesa compatibility context: " << why;
  std::printf("  OSMesa: %s\n", context->version().c_str());
  const GlApi api = load_gl_api(context->get_proc_address());
  ASSERT_TRUE(api.compatibility_profile);
  const GLenum alpha_test = 0x0BC0, never = GL_NEVER;
  using AlphaFunc = void (*)(GLenum, GLfloat);
  const auto alpha_func = reinterpret_cast<AlphaFunc>(context->get_proc_address()("glAlphaFunc"));
  ASSERT_NE(alpha_func, nullptr);
  alpha_func(never, 0.0f);  // discards every fragment while enabled
  api.Enable(alpha_test);
  {
    GlStateGuard guard(api);  // its queries must all be legal in a compatibility context
    EXPECT_EQ(api.GetError(), GLenum(GL_NO_ERROR));
  }

  const MeshData m = box_scene();
  auto g = make_gl_visibility(m.view(), context->get_proc_address(), VisibilitySettings());
  const auto r = run_light(*g, m, {0, 0, 1});
  EXPECT_EQ(count_violations(r, box_scene_expect(m, [](V3 p) { return p + V3{0, 0, 10}; }, true), m,
                             "compatibility context, overhead light"), 0);
  EXPECT_GT(std::count(r.begin(), r.end(), 0), 100);
  EXPECT_TRUE(api.IsEnabled(alpha_test));
  EXPECT_EQ(api.GetError(), GLenum(GL_NO_ERROR));
}

// Degenerate extents (a flat patch, one triangle): nothing can occlude anything.
TEST_F(GlVisibilityTest, FlatMeshesAreClearInBothBackEnds) {
  MeshData flat;
  add_patch(flat, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 30, 30);
  MeshData single;
  add_patch(single, {0.2, 0.1, 0}, {0.3, 0, 0}, {0, 0.2, 0}, 1, 1);
  single.indices.resize(3);
  for (MeshData *m : {&flat, &single}) {
    compute_normals(*m);
    const Shot shot = look_at({0.3, -2, 1.5}, {0, 0, 0}, {0, 0, 1}, 500, 320, 240);
    auto cpu = make_cpu_visibility(m->view(), VisibilitySettings());
    auto g = gl(*m);
    for (VisibilityBackend *b : {cpu.get(), g.get()}) {
      for (V3 light : kLights) {
        const auto r = run_light(*b, *m, light);
        EXPECT_EQ(std::count(r.begin(), r.end(), 1), long(r.size())) << b->name();
      }
      const auto r = run_camera(*b, *m, shot);
      EXPECT_EQ(std::count(r.begin(), r.end(), 0), 0) << b->name();
    }
  }
}

TEST_F(GlVisibilityTest, ReportsTheFirstMissingEntryPointByName) {
  const GetProcAddressFn real = context_->get_proc_address();
  const GetProcAddressFn no_draw = [&](const char *name) -> void * {
    return std::string(name) == "glDrawElements" ? nullptr : real(name);
  };
  try {
    make_gl_visibility(box_scene().view(), no_draw, VisibilitySettings());
    FAIL() << "no error for a missing entry point";
  } catch (const ProcessingError &e) {
    EXPECT_NE(std::string(e.what()).find("glDrawElements"), std::string::npos) << e.what();
  }
  const GetProcAddressFn no_dispatch = [&](const char *name) -> void * {
    return std::string(name) == "glDispatchCompute" ? nullptr : real(name);
  };
  const GlApi api = load_gl_api(no_dispatch);  // optional: loads, without compute
  EXPECT_FALSE(api.has_compute);
  try {
    require_compute(api, "the fit");
    FAIL() << "require_compute accepted a table without glDispatchCompute";
  } catch (const ProcessingError &e) {
    EXPECT_NE(std::string(e.what()).find("the fit"), std::string::npos) << e.what();
  }
}

TEST_F(GlVisibilityTest, ShaderErrorsCarryTheInfoLog) {
  const GlApi api = load_gl_api(context_->get_proc_address());
  try {
    compile_shader(api, GL_FRAGMENT_SHADER, "#version 330 core\nvoid main() { undeclared_thing = 1.0; }\n",
                   "a broken test shader");
    FAIL() << "a broken shader compiled";
  } catch (const ProcessingError &e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("a broken test shader"), std::string::npos) << what;
    EXPECT_NE(what.find("undeclared_thing"), std::string::npos) << what;  // the compiler's log
  }
  EXPECT_EQ(api.GetError(), GLenum(GL_NO_ERROR));
}

TEST_F(GlVisibilityTest, RejectsRenderTargetsLargerThanTheContextAllows) {
  const MeshData m = box_scene();
  VisibilitySettings huge;
  huge.shadow_map_size = 1 << 20;
  EXPECT_THROW(gl(m, huge), ProcessingError);
  auto g = gl(m);
  EXPECT_THROW(run_camera(*g, m, look_at({0.2, -2.5, 1.2}, {0, 0, 0.2}, {0, 0, 1}, 500, 1 << 20, 16)),
               ProcessingError);
  // Still usable afterwards.
  const auto r = run_light(*g, m, {0, 0, 1});
  EXPECT_GT(std::count(r.begin(), r.end(), 0), 100);
}

// ~100k vertices: the camera pass at 1024x768 and the light pass at 2048^2 agree with the CPU
// reference on the front-facing vertices (second call of each: the render targets exist). Their
// time is a benchmark figure, not a test on a shared machine: bench_gather --passes.
TEST_F(GlVisibilityTest, PassesOn100kVerticesAgreeWithTheCpu) {
  const MeshData m = dense_scene(310, 32);
  const Shot shot = dense_scene_camera(1024, 768);
  const V3 light = normalized(kLights[1]);
  auto g = gl(m);
  run_camera(*g, m, shot);
  run_light(*g, m, light);
  const auto cam = run_camera(*g, m, shot);
  const auto lit = run_light(*g, m, light);
  auto cpu = make_cpu_visibility(m.view(), VisibilitySettings());
  const auto cam_cpu = run_camera(*cpu, m, shot);
  const auto lit_cpu = run_light(*cpu, m, light);

  std::printf("  %u vertices, %zu triangles\n", vertex_count(m), m.indices.size() / 3);
  const V3 c = centre_of(shot);
  const Comparison cam_cmp = compare(m, cam, cam_cpu, {}, nullptr, [&](size_t v) { return c - v3(&m.positions[3 * v]); });
  const Comparison lit_cmp = compare(m, lit, lit_cpu, {}, nullptr, [&](size_t) { return light; });
  std::printf("  disagreements: camera %zu (%zu front-facing), light %zu (%zu front-facing)\n", cam_cmp.total,
              cam_cmp.front_total, lit_cmp.total, lit_cmp.front_total);
  EXPECT_GE(vertex_count(m), 95000u);  // the size the benchmark figure refers to
  EXPECT_LE(cam_cmp.front_fraction(), 0.02);
  EXPECT_LE(lit_cmp.front_fraction(), 0.02);
}

} // namespace
} // namespace vbrdf

namespace vbrdf {
namespace {
// A plane facing the camera: interior vertices have a clean pixel footprint (kCameraClear); the
// outermost ring's footprint also covers the background (kFootprintPartial), but some of its
// texels still show the plane (the mask is neither empty nor full), and both back ends agree.
TEST_F(GlVisibilityTest, BorderVerticesHaveMixedFootprints) {
  const MeshData plane = test::make_grid(20, 1.0f, 0.0f);  // y = 0, normals +y
  const float eye[3] = {0, 5, 0.001f}, target[3] = {0, 0, 0}, up[3] = {0, 0, -1};
  const Shot shot = test::make_look_at_shot(eye, target, up, 600, 640, 480);
  auto g = gl(plane);
  auto cpu = make_cpu_visibility(plane.view(), VisibilitySettings());
  for (VisibilityBackend *b : {static_cast<VisibilityBackend *>(g.get()), cpu.get()}) {
    const auto r = run_camera(*b, plane, shot);
    int border_mixed = 0, interior_clean = 0, border = 0, interior = 0, partial_masks = 0;
    for (int i = 0; i <= 20; ++i)
      for (int j = 0; j <= 20; ++j) {
        const uint8_t v = r[size_t(i * 21 + j)];
        const bool on_border = i == 0 || j == 0 || i == 20 || j == 20;
        (on_border ? border : interior) += 1;
        if (on_border && (v & kFootprintPartial)) ++border_mixed;
        if (on_border && (v & kFootprintPartial) && (v & 0xF) != 0 && (v & 0xF) != 0xF) ++partial_masks;
        if (!on_border && v == kCameraClear) ++interior_clean;
      }
    EXPECT_EQ(border_mixed, border) << b->name();
    EXPECT_EQ(partial_masks, border) << b->name();
    EXPECT_EQ(interior_clean, interior) << b->name();
  }
}

// The depth tests run in a compute shader where the context has one (the map stays on the GPU),
// else on the CPU after reading the map back: both paths must give the same code for every vertex
// (camera footprints, directional and point-light shadows), on a mesh with real occlusion, mesh
// borders and shadows. A float rounding of a window coordinate may put a vertex into the next
// texel in one path: at most 0.1 % of the vertices may differ.
TEST_F(GlVisibilityTest, ComputeShaderTestsGiveTheReadBackCodes) {
  const GlApi api = load_gl_api(context_->get_proc_address());
  if (!api.has_compute) GTEST_SKIP() << "no compute shaders in this context: only the read-back path runs";
  const MeshData m = dense_scene(160, 24);
  VisibilitySettings on, off;
  off.depth_tests_on_gpu = false;
  auto gpu = gl(m, on), readback = gl(m, off);
  EXPECT_NE(std::string(gpu->name()).find("compute shader"), std::string::npos) << gpu->name();
  EXPECT_NE(std::string(readback->name()).find("read back"), std::string::npos) << readback->name();
  const auto differing = [&](const std::vector<uint8_t> &a, const std::vector<uint8_t> &b) {
    size_t d = 0;
    for (size_t v = 0; v < a.size(); ++v) d += a[v] != b[v];
    return d;
  };
  const size_t limit = vertex_count(m) / 1000;
  // The last shot's pass is divided (a map texel of 2 x 2 photo pixels, pass_size.h).
  for (const Shot &shot : {dense_scene_camera(), dense_scene_camera(321, 237), dense_scene_camera(1800, 1350)}) {
    const auto a = run_camera(*gpu, m, shot), b = run_camera(*readback, m, shot);
    EXPECT_EQ(gpu->last_pass_sizes().camera_divisor, readback->last_pass_sizes().camera_divisor);
    std::printf("  camera %dx%d: %zu of %u vertices differ; %ld hidden, %ld partial footprints\n",
                shot.Intrinsics.ViewportPx[0], shot.Intrinsics.ViewportPx[1], differing(a, b), vertex_count(m),
                long(std::count(a.begin(), a.end(), kCameraHidden)),
                long(std::count_if(a.begin(), a.end(), [](uint8_t c) { return (c & kFootprintPartial) != 0; })));
    EXPECT_LE(differing(a, b), limit);
    EXPECT_GT(std::count(a.begin(), a.end(), kCameraHidden), long(vertex_count(m) / 50));  // the test has teeth
  }
  EXPECT_EQ(gpu->last_pass_sizes().camera_divisor, 2);
  for (V3 light : kLights) {
    const auto a = run_light(*gpu, m, normalized(light)), b = run_light(*readback, m, normalized(light));
    EXPECT_LE(differing(a, b), limit) << light_label("dense", normalized(light));
    EXPECT_GT(std::count(a.begin(), a.end(), 0), 10);
  }
  for (V3 position : {V3{0.2, -0.3, 2.2}, V3{-2.4, 0.4, 0.9}}) {
    const auto a = run_point_light(*gpu, m, position), b = run_point_light(*readback, m, position);
    EXPECT_LE(differing(a, b), limit);
    EXPECT_GT(std::count(a.begin(), a.end(), 0), 10);
  }
}

// The compute path binds shader-storage buffers and texture unit 0: the host's bindings there
// come back as they were.
TEST_F(GlVisibilityTest, ComputeShaderTestsRestoreTheHostsBindings) {
  const GlApi api = load_gl_api(context_->get_proc_address());
  if (!api.has_compute) GTEST_SKIP() << "no compute shaders in this context";
  const MeshData m = box_scene();
  auto g = gl(m);
  GLuint host_buffers[2] = {0, 0}, host_texture = 0;
  api.GenBuffers(2, host_buffers);
  api.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, host_buffers[0]);
  api.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, host_buffers[1]);
  api.GenTextures(1, &host_texture);
  api.ActiveTexture(GL_TEXTURE0);
  api.BindTexture(GL_TEXTURE_2D, host_texture);
  api.ActiveTexture(GL_TEXTURE3);
  run_camera(*g, m, box_scene_camera());
  run_light(*g, m, {0, 0, 1});
  GLint unit = 0, texture = -1, b0 = -1, b1 = -1;
  api.GetIntegerv(GL_ACTIVE_TEXTURE, &unit);
  EXPECT_EQ(unit, GL_TEXTURE3);
  api.ActiveTexture(GL_TEXTURE0);
  api.GetIntegerv(GL_TEXTURE_BINDING_2D, &texture);
  EXPECT_EQ(GLuint(texture), host_texture);
  api.GetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, 0, &b0);
  api.GetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, 1, &b1);
  EXPECT_EQ(GLuint(b0), host_buffers[0]);
  EXPECT_EQ(GLuint(b1), host_buffers[1]);
  EXPECT_EQ(api.GetError(), GLenum(GL_NO_ERROR));
  g.reset();
  api.DeleteTextures(1, &host_texture);
  api.DeleteBuffers(2, host_buffers);
}

// Camera passes smaller than the photo (pass_size.h): a 26 800-vertex scene photographed at 1800
// and 3600 pixels wide, where the mesh's edges span ~6.8 and ~13.6 pixels, so the automatic pass
// is rendered at 1/2 and 1/4 of the photo's resolution. Against the CPU ray caster (exact rays, the
// footprint texels cast at photo resolution):
//  - occlusion: the bound of photo-resolution passes (<= 2 % of the front-facing vertices
//    disagree, nearly all within a map texel of an occluder's silhouette);
//  - footprints stay conservative: a footprint texel the divided pass calls the vertex's own
//    surface is own surface for the CPU too (<= 0.3 % of the clear vertices claim one it does
//    not, as many as at photo resolution + 0.2 %): no clean sample takes a colour from across a
//    depth jump. The price: a band of up to d pixels along silhouettes, and steep faces, read as
//    partial footprints (at most (d + 1) times those of the photo-resolution pass).
TEST_F(GlVisibilityTest, DividedCameraPassesAgreeWithTheCpu) {
  const MeshData m = dense_scene(160, 24);
  auto cpu = make_cpu_visibility(m.view(), VisibilitySettings());
  VisibilitySettings photo_resolution;
  photo_resolution.camera_pass_divisor = 1;
  auto sized = gl(m), full = gl(m, photo_resolution);
  const auto own_of = [](uint8_t code) { return code == kCameraClear ? kAllFootprintTexels : uint8_t(code & 0xF); };
  const auto partial = [](const std::vector<uint8_t> &codes) {
    return size_t(std::count_if(codes.begin(), codes.end(), [](uint8_t c) { return (c & kFootprintPartial) != 0; }));
  };
  for (int width : {1800, 3600}) {
    const Shot shot = dense_scene_camera(width, width * 3 / 4);
    std::vector<uint8_t> a;
    char label[64];
    std::snprintf(label, sizeof label, "dense camera %dx%d, sized", width, width * 3 / 4);
    const int d_expected = width == 1800 ? 2 : 4;
    const Comparison cmp = compare_camera(*sized, *cpu, m, shot, &a, 2.0 * d_expected);
    const int d = sized->last_pass_sizes().camera_divisor;
    EXPECT_EQ(d, d_expected) << "the scene must exercise a divided pass";
    EXPECT_EQ(sized->last_pass_sizes().camera_width, (width + d - 1) / d);
    expect_agreement(label, cmp);
    const auto c = run_camera(*cpu, m, shot), f = run_camera(*full, m, shot);
    EXPECT_EQ(full->last_pass_sizes().camera_divisor, 1);
    size_t clear = 0, extra_sized = 0, extra_full = 0;
    for (size_t v = 0; v < c.size(); ++v) {
      if (c[v] == kCameraHidden) continue;
      ++clear;
      if (a[v] != kCameraHidden && (own_of(a[v]) & ~own_of(c[v]))) ++extra_sized;
      if (f[v] != kCameraHidden && (own_of(f[v]) & ~own_of(c[v]))) ++extra_full;
    }
    std::printf("  %s: divisor %d; own texels the CPU does not see: %zu sized, %zu at photo resolution, of %zu "
                "clear; partial footprints %zu sized, %zu at photo resolution, %zu CPU\n",
                label, d, extra_sized, extra_full, clear, partial(a), partial(f), partial(c));
    EXPECT_LE(extra_sized, clear * 3 / 1000);
    EXPECT_LE(extra_sized, extra_full + clear / 500);
    EXPECT_GE(partial(a), partial(f) * 9 / 10);  // conservative: no fewer partial footprints
    EXPECT_LE(partial(a), partial(f) * size_t(d + 1) + 10);
    EXPECT_GT(partial(c), size_t(100));  // the scene has silhouettes
  }
}

// One backend draws its shadow maps at the size each light needs, keeping a texture larger than the
// next map and drawing into its corner (gl_depth.h ensure_render_target_region): every light,
// whether its map grew or shrank from the previous one, gives the codes of a fresh backend's pass.
TEST_F(GlVisibilityTest, ShadowMapsOfChangingSizeGiveTheCodesOfFreshPasses) {
  const MeshData m = dense_scene(230, 24);
  auto shared = gl(m);
  std::vector<V3> order(std::begin(kLights), std::end(kLights));
  order.insert(order.end(), std::rbegin(kLights), std::rend(kLights));
  std::vector<int> sizes;
  for (V3 light : order) {
    const V3 l = normalized(light);
    const std::vector<uint8_t> kept = run_light(*shared, m, l);
    sizes.push_back(shared->last_pass_sizes().shadow_map);
    auto fresh = gl(m);
    EXPECT_EQ(kept, run_light(*fresh, m, l)) << light_label("dense", l) << ", map " << sizes.back();
  }
  // The order makes the map both shrink and grow between passes.
  bool shrank = false, grew = false;
  for (size_t i = 1; i < sizes.size(); ++i) shrank |= sizes[i] < sizes[i - 1], grew |= sizes[i] > sizes[i - 1];
  EXPECT_TRUE(shrank && grew);
}

// Shadow maps sized per light (pass_size.h) against the former fixed size (resolved_shadow_map_size:
// 2048 here, where the overhead light's map is ~1400) and the CPU: the sized pass meets the bound
// of the others (<= 2 % of the vertices facing the light disagree with the CPU, nearly all within
// 2 map texels of a shadow edge) and disagrees with the CPU on at most 25 % (+ 10) more
// front-facing vertices than the former size, for three directional lights and a point light.
TEST_F(GlVisibilityTest, SizedShadowMapsAgreeWithTheCpu) {
  const MeshData m = dense_scene(230, 24);
  auto cpu = make_cpu_visibility(m.view(), VisibilitySettings());
  VisibilitySettings fixed;
  fixed.shadow_map_size = resolved_shadow_map_size(m.view(), VisibilitySettings());
  auto sized = gl(m), former = gl(m, fixed);
  for (V3 light : kLights) {
    const Comparison s = compare_light(*sized, *cpu, m, light), f = compare_light(*former, *cpu, m, light);
    const int size = sized->last_pass_sizes().shadow_map;
    std::printf("  %s: map %d (former %d): %zu front-facing disagreements (former %zu)\n",
                light_label("dense", normalized(light)).c_str(), size, fixed.shadow_map_size, s.front_total, f.front_total);
    EXPECT_LE(size, fixed.shadow_map_size);
    if (light.z == 1) EXPECT_LT(size, fixed.shadow_map_size);  // the test compares two different sizes
    EXPECT_GE(size, kMinShadowMapSize);
    expect_agreement(light_label("dense sized", normalized(light)), s);
    EXPECT_LE(s.front_total, f.front_total * 5 / 4 + 10);
  }
  const auto p = run_point_light(*sized, m, {0.2, -0.3, 2.2}), q = run_point_light(*cpu, m, {0.2, -0.3, 2.2});
  size_t diff = 0;
  for (size_t v = 0; v < p.size(); ++v) diff += p[v] != q[v];
  EXPECT_LE(diff, p.size() / 50);
}

// light_pass's `only`: the wanted vertices get the codes of a full pass, the others 1 untested,
// in the compute-shader, read-back and CPU back ends, for a directional and a point light.
TEST_F(GlVisibilityTest, LightPassesTestOnlyTheWantedVertices) {
  const MeshData m = dense_scene(120, 24);
  const size_t n = vertex_count(m);
  std::vector<uint64_t> only((n + 63) / 64, 0);
  std::mt19937 rng(7);
  for (size_t v = 0; v < n; ++v)
    if (rng() % 2) only[v / 64] |= uint64_t(1) << (v % 64);
  VisibilitySettings readback_settings;
  readback_settings.depth_tests_on_gpu = false;
  auto compute = gl(m), readback = gl(m, readback_settings);
  auto cpu = make_cpu_visibility(m.view(), VisibilitySettings());
  LightSource point;
  point.positional = true;
  point.position = {{0.2f, -0.3f, 2.2f}};
  const V3 dir = normalized(kLights[1]);
  for (VisibilityBackend *b : {compute.get(), readback.get(), cpu.get()})
    for (const LightSource &light : {LightSource::directional({{float(dir.x), float(dir.y), float(dir.z)}}), point}) {
      std::vector<uint8_t> full(n, 7), part(n, 7);
      b->light_pass(light, full.data());
      b->light_pass(light, part.data(), only.data());
      size_t shadowed_unwanted = 0, wrong = 0;
      for (size_t v = 0; v < n; ++v) {
        const bool wanted = (only[v / 64] >> (v % 64)) & 1u;
        wrong += wanted ? part[v] != full[v] : part[v] != 1;
        shadowed_unwanted += !wanted && full[v] == 0;
      }
      EXPECT_EQ(wrong, 0u) << b->name() << (light.positional ? ", point light" : ", directional light");
      EXPECT_GT(shadowed_unwanted, 10u) << b->name();  // the untested vertices would have read 0
    }
}

} // namespace
} // namespace vbrdf

// ---------------------------------------------------------------------------------------------
// Camera pass cache (camera_pass_cache.h).

namespace vbrdf {
namespace {
struct CountingBackend : VisibilityBackend {
  VisibilityBackend &inner;
  int camera_passes = 0;
  explicit CountingBackend(VisibilityBackend &b) : inner(b) {}
  const char *name() const override { return "counting"; }
  void camera_pass(const Shot &shot, uint8_t *out) override {
    ++camera_passes;
    inner.camera_pass(shot, out);
  }
  void light_pass(const LightSource &light, uint8_t *out, const uint64_t *only) override {
    inner.light_pass(light, out, only);
  }
};
} // namespace

// The same camera twice: one pass, the same codes; another camera: a pass of its own.
TEST(CameraPassCache, ReusesTheLastPassForTheSameCameraOnly) {
  const MeshData m = box_scene();
  auto cpu = make_cpu_visibility(m.view(), VisibilitySettings());
  CountingBackend counting(*cpu);
  CameraPassCache cache(counting, vertex_count(m));
  const float eye[3] = {2, -3, 4};
  const Shot shot = look_at({eye[0], eye[1], eye[2]}, {0, 0, 0}, {0, 0, 1}, 500, 320, 240);
  std::vector<uint8_t> first(vertex_count(m)), again(vertex_count(m)), direct(vertex_count(m));
  cache.camera_pass(shot, first.data());
  cache.camera_pass(shot, again.data());
  EXPECT_EQ(counting.camera_passes, 1);
  EXPECT_EQ(cache.reused(), 1u);
  EXPECT_EQ(first, again);
  cpu->camera_pass(shot, direct.data());
  EXPECT_EQ(first, direct);
  EXPECT_GT(std::count(first.begin(), first.end(), kCameraHidden), 0);  // the box hides part of the ground
  const float other_eye[3] = {-2, -3, 4};
  cache.camera_pass(look_at({other_eye[0], other_eye[1], other_eye[2]}, {0, 0, 0}, {0, 0, 1}, 500, 320, 240), again.data());
  EXPECT_EQ(counting.camera_passes, 2);
  EXPECT_NE(first, again);
}

} // namespace vbrdf
