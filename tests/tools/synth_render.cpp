#include "synth_render.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace synth {
namespace {

const int kBands = 64;  // row bands rasterised in parallel: fixed, so results ignore thread count

double edge(double ax, double ay, double bx, double by, double px, double py) {
  return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

struct Projected {
  std::vector<double> x, y, z;  // supersampled image coordinates (y down) and view depth
};

Projected project_vertices(const Scene &s, const Shot &shot, int ss) {
  const int H = shot.Intrinsics.ViewportPx[1];
  Projected p;
  const size_t n = s.vertex_count();
  p.x.resize(n);
  p.y.resize(n);
  p.z.resize(n);
  for (size_t v = 0; v < n; ++v) {
    const vcg::Point3f w(s.pos[v].x, s.pos[v].y, s.pos[v].z);
    const vcg::Point2f q = shot.Project(w);  // VCG pixels: origin bottom-left, y up
    p.x[v] = double(q[0]) * ss;
    p.y[v] = (H - double(q[1])) * ss;
    p.z[v] = shot.Depth(w);
    if (!(p.z[v] > 0)) throw std::runtime_error("a vertex is behind the camera: move the camera out");
  }
  return p;
}

// Rasterises the triangles over sample rows [y0, y1) into the z-buffer.
void rasterize_band(const Scene &s, const Projected &p, int y0, int y1, int sw, ViewRaster &r,
                    std::vector<float> &zbuf) {
  for (size_t t = 0; t < s.triangle_count(); ++t) {
    const uint32_t a = s.idx[3 * t], b = s.idx[3 * t + 1], c = s.idx[3 * t + 2];
    const double miny = std::min({p.y[a], p.y[b], p.y[c]}), maxy = std::max({p.y[a], p.y[b], p.y[c]});
    // Sample (i, j) sits at (i + 0.5, j + 0.5).
    const int iy0 = std::max(y0, int(std::ceil(miny - 0.5))), iy1 = std::min(y1 - 1, int(std::floor(maxy - 0.5)));
    if (iy0 > iy1) continue;
    const double minx = std::min({p.x[a], p.x[b], p.x[c]}), maxx = std::max({p.x[a], p.x[b], p.x[c]});
    const int ix0 = std::max(0, int(std::ceil(minx - 0.5))), ix1 = std::min(sw - 1, int(std::floor(maxx - 0.5)));
    if (ix0 > ix1) continue;
    const double area = edge(p.x[a], p.y[a], p.x[b], p.y[b], p.x[c], p.y[c]);
    if (area == 0) continue;
    const double inv = 1.0 / area, tol = -1e-9;  // tolerance: no cracks on shared edges
    for (int iy = iy0; iy <= iy1; ++iy)
      for (int ix = ix0; ix <= ix1; ++ix) {
        const double px = ix + 0.5, py = iy + 0.5;
        const double w0 = edge(p.x[b], p.y[b], p.x[c], p.y[c], px, py) * inv;
        const double w1 = edge(p.x[c], p.y[c], p.x[a], p.y[a], px, py) * inv;
        const double w2 = edge(p.x[a], p.y[a], p.x[b], p.y[b], px, py) * inv;
        if (w0 < tol || w1 < tol || w2 < tol) continue;
        // Perspective-correct: screen barycentrics / depth, renormalised.
        const double q0 = w0 / p.z[a], q1 = w1 / p.z[b], q2 = w2 / p.z[c], sum = q0 + q1 + q2;
        const float depth = float(1.0 / sum);
        const size_t k = size_t(iy) * sw + ix;
        if (depth < zbuf[k]) {  // strict: the first triangle wins ties, deterministic
          zbuf[k] = depth;
          r.tri[k] = int32_t(t);
          r.b1[k] = float(q1 / sum);
          r.b2[k] = float(q2 / sum);
        }
      }
  }
}

// Standard normal from two stateless hashes (Box-Muller).
float gaussian(uint64_t key) {
  const double u1 = hash_uniform(hash64(key)), u2 = hash_uniform(hash64(key ^ 0xA5A5A5A5A5A5A5A5ull));
  return float(std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * 3.14159265358979323846 * u2));
}

} // namespace

namespace {
// Fresnel transmission of unpolarised light into glass (n = 1.5) at incidence cosine ci.
double glass_transmission(double ci) {
  ci = std::min(std::max(ci, 0.0), 1.0);
  const double n = 1.5, ct = std::sqrt(std::max(0.0, 1.0 - (1.0 - ci * ci) / (n * n)));
  const double rs = (ci - n * ct) / (ci + n * ct), rp = (n * ci - ct) / (n * ci + ct);
  return 1.0 - (rs * rs + rp * rp) / 2.0;
}
} // namespace

V3 phong(float kd, float ks, float shininess, V3 color, V3 N, V3 L, V3 V, float irradiance, bool coated) {
  const float nl = dot(N, L);
  const V3 R = N * (2 * nl) - L;
  const float spec = ks * std::pow(std::max(dot(R, V), 0.0f), shininess);
  const double coat = coated ? glass_transmission(nl) * glass_transmission(dot(N, V)) /
                                   (glass_transmission(1.0) * glass_transmission(1.0))
                             : 1.0;
  const float diff = float(kd * std::max(nl, 0.0f) * coat);
  return V3(diff * color.x + spec, diff * color.y + spec, diff * color.z + spec) * irradiance;
}

RenderContext::RenderContext(const Scene &s) : scene(s), bvh(s.pos, s.idx) {
  face_normal.resize(s.triangle_count());
  for (size_t t = 0; t < s.triangle_count(); ++t) {
    const V3 a = s.pos[s.idx[3 * t]], b = s.pos[s.idx[3 * t + 1]], c = s.pos[s.idx[3 * t + 2]];
    face_normal[t] = normalize(cross(b - a, c - a));
  }
  ray_eps = 2e-4f * s.frame_radius;
}

LightAt light_at(const Light &light, V3 x) {
  if (!light.point) return {light.direction, std::numeric_limits<float>::infinity(), 1.0f};
  const V3 d = light.position - x;
  const float dist = length(d);
  if (!(dist > 1e-6f * light.reference_distance)) return {V3(), 0.0f, 0.0f};
  const float ratio = light.reference_distance / dist;
  return {d * (1.0f / dist), dist, ratio * ratio};
}

bool RenderContext::lit(V3 p, V3 ng, V3 n, V3 L, float distance) const {
  if (dot(n, L) <= 0 || dot(ng, L) <= 0) return false;
  if (std::isinf(distance)) return !bvh.occluded(p + ng * ray_eps, L, distance);
  // Point light: the segment from the offset origin to the light.
  const V3 o = p + ng * ray_eps, d = (p + L * distance) - o;
  const float len = length(d);
  return !bvh.occluded(o, d * (1.0f / len), len);
}

ViewRaster rasterize(const RenderContext &ctx, const Shot &shot, int ss) {
  ViewRaster r;
  r.width = shot.Intrinsics.ViewportPx[0];
  r.height = shot.Intrinsics.ViewportPx[1];
  r.ss = ss;
  const int sw = r.width * ss, sh = r.height * ss;
  const size_t n = size_t(sw) * sh;
  r.tri.assign(n, -1);
  r.b1.assign(n, 0.0f);
  r.b2.assign(n, 0.0f);
  std::vector<float> zbuf(n, std::numeric_limits<float>::infinity());
  const Projected p = project_vertices(ctx.scene, shot, ss);
  const int rows = (sh + kBands - 1) / kBands;
#pragma omp parallel for schedule(dynamic, 1)
  for (int band = 0; band < kBands; ++band)
    rasterize_band(ctx.scene, p, band * rows, std::min(sh, (band + 1) * rows), sw, r, zbuf);
  return r;
}

uint8_t encode_srgb8(float v) {
  v = clampf(v, 0, 1);
  const float s = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
  return uint8_t(std::lround(255.0f * s));
}

uint16_t encode_linear16(float v) { return uint16_t(std::lround(65535.0f * clampf(v, 0, 1))); }

cv::Mat render_photo(const RenderContext &ctx, const ViewRaster &r, const Shot &shot,
                     const Light &light, const ShadeSettings &set, uint64_t photo_key,
                     PhotoStats &stats) {
  const Scene &s = ctx.scene;
  const V3 eye = shot_centre(shot);
  const int ss = r.ss, sw = r.width * ss;
  cv::Mat img(r.height, r.width, set.linear16 ? CV_16UC3 : CV_8UC3);
  const uint64_t noise_key = hash_combine(set.seed, photo_key);
  uint64_t covered = 0, saturated = 0;
#pragma omp parallel for schedule(dynamic, 4) reduction(+ : covered, saturated)
  for (int y = 0; y < r.height; ++y)
    for (int x = 0; x < r.width; ++x) {
      V3 sum;
      bool any = false;
      for (int j = 0; j < ss; ++j)
        for (int i = 0; i < ss; ++i) {
          const size_t k = size_t(y * ss + j) * sw + size_t(x * ss + i);
          const int t = r.tri[k];
          if (t < 0) continue;
          any = true;
          const uint32_t a = s.idx[3 * t], b = s.idx[3 * t + 1], c = s.idx[3 * t + 2];
          const float w1 = r.b1[k], w2 = r.b2[k], w0 = 1 - w1 - w2;
          const V3 P = s.pos[a] * w0 + s.pos[b] * w1 + s.pos[c] * w2;
          const V3 N = normalize(s.nrm[a] * w0 + s.nrm[b] * w1 + s.nrm[c] * w2);
          const LightAt in = light_at(light, P);
          if (in.falloff == 0 || !ctx.lit(P, ctx.face_normal[t], N, in.L, in.distance)) continue;
          const float kd = s.kd[a] * w0 + s.kd[b] * w1 + s.kd[c] * w2;
          const float ks = s.ks[a] * w0 + s.ks[b] * w1 + s.ks[c] * w2;
          const float al = s.shininess[a] * w0 + s.shininess[b] * w1 + s.shininess[c] * w2;
          const V3 C = s.color[a] * w0 + s.color[b] * w1 + s.color[c] * w2;
          // Directional: falloff is exactly 1, so E * 1 keeps the bytes of the directional renders.
          const bool coated = set.coated_diffuse && (!set.coat_glossy_only || ks > 0);
          sum = sum + phong(kd, ks, al, C, N, in.L, normalize(eye - P), set.irradiance * in.falloff, coated);
        }
      sum = sum * (1.0f / float(ss * ss));  // box filter in linear radiance, before clipping
      const float rgb[3] = {sum.x, sum.y, sum.z};
      bool clipped = false;
      for (int ch = 0; ch < 3; ++ch) {
        float v = rgb[ch];
        if (set.noise_sigma > 0) {
          const uint64_t pix = (uint64_t(y) * r.width + x) * 3 + ch;
          v += set.noise_sigma * gaussian(hash_combine(noise_key, pix));
        }
        // Saturated = the stored code is the maximum (what a fitter sees); OpenCV stores BGR.
        if (set.linear16) {
          const uint16_t code = encode_linear16(v);
          img.at<cv::Vec3w>(y, x)[2 - ch] = code;
          clipped |= code == 65535;
        } else {
          const uint8_t code = encode_srgb8(v);
          img.at<cv::Vec3b>(y, x)[2 - ch] = code;
          clipped |= code == 255;
        }
      }
      covered += any;
      saturated += any && clipped;
    }
  stats.covered_pixels += covered;
  stats.saturated_pixels += saturated;
  return img;
}

} // namespace synth
