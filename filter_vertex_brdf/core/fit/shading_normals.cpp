#include "fit/shading_normals.h"

#include <algorithm>
#include <cmath>

#include "base/vec3.h"
#include "inputs/camera.h"

namespace vbrdf {

namespace {

constexpr double kDegree = kRadiansPerDegree;
constexpr double kHuber = 2.0;         // residuals beyond 2 sigma count linearly
constexpr double kStep = 2e-3;         // numeric derivative step (radians of normal tilt)

struct NormalSample {
  float rgb[3];
  float l[3], e[3];  // unit, towards the light and the camera
  float footprint;
  double w;          // resolution weight
};

struct TangentFrame {
  double n0[3], t1[3], t2[3];
  // The unit normal n0 + x[0] t1 + x[1] t2, as float.
  void normal_at(const double x[2], float out[3]) const {
    double n[3];
    for (int k = 0; k < 3; ++k) n[k] = n0[k] + x[0] * t1[k] + x[1] * t2[k];
    normalize3(n);
    for (int k = 0; k < 3; ++k) out[k] = float(n[k]);
  }
};

// An orthonormal frame around unit n: t1 from the axis least aligned with n.
TangentFrame tangent_frame(const float n[3]) {
  TangentFrame f;
  for (int k = 0; k < 3; ++k) f.n0[k] = n[k];
  const double ax = std::fabs(n[0]), ay = std::fabs(n[1]), az = std::fabs(n[2]);
  double a[3] = {0, 0, 0};
  a[ax <= ay && ax <= az ? 0 : (ay <= az ? 1 : 2)] = 1;
  cross3(f.n0, a, f.t1);
  normalize3(f.t1);
  cross3(f.n0, f.t1, f.t2);
  return f;
}

// The vertex's usable samples for the normal: lit by the mesh's shadow test (attached shadow is a
// normal question and stays in), unsaturated, clean pixel, finite; highlight samples only when
// `specular` (use_highlights and a vertex with a lobe): a lobe the model lacks, or fitted with the
// wrong normal, must not tilt the normal towards it.
std::vector<NormalSample> normal_samples(const Sample *s, size_t count, const float p[3], const float *centres,
                                         const std::vector<LightSource> &lights, bool specular) {
  std::vector<NormalSample> out;
  out.reserve(count);
  const uint16_t skip = kCastShadow | kSaturated | kMixedPixel | kNotSeen | (specular ? 0 : kHighlight);
  for (size_t i = 0; i < count; ++i) {
    if (s[i].flags & skip) continue;
    if (!std::isfinite(s[i].rgb[0]) || !std::isfinite(s[i].rgb[1]) || !std::isfinite(s[i].rgb[2])) continue;
    NormalSample n;
    for (int c = 0; c < 3; ++c) n.rgb[c] = s[i].rgb[c];
    const float *c = centres + 3 * s[i].raster;
    n.e[0] = c[0] - p[0], n.e[1] = c[1] - p[1], n.e[2] = c[2] - p[2];
    normalize3(n.e);
    light_direction_at(lights[s[i].raster], p, n.l);
    n.footprint = s[i].footprint;
    n.w = resolution_weight(s[i]);
    out.push_back(n);
  }
  return out;
}

struct VertexProblem {
  const VertexFit &fit;
  const std::vector<NormalSample> &samples;
  DiffuseForm form;
  LobeForm lobe;
  TangentFrame frame;

  // Model minus photo (3 per sample) at tangent offset x, with the reflectance that fits best at
  // that normal (variable projection: for the fitted shininess the model is linear in k_d C and
  // k_s, solved here in closed form, non-negative), so the normal and the brightness it trades
  // against are found together rather than in slow alternation.
  void residuals(const double x[2], std::vector<double> &r) const {
    float n[3];
    frame.normal_at(x, n);
    const size_t m = samples.size();
    std::vector<double> d(m), g(m);
    const bool specular = fit.ks > 0 && fit.shininess > 0;
    double sdd = 0, sdg = 0, sgg = 0, sdp[3] = {0, 0, 0}, sgp[3] = {0, 0, 0};
    for (size_t i = 0; i < m; ++i) {
      const NormalSample &s = samples[i];
      d[i] = std::max(0.0, double(diffuse_factor(form, dot3(n, s.l), dot3(n, s.e))));
      g[i] = specular && d[i] > 0 ? lobe_value(lobe, lobe_cosine(lobe, n, s.l, s.e), fit.shininess, s.footprint) : 0.0;
      sdd += s.w * d[i] * d[i], sdg += s.w * d[i] * g[i], sgg += s.w * g[i] * g[i];
      for (int c = 0; c < 3; ++c) sdp[c] += s.w * d[i] * s.rgb[c], sgp[c] += s.w * g[i] * s.rgb[c];
    }
    double rho[3] = {0, 0, 0}, ks = 0;
    if (specular && sgg > 0) {  // Schur complement on k_s; k_s < 0 means no specular term
      const double schur = 3 * (sgg - (sdd > 0 ? sdg * sdg / sdd : 0.0));
      double rhs = 0;
      for (int c = 0; c < 3; ++c) rhs += sgp[c] - (sdd > 0 ? sdg * sdp[c] / sdd : 0.0);
      ks = schur > 1e-12 * (3 * sgg) ? std::max(0.0, rhs / schur) : 0.0;
    }
    for (int c = 0; c < 3; ++c) rho[c] = sdd > 0 ? std::max(0.0, (sdp[c] - ks * sdg) / sdd) : 0.0;
    r.resize(3 * m);
    for (size_t i = 0; i < m; ++i)
      for (int c = 0; c < 3; ++c) r[3 * i + size_t(c)] = rho[c] * d[i] + ks * g[i] - double(samples[i].rgb[c]);
  }
  // Robust cost of residuals r at spread sigma, plus the prior on x.
  double cost(const std::vector<double> &r, double sigma, const double x[2], double prior) const {
    double c = 0;
    for (size_t i = 0; i < samples.size(); ++i) {
      const double t = std::sqrt(r[3 * i] * r[3 * i] + r[3 * i + 1] * r[3 * i + 1] + r[3 * i + 2] * r[3 * i + 2]) / sigma;
      c += samples[i].w * (t <= kHuber ? 0.5 * t * t : kHuber * t - 0.5 * kHuber * kHuber);
    }
    return c + 0.5 * prior * (x[0] * x[0] + x[1] * x[1]);
  }
};

// Residual spread per channel (weighted RMS), floored at noise_floor x the mean brightness.
double residual_spread(const VertexProblem &p, const std::vector<double> &r, double noise_floor) {
  double sw = 0, s2 = 0, bright = 0;
  for (size_t i = 0; i < p.samples.size(); ++i) {
    const NormalSample &s = p.samples[i];
    sw += s.w;
    bright += s.w * (s.rgb[0] + s.rgb[1] + s.rgb[2]) / 3.0;
    for (int c = 0; c < 3; ++c) s2 += s.w * r[3 * i + size_t(c)] * r[3 * i + size_t(c)];
  }
  if (!(sw > 0)) return 0;
  const double rms = std::sqrt(s2 / (3 * sw)), floor = noise_floor * bright / sw;
  return std::max(rms, floor);
}

// Gauss-Newton normal equations at x: H (a00, a01, a11) and g = -J^T r, robustly weighted, / sigma^2.
void normal_equations(const VertexProblem &p, const double x[2], const std::vector<double> &r, double sigma,
                      double h[3], double g[2]) {
  std::vector<double> ra, rb;
  const double xa[2] = {x[0] + kStep, x[1]}, xb[2] = {x[0], x[1] + kStep};
  p.residuals(xa, ra);
  p.residuals(xb, rb);
  h[0] = h[1] = h[2] = g[0] = g[1] = 0;
  for (size_t i = 0; i < p.samples.size(); ++i) {
    const double norm = std::sqrt(r[3 * i] * r[3 * i] + r[3 * i + 1] * r[3 * i + 1] + r[3 * i + 2] * r[3 * i + 2]);
    const double t = norm / sigma;
    const double u = p.samples[i].w * (t <= kHuber ? 1.0 : kHuber / t) / (sigma * sigma);
    for (int c = 0; c < 3; ++c) {
      const size_t k = 3 * i + size_t(c);
      const double ja = (ra[k] - r[k]) / kStep, jb = (rb[k] - r[k]) / kStep;
      h[0] += u * ja * ja, h[1] += u * ja * jb, h[2] += u * jb * jb;
      g[0] -= u * ja * r[k], g[1] -= u * jb * r[k];
    }
  }
}

double largest_eigenvalue(const double a[3]) {
  const double m = 0.5 * (a[0] + a[2]), d = 0.5 * (a[0] - a[2]);
  return m + std::sqrt(d * d + a[1] * a[1]);
}

// Solves [a0 a1; a1 a2] y = b; false when singular or not finite.
bool solve2(const double a[3], const double b[2], double y[2]) {
  const double det = a[0] * a[2] - a[1] * a[1];
  if (!(std::fabs(det) > 1e-300)) return false;
  y[0] = (a[2] * b[0] - a[1] * b[1]) / det;
  y[1] = (a[0] * b[1] - a[1] * b[0]) / det;
  return std::isfinite(y[0]) && std::isfinite(y[1]);
}

// Where unit normal `now` stands in the frame's tangent plane (0 when more than 60 deg away).
void tangent_offset(const TangentFrame &frame, const float now[3], double x[2]) {
  const double nd[3] = {now[0], now[1], now[2]};
  const double along = dot3(nd, frame.n0);
  x[0] = x[1] = 0;
  if (along > 0.5) x[0] = dot3(nd, frame.t1) / along, x[1] = dot3(nd, frame.t2) / along;
}

struct VertexSolution {
  bool determined = false;
  bool fixed = false;  // not solved this round (converged): a neighbour with its current correction
  double x[2] = {0, 0};
  double info[3] = {0, 0, 0};  // the posterior's information matrix at x (data + prior)
};

void clamp_length(double x[2], double max_length) {
  const double l = std::sqrt(x[0] * x[0] + x[1] * x[1]);
  if (l > max_length) x[0] *= max_length / l, x[1] *= max_length / l;
}

VertexSolution solve_vertex(const VertexProblem &p, const double start[2], const ShadingNormalSettings &settings) {
  VertexSolution out;
  const double prior = 1.0 / std::pow(settings.mesh_normal_degrees * kDegree, 2);
  const double max_length = std::tan(settings.max_degrees * kDegree);
  double x[2] = {start[0], start[1]};
  std::vector<double> r, r_new;
  p.residuals(x, r);
  const double sigma = residual_spread(p, r, settings.noise_floor);
  if (!(sigma > 0)) return out;
  double h[3], g[2];
  normal_equations(p, x, r, sigma, h, g);
  if (!(largest_eigenvalue(h) >= prior)) return out;  // the data say less than the prior in every direction
  out.determined = true;
  double c = p.cost(r, sigma, x, prior), mu = 1e-3;
  for (int it = 0; it < settings.iterations; ++it) {
    const double a[3] = {(h[0] + prior) * (1 + mu), h[1], (h[2] + prior) * (1 + mu)};
    const double b[2] = {g[0] - prior * x[0], g[1] - prior * x[1]};
    double step[2];
    if (!solve2(a, b, step)) break;
    double xn[2] = {x[0] + step[0], x[1] + step[1]};
    clamp_length(xn, max_length);
    p.residuals(xn, r_new);
    const double cn = p.cost(r_new, sigma, xn, prior);
    if (cn < c) {
      const bool small = std::hypot(xn[0] - x[0], xn[1] - x[1]) < 1e-5;
      x[0] = xn[0], x[1] = xn[1], c = cn;
      r.swap(r_new);
      mu = std::max(mu / 4, 1e-6);
      if (small) break;
      normal_equations(p, x, r, sigma, h, g);
    } else {
      mu *= 8;
      if (mu > 1e4) break;
    }
  }
  // Keep the mesh normal unless the refined one explains the samples significantly better: the
  // cost must fall by more than settings.min_gain (half a chi-square quantile for the normal's
  // two degrees of freedom). Where the mesh normal is right, noise alone does not move it.
  {
    const double zero[2] = {0, 0};
    std::vector<double> r0;
    p.residuals(zero, r0);
    if (!(p.cost(r0, sigma, zero, prior) - c > settings.min_gain)) {
      x[0] = x[1] = 0;
      r.swap(r0);
    }
  }
  // Information at the solution, with the spread the solution leaves (a better fit: more certain).
  const double sigma_final = residual_spread(p, r, settings.noise_floor);
  normal_equations(p, x, r, sigma_final > 0 ? sigma_final : sigma, h, g);
  out.x[0] = x[0], out.x[1] = x[1];
  out.info[0] = h[0] + prior, out.info[1] = h[1], out.info[2] = h[2] + prior;
  if (!std::isfinite(out.x[0] + out.x[1] + out.info[0] + out.info[1] + out.info[2])) out = VertexSolution();
  return out;
}

// Smooths the corrections towards the neighbours' (see the header): Jacobi sweeps over the chunk's
// determined vertices, each solving (A_v + lambda k I) x_v = A_v x_hat_v + lambda sum_u P_v x_u.
void smooth_corrections(const SampleChunk &chunk, const MeshAdjacency &adjacency, const std::vector<TangentFrame> &frames,
                        std::vector<VertexSolution> &solutions, const ShadingNormalSettings &settings) {
  if (settings.neighbour_sweeps <= 0 || !(settings.neighbour_degrees > 0)) return;
  const double lambda = 1.0 / std::pow(settings.neighbour_degrees * kDegree, 2);
  const size_t n = chunk.vertex_count;
  std::vector<double> world(3 * n, 0.0), next(3 * n, 0.0);  // corrections as world tangent vectors
  const auto to_world = [&](size_t i, const double x[2], double *w) {
    for (int k = 0; k < 3; ++k) w[k] = x[0] * frames[i].t1[k] + x[1] * frames[i].t2[k];
  };
  for (size_t i = 0; i < n; ++i)
    if (solutions[i].determined) to_world(i, solutions[i].x, &world[3 * i]);
  for (int sweep = 0; sweep < settings.neighbour_sweeps; ++sweep) {
#pragma omp parallel for schedule(dynamic, 1024)
    for (long long ii = 0; ii < (long long)n; ++ii) {
      const size_t i = size_t(ii);
      const VertexSolution &s = solutions[i];
      if (!s.determined) continue;
      if (s.fixed) {
        to_world(i, s.x, &next[3 * i]);
        continue;
      }
      const size_t v = chunk.first_vertex + i;
      double sum[2] = {0, 0};
      int k = 0;
      for (uint32_t a = adjacency.offsets[v]; a < adjacency.offsets[v + 1]; ++a) {
        const size_t u = adjacency.neighbours[a];
        if (u < chunk.first_vertex || u >= chunk.first_vertex + n || !solutions[u - chunk.first_vertex].determined) continue;
        const double *wu = &world[3 * (u - chunk.first_vertex)];
        sum[0] += dot3(wu, frames[i].t1), sum[1] += dot3(wu, frames[i].t2);
        ++k;
      }
      double x[2] = {s.x[0], s.x[1]};
      if (k > 0) {
        const double a[3] = {s.info[0] + lambda * k, s.info[1], s.info[2] + lambda * k};
        const double b[2] = {s.info[0] * s.x[0] + s.info[1] * s.x[1] + lambda * sum[0],
                             s.info[1] * s.x[0] + s.info[2] * s.x[1] + lambda * sum[1]};
        if (!solve2(a, b, x)) x[0] = s.x[0], x[1] = s.x[1];
      }
      to_world(i, x, &next[3 * i]);
    }
    world.swap(next);
  }
  for (size_t i = 0; i < n; ++i)
    if (solutions[i].determined) {
      solutions[i].x[0] = dot3(&world[3 * i], frames[i].t1);
      solutions[i].x[1] = dot3(&world[3 * i], frames[i].t2);
    }
}

// The vertex's solve from its samples, starting at tangent offset `start`: undetermined when
// fewer than min_samples of them are usable for the normal (normal_samples).
VertexSolution solve_from_samples(const Sample *samples, size_t count, const float position[3], const float *centres,
                                  const std::vector<LightSource> &lights, const VertexFit &fit, DiffuseForm form,
                                  LobeForm lobe, const TangentFrame &frame, const double start[2],
                                  const ShadingNormalSettings &settings) {
  const std::vector<NormalSample> usable =
      normal_samples(samples, count, position, centres, lights, settings.use_highlights && fit.ks > 0 && fit.shininess > 0);
  if (usable.size() < size_t(std::max(settings.min_samples, 3))) return VertexSolution();
  return solve_vertex(VertexProblem{fit, usable, form, lobe, frame}, start, settings);
}

// Writes the normal at (bounded) tangent offset x into `normal` when it moved from it by more than
// converged_degrees; false (normal unchanged) when it did not: its samples keep their shading.
bool take_if_moved(const TangentFrame &frame, const double x[2], const ShadingNormalSettings &settings, float normal[3]) {
  float refined[3];
  frame.normal_at(x, refined);
  if (!(dot3(refined, normal) < float(std::cos(settings.converged_degrees * kDegree)))) return false;
  for (int k = 0; k < 3; ++k) normal[k] = refined[k];
  return true;
}

} // namespace

ShadingNormalCounts refine_shading_normals(const SampleChunk &chunk, const MeshView &mesh, const MeshAdjacency &adjacency,
                                           const std::vector<Raster> &rasters, const std::vector<LightSource> &lights,
                                           const DiffuseForms &forms, LobeForm lobe, const VertexFit *fits,
                                           const ShadingNormalSettings &settings, const uint8_t *active, float *normals,
                                           float *moved_degrees, uint8_t *changed) {
  ShadingNormalCounts counts;
  const size_t n = chunk.vertex_count;
  std::vector<float> centres(3 * rasters.size());
  for (size_t r = 0; r < rasters.size(); ++r) camera_centre(rasters[r].shot, &centres[3 * r]);
  std::vector<TangentFrame> frames(n);
  std::vector<VertexSolution> solutions(n);
  std::vector<uint8_t> modelled(n, 0);
  const double max_length = std::tan(settings.max_degrees * kDegree);
#pragma omp parallel for schedule(dynamic, 256)
  for (long long ii = 0; ii < (long long)n; ++ii) {
    const size_t i = size_t(ii), v = chunk.first_vertex + i;
    changed[i] = 0;
    float n0[3] = {mesh.normals[3 * v], mesh.normals[3 * v + 1], mesh.normals[3 * v + 2]};
    if (!(normalize3(n0) > 0)) continue;
    frames[i] = tangent_frame(n0);
    const VertexFit &fit = fits[i];
    if (fit.status != kFitFull && fit.status != kFitDiffuseOnly) continue;
    modelled[i] = 1;
    double start[2];  // a later round starts where the current normal stands
    tangent_offset(frames[i], normals + 3 * v, start);
    if (active && !active[i]) {  // converged in an earlier round: a fixed neighbour now
      solutions[i].determined = moved_degrees[v] >= 0;
      solutions[i].fixed = true;
      solutions[i].x[0] = start[0], solutions[i].x[1] = start[1];
      continue;
    }
    solutions[i] = solve_from_samples(chunk.samples.data() + chunk.offsets[i], chunk.offsets[i + 1] - chunk.offsets[i],
                                      mesh.positions + 3 * v, centres.data(), lights, fit, forms.at(v), lobe, frames[i],
                                      start, settings);
  }
  smooth_corrections(chunk, adjacency, frames, solutions, settings);
  for (size_t i = 0; i < n; ++i) {
    const size_t v = chunk.first_vertex + i;
    if (!modelled[i] || solutions[i].fixed) continue;
    moved_degrees[v] = -1;
    if (!solutions[i].determined) {
      ++counts.undetermined;
      continue;
    }
    ++counts.refined;
    clamp_length(solutions[i].x, max_length);
    moved_degrees[v] = float(std::atan(std::hypot(solutions[i].x[0], solutions[i].x[1])) / kDegree);
    changed[i] = uint8_t(take_if_moved(frames[i], solutions[i].x, settings, normals + 3 * v));
  }
  return counts;
}

bool refine_vertex_normal(const Sample *samples, size_t count, const float position[3], const float mesh_normal[3],
                          const float *centres, const std::vector<LightSource> &lights, const VertexFit &fit,
                          DiffuseForm form, LobeForm lobe, const ShadingNormalSettings &settings, float normal[3]) {
  float n0[3] = {mesh_normal[0], mesh_normal[1], mesh_normal[2]};
  if (!(normalize3(n0) > 0) || (fit.status != kFitFull && fit.status != kFitDiffuseOnly)) return false;
  const TangentFrame frame = tangent_frame(n0);
  double start[2];
  tangent_offset(frame, normal, start);
  VertexSolution solution =
      solve_from_samples(samples, count, position, centres, lights, fit, form, lobe, frame, start, settings);
  if (!solution.determined) return false;
  clamp_length(solution.x, std::tan(settings.max_degrees * kDegree));
  return take_if_moved(frame, solution.x, settings, normal);
}

MovedSummary summarise_moved(const std::vector<float> &moved_degrees, const std::vector<uint8_t> &select) {
  std::vector<float> values;
  for (size_t v = 0; v < moved_degrees.size(); ++v)
    if (moved_degrees[v] >= 0 && (select.empty() || (v < select.size() && select[v]))) values.push_back(moved_degrees[v]);
  MovedSummary s;
  s.count = values.size();
  if (values.empty()) return s;
  const auto at = [&](double q) {
    const size_t k = std::min(values.size() - 1, size_t(q * double(values.size() - 1) + 0.5));
    std::nth_element(values.begin(), values.begin() + long(k), values.end());
    return values[k];
  };
  s.median = at(0.5);
  s.p95 = at(0.95);
  return s;
}

} // namespace vbrdf
