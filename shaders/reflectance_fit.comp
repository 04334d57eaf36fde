#version 430
// Per-vertex reflectance fit, one invocation per vertex, float32. Contract: core/fit/reflectance_fit.h; this is a
// transcription of the double-precision reference core/fit/reflectance_fit_cpu.cpp (keep them in step).
// There are no per-vertex arrays in GLSL, so every stage loops over the vertex's sample range again
// ("passes"); a dropped highlight sample is skipped by every loop.
//
// Float-specific measures (the algorithm and its decisions are the reference's):
// - pixel values and weights are scaled by powers of two (exact) so that squares neither overflow
//   nor underflow; the thresholds in pixel units (excess 1e-4, kd_max, ks_max) are scaled too;
// - ln s is evaluated by a series near s = 1, where GPU log() only has an absolute error bound;
// - the (rho, k_s) normal equations use the diffuse-only solution r = p/A as pivot
//   (sum w g (P - r d) instead of q - b p/A), and the Schur complement g2 - b^2/A is recomputed
//   as a sum of squares when it cancels, so that the singularity test means what it does in double;
// - the objective is summed with Kahan compensation: the 1e-5 convergence test is near the
//   rounding error of a plain float sum over a few hundred samples.
// Both back ends keep the contract alike (tests/unit/test_reflectance_fit_gpu.cpp): a sample with N.L = +Inf
// is not usable; the alpha_from_highlights fallback is the clamped alpha_init; the convergence
// floor is relative to the data's scale, so very small pixel values are fitted like ordinary ones.
// The fallback fit for vertices without a strictly usable sample (fit_vertex_weak, fit_status 4)
// and the neighbour fill (fit_status 3) run on the CPU after either back end (core/run/fit_run.cpp).
layout(local_size_x = 64) in;

struct Sample {  // core/samples/samples.h Sample, 28 bytes
  float r, g, b;
  float d;             // N.L
  float s;             // the lobe's cosine: R.E or N.H (model/lobe.h)
  uint raster_flags;   // raster | flags << 16 | resolution << 26
  float footprint;     // the normal variance over the photo's pixel footprint (samples/footprint.h)
};

struct Fit {  // core/fit/reflectance_fit.h VertexFit, 40 bytes
  float color[3];
  float kd, ks, shininess, dq, sq, rmse;
  uint bits;  // iterations | status << 16 | converged << 24
};

layout(std430, binding = 0) readonly buffer Samples { Sample samples[]; };
layout(std430, binding = 1) readonly buffer Offsets { uint offsets[]; };  // vertex_count + 1 entries
layout(std430, binding = 2) writeonly buffer Fits { Fit fits[]; };
// Vertices in the order they are run (a permutation of 0 .. u_vertex_count-1): the host puts the
// vertices that will iterate first, so that SIMD groups / warps do similar amounts of work.
layout(std430, binding = 3) readonly buffer Order { uint order[]; };

uniform uint u_vertex_count;  // vertices in this dispatch
uniform uint u_sample_base;   // offsets[0]: the samples buffer starts at this sample
uniform float u_alpha_init, u_alpha_min, u_alpha_max, u_tolerance, u_weight_cap, u_prior;
uniform float u_kd_max, u_ks_max, u_specular_threshold;
uniform int u_max_iterations, u_min_specular, u_min_lobe;
uniform float u_lobe_threshold;  // both thresholds already on the lobe's cosine (lobe_threshold())
uniform int u_half_angle_lobe;   // 1: s is N.H (SQ's sampling term is then 2 s^2 - 1, lobe_as_r_dot_e)
uniform int u_ggx_lobe;          // 1: the lobe is GGX's D(N.H)/D(1), not s^alpha (model/lobe.h lobe_value)

const uint kUnusable = 0x13Fu;  // kNotSeen | kShadowed | kSaturated | kMixedPixel (samples.h)
const uint kStatusDiffuseOnly = 1u, kStatusFull = 2u;
// The model's constants, each named once (model/lobe.h; tests/unit/test_model_constants.cpp checks
// every named constant here against the C++ model and fails on a bare copy of its value).
const float kMaxFootprintVariance = 0.18;  // the clamp on a sample's footprint variance
const float kLobeLogFloor = -80.0;         // the floor on alpha ln s: no ln 0, no denormals

struct Obs {
  vec3 p;      // pixel value / g_pixel_scale
  float d, s;  // min(N.L, 1), the lobe's cosine
  float w;     // N.L * resolution weight / g_weight_scale, times g_high_scale for highlight samples
  float v;     // Sample::footprint for the GGX lobe (0 for the power forms)
  bool high;
};

// Linear parameters for one alpha, with the objective and its t = ln(alpha) derivatives there.
struct Linear {
  vec3 rho;
  float ks, energy, grad, curv;
};

// Per-vertex state (GLSL globals are per invocation).
uint g_begin, g_end;
bool g_drop_high;       // remedy 3: highlight samples left out
float g_high_scale;     // remedy 1: weight factor of highlight samples
float g_pixel_scale, g_inv_pixel_scale, g_inv_weight_scale;
float g_a;              // A = sum w d^2 + prior
vec3 g_p;               // p_c = sum w d P_c + prior rho0_c
vec3 g_r;               // p / A: the pivot of the k_s equation
vec3 g_rho0;            // diffuse-only estimate
float g_prior;          // diffuse_prior * total weight

// Bit test: cannot be optimised away the way isnan/isinf may be under fast-math rules.
bool finite(float x) { return (floatBitsToUint(x) & 0x7F800000u) != 0x7F800000u; }

// ln s for s in (0, 1]. Near 1, 2 atanh((s-1)/(s+1)) as a series (s - 1 is exact there).
float ln_s(float s) {
  if (s < 0.5) return log(s);
  const float u = (s - 1.0) / (s + 1.0), u2 = u * u;
  return 2.0 * u *
         (1.0 + u2 * (1.0 / 3.0 + u2 * (1.0 / 5.0 + u2 * (1.0 / 7.0 + u2 * (1.0 / 9.0 + u2 * (1.0 / 11.0 + u2 / 13.0))))));
}

// GGX's D(N.H)/D(1) with a^2 = 2 / (alpha + 2), seen through a pixel footprint of normal variance
// v (model/lobe.h ggx_lobe_through_footprint: a_f^2 = min(a^2 + min(v, kMaxFootprintVariance), 1), the value
// (a^2 / a_f^2) r^2), for s in (0, 1].
float ggx_lobe(float s, float alpha, float v) {
  const float a2 = 2.0 / (alpha + 2.0), a2f = min(a2 + min(max(v, 0.0), kMaxFootprintVariance), 1.0);
  const float den = a2f + (1.0 - s * s) * (1.0 - a2f);
  return a2 * a2f / (den * den);
}

// Its derivative in t = ln(alpha) (lobe.h lobe_dvalue_dlog_alpha), for s in (0, 1], or s = 1 with v > 0.
float ggx_lobe_dt(float s, float alpha, float v) {
  const float a2 = 2.0 / (alpha + 2.0), u = 1.0 - s * s, a2f = a2 + min(max(v, 0.0), kMaxFootprintVariance);
  const float da2_dt = -2.0 * alpha / ((alpha + 2.0) * (alpha + 2.0));
  if (a2f >= 1.0) return da2_dt;
  const float den = a2f + u * (1.0 - a2f), r = a2f / den;
  return (r * r * (a2f - a2) / (a2f * a2f) + a2 / a2f * 2.0 * r * u / (den * den)) * da2_dt;
}

// The lobe g(s, alpha) without ln(0), overflow or denormals (as the reference's lobe()); v: the
// sample's footprint variance (GGX only).
float lobe(float s, float alpha, float v) {
  if (!(s > 0.0)) return 0.0;
  if (u_ggx_lobe != 0) return ggx_lobe(min(s, 1.0), alpha, v);
  return exp(max(alpha * ln_s(min(s, 1.0)), kLobeLogFloor));
}

// Reads sample i; false when it is not usable (or dropped). Same usability rule as the reference,
// plus a finite N.L (the reference takes +Inf, which is not evidence either).
bool load(uint i, out Obs x) {
  const Sample raw = samples[i - u_sample_base];
  x.p = vec3(0.0); x.d = 0.0; x.s = 0.0; x.w = 0.0; x.v = 0.0; x.high = false;
  const uint flags = (raw.raster_flags >> 16) & 0x3FFu;
  const float resolution = exp2(-float(raw.raster_flags >> 26) / 8.0);  // resolution_weight()
  if ((flags & kUnusable) != 0u) return false;
  // Grazing light (kGrazing) is not evidence unless the sample is a highlight (kHighlight).
  if ((flags & 0x40u) != 0u && (flags & 0x80u) == 0u) return false;
  if (!finite(raw.d) || !(raw.d > 0.0)) return false;
  if (!finite(raw.r) || !finite(raw.g) || !finite(raw.b) || !finite(raw.s)) return false;
  x.high = raw.s > u_specular_threshold;
  if (x.high && g_drop_high) return false;
  x.p = vec3(raw.r, raw.g, raw.b) * g_inv_pixel_scale;
  x.d = min(raw.d, 1.0);
  x.s = raw.s;
  x.v = u_ggx_lobe != 0 && finite(raw.footprint) ? raw.footprint : 0.0;
  x.w = raw.d * resolution * g_inv_weight_scale * (x.high ? g_high_scale : 1.0);
  return true;
}

// Power of two near |x| (1 for 0), in the normal float range.
float pow2_near(float x) {
  if (!(x > 0.0)) return 1.0;
  int e;
  frexp(x, e);
  return ldexp(1.0, clamp(e - 1, -120, 120));
}

// Kahan summation: sum += x.
void kahan_add(inout float sum, inout float comp, float x) {
  precise float y = x - comp;
  precise float t = sum + y;
  precise float c = (t - sum) - y;
  comp = c;
  sum = t;
}

// ---------------------------------------------------------------------------------------------
// Set-up passes.

// Pass 1: usable and highlight counts, and the magnitudes that fix the scales.
void count_samples(out int n, out int n_high, out int n_lobe) {
  n = 0; n_high = 0; n_lobe = 0;
  float max_p = 0.0, max_w = 0.0;
  for (uint i = g_begin; i < g_end; ++i) {
    Obs x;
    if (!load(i, x)) continue;
    ++n;
    if (x.high) ++n_high;
    if (x.s > u_lobe_threshold) ++n_lobe;
    max_p = max(max_p, max(abs(x.p.r), max(abs(x.p.g), abs(x.p.b))));
    max_w = max(max_w, x.w);
  }
  g_pixel_scale = pow2_near(max_p);
  g_inv_pixel_scale = 1.0 / g_pixel_scale;
  g_inv_weight_scale = 1.0 / pow2_near(max_w);
}

// Pass 2: remedies 1 and 3, diffuse-only estimate rho0 and the constant part of the normal
// equations. Sums are kept apart for highlight and other samples so that one pass serves both
// the weight cap and the dropping decision.
void setup_linear(int n, int n_high, bool ks_free) {
  float w_h = 0.0, w_o = 0.0, dd_h = 0.0, dd_o = 0.0;
  vec3 dp_h = vec3(0.0), dp_o = vec3(0.0);
  for (uint i = g_begin; i < g_end; ++i) {
    Obs x;
    if (!load(i, x)) continue;
    const float wd = x.w * x.d;
    if (x.high) w_h += x.w, dd_h += wd * x.d, dp_h += wd * x.p;
    else w_o += x.w, dd_o += wd * x.d, dp_o += wd * x.p;
  }
  g_high_scale = (w_o > 0.0 && w_h > u_weight_cap * w_o) ? u_weight_cap * w_o / w_h : 1.0;
  g_drop_high = !ks_free && n_high > 0 && n_high < n;
  const float k = g_drop_high ? 0.0 : g_high_scale;
  const float total_w = w_o + k * w_h, dd_all = dd_o + k * dd_h;
  const vec3 dp_all = dp_o + k * dp_h;
  // Without any non-highlight sample, rho0 comes from all samples.
  g_rho0 = max(vec3(0.0), dd_o > 0.0 ? dp_o / dd_o : dp_all / max(dd_all, 1e-30));
  g_prior = u_prior * total_w;
  g_a = dd_all + g_prior;
  g_p = dp_all + g_prior * g_rho0;
  g_r = g_p / g_a;
}

// Thesis 4.5-style initial shininess: slope of ln(P - rho0 d) against ln s over highlight
// samples (Welford's updates: the plain sums cancel in float when ln s hardly varies).
float alpha_from_highlights(float fallback) {
  int n = 0;
  float mx = 0.0, my = 0.0, sxx = 0.0, sxy = 0.0;
  const float min_excess = 1e-4 * g_inv_pixel_scale;
  const float rho0_sum = g_rho0.r + g_rho0.g + g_rho0.b;
  for (uint i = g_begin; i < g_end; ++i) {
    Obs x;
    if (!load(i, x) || !x.high || !(x.s > 0.0) || x.s >= 1.0) continue;
    const float excess = (x.p.r + x.p.g + x.p.b - rho0_sum * x.d) / 3.0;
    if (!(excess > min_excess)) continue;
    const float lx = ln_s(x.s), ly = log(excess);
    ++n;
    const float dx = lx - mx;
    mx += dx / float(n);
    my += (ly - my) / float(n);
    sxy += dx * (ly - my);
    sxx += dx * (lx - mx);
  }
  // The reference's threshold is on the unscaled sums; ly's scale shift does not change sxx.
  if (n < 2 || sxx < 1e-10) return fallback;
  return clamp(sxy / sxx, u_alpha_min, u_alpha_max);
}

// ---------------------------------------------------------------------------------------------
// Linear solve and objective.

// g2 - b^2/A as the sum of squares sum w (g - beta d)^2 + beta^2 prior, beta = b/A (no
// cancellation; used when the cheap form has lost most of its digits).
float schur_by_squares(float alpha, float beta) {
  float sum = 0.0;
  for (uint i = g_begin; i < g_end; ++i) {
    Obs x;
    if (!load(i, x)) continue;
    const float e = lobe(x.s, alpha, x.v) - beta * x.d;
    sum += x.w * e * e;
  }
  return sum + beta * beta * g_prior;
}

// Objective at (L, alpha), and its gradient and Gauss-Newton curvature in t = ln(alpha) at fixed
// linear parameters (envelope theorem), in one pass.
void objective(inout Linear L, float alpha) {
  float e = 0.0, comp = 0.0, grad = 0.0, curv = 0.0;
  for (uint i = g_begin; i < g_end; ++i) {
    Obs x;
    if (!load(i, x)) continue;
    // k_s = 0 (every diffuse-only fit): no lobe, and no alpha derivative.
    const bool lobed = L.ks > 0.0 && x.s > 0.0;
    const bool ggx = u_ggx_lobe != 0;
    const float lx = lobed && !ggx ? ln_s(min(x.s, 1.0)) : 0.0;
    const float g = lobed ? (ggx ? ggx_lobe(min(x.s, 1.0), alpha, x.v) : exp(max(alpha * lx, kLobeLogFloor))) : 0.0;
    const vec3 r = x.p - L.rho * x.d - vec3(L.ks * g);
    kahan_add(e, comp, x.w * dot(r, r));
    if (lobed && (x.s < 1.0 || (ggx && x.v > 0.0))) {  // ln s finite and non-zero, or a footprint's peak
      const float dg = L.ks * (ggx ? ggx_lobe_dt(min(x.s, 1.0), alpha, x.v) : g * lx * alpha);  // d(k_s g)/dt
      grad += -2.0 * x.w * (r.r + r.g + r.b) * dg;
      curv += 6.0 * x.w * dg * dg;
    }
  }
  const vec3 dr = L.rho - g_rho0;
  L.energy = e + g_prior * dot(dr, dr);
  L.grad = grad;
  L.curv = curv;
}

// Exact non-negative least squares in (rho, k_s) for a fixed alpha (ks_free = false: k_s = 0),
// then the objective there.
Linear solve(float alpha, bool ks_free) {
  float b = 0.0, g2 = 0.0;
  vec3 qr = vec3(0.0);  // sum w g (P - r d) = q - b p / A
  if (ks_free)
    for (uint i = g_begin; i < g_end; ++i) {
      Obs x;
      if (!load(i, x)) continue;
      const float g = lobe(x.s, alpha, x.v), wg = x.w * g;
      b += wg * x.d;
      g2 += wg * g;
      qr += wg * (x.p - g_r * x.d);
    }
  float schur = g2 - b * (b / g_a);
  if (ks_free && schur < 1e-3 * g2) schur = schur_by_squares(alpha, b / g_a);

  Linear L;
  L.rho = vec3(0.0);
  L.ks = 0.0;
  bvec3 at_zero = bvec3(false);  // channels held at 0 (active set)
  for (int pass = 0; pass < 4; ++pass) {
    // k_s equation after eliminating the free rho_c = (p_c - b k_s) / A.
    float num = 0.0;
    int free_count = 0;
    for (int c = 0; c < 3; ++c) {
      if (at_zero[c]) num += qr[c] + g_r[c] * b;
      else num += qr[c], ++free_count;
    }
    const float den = float(free_count) * schur + float(3 - free_count) * g2;
    // Singular (g ~ 0, or g proportional to d): no specular discrimination, k_s = 0.
    L.ks = (ks_free && den > 1e-9 * (3.0 * g2 + 1e-30)) ? max(0.0, num / den) : 0.0;
    bool changed = false;
    for (int c = 0; c < 3; ++c) {
      if (at_zero[c]) continue;
      L.rho[c] = (g_p[c] - b * L.ks) / g_a;
      if (L.rho[c] < 0.0) L.rho[c] = 0.0, at_zero[c] = true, changed = true;
    }
    if (!changed || free_count == 0) break;
  }
  L.rho = min(L.rho, vec3(u_kd_max * g_inv_pixel_scale));
  L.ks = min(L.ks, u_ks_max * g_inv_pixel_scale);
  objective(L, alpha);
  return L;
}

// ---------------------------------------------------------------------------------------------
// Output.

// evaluate_reflectance() of the reference, in pixel units.
vec3 evaluate(Fit f, float d, float s, float v) {
  d = max(d, 0.0);
  const float spec = (d > 0.0 && f.ks > 0.0) ? f.ks * lobe(s, f.shininess, v) : 0.0;
  return f.kd * d * vec3(f.color[0], f.color[1], f.color[2]) + vec3(spec);
}

// Thesis 4.7.1 quality terms and the weighted RMSE (last pass).
void quality_metrics(inout Fit f) {
  float dq_term = 0.0, dq_err = 0.0, sq_term = 0.0, sq_err = 0.0, e = 0.0, w = 0.0;
  int nd = 0, ns = 0;
  const float p2 = g_pixel_scale * g_pixel_scale;
  for (uint i = g_begin; i < g_end; ++i) {
    Obs x;
    if (!load(i, x)) continue;
    const vec3 diff = x.p - evaluate(f, x.d, x.s, x.v) * g_inv_pixel_scale;
    const float err2 = dot(diff, diff);  // scaled; * p2 in pixel units (may be +Inf: clamped below)
    e += x.w * err2, w += x.w;
    const float s_re = u_half_angle_lobe != 0 ? (x.s > 0.0 ? 2.0 * x.s * x.s - 1.0 : -1.0) : x.s;
    if (x.high) sq_term += s_re, sq_err += s_re * err2 * p2 / 3.0, ++ns;
    else dq_term += x.d, dq_err += x.d * err2 * p2 / 3.0, ++nd;
  }
  f.dq = nd > 0 ? clamp(dq_term / float(nd) + 1.0 - min(1.0, dq_err / float(nd)), 0.0, 2.0) : 0.0;
  f.sq = ns > 0 ? clamp(sq_term / float(ns) + 1.0 - min(1.0, sq_err / float(ns)), 0.0, 2.0) : 0.0;
  f.rmse = w > 0.0 ? sqrt(e / (3.0 * w)) * g_pixel_scale : 0.0;
}

Fit sentinel_fit() {
  Fit f;
  f.color[0] = 0.0; f.color[1] = 0.0; f.color[2] = 0.0;
  f.kd = 0.0; f.ks = 0.0; f.shininess = 0.0; f.dq = 0.0; f.sq = 0.0; f.rmse = 0.0;
  f.bits = 0u;
  return f;
}

// Normalisation: k_d = max_c rho_c, C = rho / k_d (max channel 1).
Fit store_linear(Linear L, float alpha) {
  Fit f = sentinel_fit();
  const vec3 rho = L.rho * g_pixel_scale;
  const float kd = max(rho.r, max(rho.g, rho.b));
  f.kd = kd;
  for (int c = 0; c < 3; ++c) f.color[c] = kd > 0.0 ? min(1.0, rho[c] / kd) : 0.0;
  f.ks = L.ks * g_pixel_scale;
  f.shininess = f.ks > 0.0 ? alpha : 0.0;
  return f;
}

// ---------------------------------------------------------------------------------------------

void main() {
  if (gl_GlobalInvocationID.x >= u_vertex_count) return;
  const uint v = order[gl_GlobalInvocationID.x];
  g_begin = offsets[v];
  g_end = offsets[v + 1u];
  g_drop_high = false;
  g_high_scale = 1.0;
  g_pixel_scale = 1.0; g_inv_pixel_scale = 1.0; g_inv_weight_scale = 1.0;

  int n, n_high, n_lobe;
  count_samples(n, n_high, n_lobe);
  if (n == 0) {
    fits[v] = sentinel_fit();
    return;
  }
  const bool ks_free = n_high >= u_min_specular || n_lobe >= u_min_lobe;
  setup_linear(n, n_high, ks_free);

  const float alpha0 = clamp(u_alpha_init, u_alpha_min, u_alpha_max);
  float alpha = alpha0;
  Linear best = solve(alpha, ks_free);
  if (ks_free) {
    const float alpha_h = alpha_from_highlights(alpha0);
    if (alpha_h != alpha) {  // same alpha: same solution, not lower
      const Linear alt = solve(alpha_h, true);
      if (alt.energy < best.energy) best = alt, alpha = alpha_h;
    }
  }

  // LM-damped Newton on t = ln(alpha) with step rejection.
  int it = 0;
  bool converged = !ks_free;
  float damping = 1e-3;
  const float t_min = log(u_alpha_min), t_max = log(u_alpha_max);
  while (ks_free && it < u_max_iterations && !converged) {
    ++it;
    if (best.ks <= 0.0) {  // no specular term: alpha is irrelevant
      converged = true;
      break;
    }
    bool improved = false;
    for (int attempt = 0; attempt < 6 && !improved; ++attempt) {
      const float t = clamp(log(alpha) - best.grad / (best.curv * (1.0 + damping) + 1e-30), t_min, t_max);
      const float trial_alpha = clamp(exp(t), u_alpha_min, u_alpha_max);
      const Linear trial = solve(trial_alpha, true);
      if (trial.energy < best.energy) {
        const float gain = (best.energy - trial.energy) / max(best.energy, 1e-30);
        best = trial, alpha = trial_alpha, improved = true, damping = max(damping / 3.0, 1e-7);
        if (gain < u_tolerance) converged = true;
      } else {
        damping = min(damping * 4.0, 1e30);  // rejected: shorter, more gradient-like step
      }
    }
    if (!improved) converged = true;  // no damped step improves: at a (local) minimum
  }

  Fit f = store_linear(best, alpha);
  const uint status = f.ks > 0.0 ? kStatusFull : kStatusDiffuseOnly;
  f.bits = uint(min(it, 65535)) | (status << 16) | ((converged ? 1u : 0u) << 24);
  quality_metrics(f);
  fits[v] = f;
}
