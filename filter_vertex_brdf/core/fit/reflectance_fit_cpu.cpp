#include "fit/reflectance_fit.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace vbrdf {

namespace {

struct FitSample {
  double p[3];
  double d, s, w;
  bool highlight;
  double ln_s = 0;  // ln(min(s, 1)) where s > 0 (with_ln_s): the lobe's iterations need no log
  double v = 0;     // Sample::footprint: the GGX lobe is seen through it (lobe.h), clamped (with_ln_s)
  double u = 1;     // 1 - min(s, 1)^2 where s > 0 (with_ln_s): GGX's variable
};

// The lobe g(s, alpha) of the form for a fit sample (model/lobe.h lobe_value, the same values up
// to rounding); power forms from its stored logarithm (bit for bit lobe_value's); `a2`: ggx_a2(alpha),
// once per alpha for the many samples of a vertex.
inline double lobe(LobeForm form, const FitSample &x, double alpha, double a2) {
  if (!(x.s > 0)) return 0.0;
  if (!lobe_is_power(form)) return ggx_lobe_through_clamped_footprint(x.u, a2, x.v);
  return std::exp(std::max(alpha * x.ln_s, kLobeLogFloor));
}

inline FitSample with_ln_s(FitSample x) {
  if (x.s > 0) x.ln_s = std::log(std::min(x.s, 1.0)), x.u = 1 - std::min(x.s, 1.0) * std::min(x.s, 1.0);
  x.v = clamped_footprint(x.v);
  return x;
}

struct Linear {
  double rho[3] = {0, 0, 0};
  double ks = 0;
  double energy = 0;
};

class VertexProblem {
public:
  VertexProblem(const std::vector<FitSample> &samples, const double rho0[3], double prior, LobeForm form)
      : samples_(samples), prior_(prior), form_(form) {
    for (int c = 0; c < 3; ++c) rho0_[c] = rho0[c];
    for (const FitSample &x : samples_) {
      a_ += x.w * x.d * x.d;
      for (int c = 0; c < 3; ++c) p_[c] += x.w * x.d * x.p[c];
    }
    a_ += prior_;  // prior_ already multiplied by the total weight
    for (int c = 0; c < 3; ++c) p_[c] += prior_ * rho0_[c];
  }

  // Exact non-negative least squares in (rho, k_s) for a fixed alpha (ks_free = false: k_s = 0).
  Linear solve(double alpha, bool ks_free, const ReflectanceFitOptions &o) const {
    double b = 0, g2 = 0, q[3] = {0, 0, 0};
    lobes_.resize(samples_.size());  // kept for the energy below: one exponential per sample
    const double a2 = ggx_a2(alpha);
    if (ks_free)
      for (size_t i = 0; i < samples_.size(); ++i) {
        const FitSample &x = samples_[i];
        const double g = lobes_[i] = lobe(form_, x, alpha, a2);
        b += x.w * x.d * g;
        g2 += x.w * g * g;
        for (int c = 0; c < 3; ++c) q[c] += x.w * g * x.p[c];
      }
    Linear L;
    bool fixed[3] = {false, false, false};
    for (int pass = 0; pass < 4; ++pass) {
      // k_s equation after eliminating the free rho_c = (p_c - B k_s) / A.
      double num = 0, den = 3 * g2;
      int free_count = 0;
      for (int c = 0; c < 3; ++c) {
        num += q[c];
        if (!fixed[c]) num -= b * p_[c] / a_, den -= b * b / a_, ++free_count;
      }
      // Singular (g ~ 0, or g proportional to d): no specular discrimination, k_s = 0.
      L.ks = (ks_free && den > 1e-9 * (3 * g2 + 1e-30)) ? std::max(0.0, num / den) : 0.0;
      bool changed = false;
      for (int c = 0; c < 3; ++c) {
        if (fixed[c]) continue;
        L.rho[c] = (p_[c] - b * L.ks) / a_;
        if (L.rho[c] < 0) L.rho[c] = 0, fixed[c] = true, changed = true;
      }
      if (!changed || free_count == 0) break;
    }
    for (int c = 0; c < 3; ++c) L.rho[c] = std::min(L.rho[c], double(o.kd_max));
    L.ks = std::min(L.ks, double(o.ks_max));
    L.energy = energy(L, ks_free ? lobes_.data() : nullptr);
    return L;
  }

  // The objective for L; `lobes`: s^alpha per sample (may be null when L.ks = 0).
  double energy(const Linear &L, const double *lobes) const {
    double e = 0;
    for (size_t i = 0; i < samples_.size(); ++i) {
      const FitSample &x = samples_[i];
      const double g = L.ks > 0 ? L.ks * lobes[i] : 0;
      for (int c = 0; c < 3; ++c) {
        const double r = x.p[c] - L.rho[c] * x.d - g;
        e += x.w * r * r;
      }
    }
    for (int c = 0; c < 3; ++c) e += prior_ * (L.rho[c] - rho0_[c]) * (L.rho[c] - rho0_[c]);
    return e;
  }

  // Gradient and Gauss-Newton curvature of the objective in t = ln(alpha) at fixed linear
  // parameters (envelope theorem: the linear parameters are optimal).
  void derivatives(const Linear &L, double alpha, double &grad, double &curv) const {
    grad = curv = 0;
    const double a2 = ggx_a2(alpha);
    for (const FitSample &x : samples_) {
      if (!(x.s > 0) || (x.s >= 1 && !(x.v > 0))) continue;
      const double g = lobe(form_, x, alpha, a2);
      const double dg = L.ks * (lobe_is_power(form_) ? g * x.ln_s * alpha  // d(k_s g)/dt
                                                     : lobe_dvalue_dlog_alpha(form_, x.s, alpha, x.v));
      for (int c = 0; c < 3; ++c) {
        const double r = x.p[c] - L.rho[c] * x.d - L.ks * g;
        grad += -2 * x.w * r * dg;
        curv += 2 * x.w * dg * dg;
      }
    }
  }

private:
  const std::vector<FitSample> &samples_;
  double rho0_[3];
  double prior_;
  LobeForm form_;
  double a_ = 0, p_[3] = {0, 0, 0};
  mutable std::vector<double> lobes_;  // g(s, alpha) of the last solve's alpha
};

// Thesis 4.5-style initial shininess: ln(P - rho0 d) = ln k_s + alpha ln s over highlight samples.
double alpha_from_highlights(const std::vector<FitSample> &samples, const double rho0[3], const ReflectanceFitOptions &o) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (const FitSample &x : samples) {
    if (!x.highlight || !(x.s > 0) || x.s >= 1) continue;
    const double excess = (x.p[0] + x.p[1] + x.p[2] - (rho0[0] + rho0[1] + rho0[2]) * x.d) / 3;
    if (!(excess > 1e-4)) continue;
    const double lx = x.ln_s, ly = std::log(excess);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly, ++n;
  }
  const double var = sxx - sx * sx / std::max(n, 1);
  const double slope = (n < 2 || var < 1e-10) ? double(o.alpha_init) : (sxy - sx * sy / n) / var;
  return std::min(std::max(slope, double(o.alpha_min)), double(o.alpha_max));
}

void diffuse_only_estimate(const std::vector<FitSample> &samples, double rho0[3]) {
  double dd = 0, dp[3] = {0, 0, 0}, dd_all = 0, dp_all[3] = {0, 0, 0};
  for (const FitSample &x : samples) {
    dd_all += x.w * x.d * x.d;
    for (int c = 0; c < 3; ++c) dp_all[c] += x.w * x.d * x.p[c];
    if (x.highlight) continue;
    dd += x.w * x.d * x.d;
    for (int c = 0; c < 3; ++c) dp[c] += x.w * x.d * x.p[c];
  }
  // Without any non-highlight sample, fall back to all samples.
  const bool use_all = !(dd > 0);
  for (int c = 0; c < 3; ++c)
    rho0[c] = std::max(0.0, (use_all ? dp_all[c] / std::max(dd_all, 1e-30) : dp[c] / dd));
}

void quality_metrics(const std::vector<FitSample> &samples, const VertexFit &fit, LobeForm form, VertexFit &out) {
  // Thesis 4.7.1: mean sampling term + (1 - mean weighted error / |white|^2), in [0, 2].
  double dq_term = 0, dq_err = 0, sq_term = 0, sq_err = 0, e = 0, w = 0;
  int nd = 0, ns = 0;
  for (const FitSample &x : samples) {
    float f[3];
    evaluate_reflectance(fit, float(x.d), float(x.s), form, f, float(x.v));
    double err2 = 0;
    for (int c = 0; c < 3; ++c) err2 += (x.p[c] - f[c]) * (x.p[c] - f[c]);
    e += x.w * err2, w += x.w;
    const double s_re = lobe_as_r_dot_e(form, float(x.s));  // the thesis's R.E sampling term
    if (x.highlight) sq_term += s_re, sq_err += s_re * err2 / 3.0, ++ns;
    else dq_term += x.d, dq_err += x.d * err2 / 3.0, ++nd;
  }
  auto quality = [](double term, double err, int n) {
    return n ? float(std::min(2.0, std::max(0.0, term / n + 1.0 - std::min(1.0, err / n)))) : 0.0f;
  };
  out.dq = quality(dq_term, dq_err, nd);
  out.sq = quality(sq_term, sq_err, ns);
  out.rmse = w > 0 ? float(std::sqrt(e / (3 * w))) : 0.0f;
}

void set_sentinels(VertexFit &out) {
  out = VertexFit{{0, 0, 0}, 0, 0, 0, 0, 0, 0, 0, kFitNone, 0};
}

void store_linear(const Linear &L, double alpha, VertexFit &out) {
  set_kd_color(L.rho, out);
  out.ks = float(L.ks);
  out.shininess = out.ks > 0 ? float(alpha) : 0.0f;  // decided on the stored (float) k_s
}

} // namespace

namespace {
// The fit's usable samples (see reflectance_fit.h); returns the number of highlight samples.
// `weak`: the fallback rules (fit_vertex_weak): grazing samples kept, mixed ones down-weighted.
int usable_samples(const Sample *in, size_t count, const ReflectanceFitOptions &o, std::vector<FitSample> &samples,
                   double &w_high, double &w_other, bool weak = false) {
  samples.clear();
  samples.reserve(count);
  w_high = w_other = 0;
  int n_high = 0;
  for (size_t i = 0; i < count; ++i) {
    const Sample &s = in[i];
    if ((s.flags & (kShadowed | kSaturated | kNotSeen)) || !(s.d > 0)) continue;
    if ((s.flags & kMixedPixel) && !weak) continue;
    // Grazing light (N.L < T_d) is as unreliable for the fit as for the basic colour (normal
    // errors, shading-model breakdown); a grazing highlight is still specular evidence.
    if ((s.flags & kGrazing) && !(s.flags & kHighlight) && !weak) continue;
    if (!std::isfinite(s.rgb[0]) || !std::isfinite(s.rgb[1]) || !std::isfinite(s.rgb[2]) || !std::isfinite(s.lobe_cos) ||
        !std::isfinite(s.d))
      continue;  // a corrupt sample is not evidence
    const double w =
        s.d * double(resolution_weight(s)) * ((s.flags & kMixedPixel) ? double(o.mixed_sample_weight) : 1.0);
    FitSample x{{s.rgb[0], s.rgb[1], s.rgb[2]}, std::min<double>(s.d, 1.0), s.lobe_cos, w,
                s.lobe_cos > lobe_threshold(o.lobe, o.specular_threshold)};
    (x.highlight ? w_high : w_other) += x.w;
    n_high += x.highlight;
    x.v = s.footprint;
    samples.push_back(with_ln_s(x));
  }
  return n_high;
}
} // namespace

void set_diffuse_only_reflectance(const Sample *in, size_t count, const ReflectanceFitOptions &o, const float rho[3],
                                  VertexFit &out) {
  std::vector<FitSample> samples;
  double w_high, w_other;
  usable_samples(in, count, o, samples, w_high, w_other);
  Linear L;
  for (int c = 0; c < 3; ++c) L.rho[c] = std::min(std::max(double(rho[c]), 0.0), double(o.kd_max));
  store_linear(L, 0, out);
  out.status = kFitDiffuseOnly;
  quality_metrics(samples, out, o.lobe, out);
}

namespace {
void fit_vertex(const Sample *in, size_t count, const ReflectanceFitOptions &o, bool weak, VertexFit &out) {
  set_sentinels(out);
  std::vector<FitSample> samples;
  double w_high, w_other;
  const int n_high = usable_samples(in, count, o, samples, w_high, w_other, weak);
  if (samples.empty() || !(w_high + w_other > 0)) return;
  // Remedy 1: highlight samples may not outweigh the rest.
  if (w_other > 0 && w_high > o.specular_weight_cap * w_other) {
    const double scale = o.specular_weight_cap * w_other / w_high;
    for (FitSample &x : samples)
      if (x.highlight) x.w *= scale;
  }
  int n_lobe = 0;
  const double broad = lobe_threshold(o.lobe, o.lobe_threshold);
  for (const FitSample &x : samples) n_lobe += x.s > broad;
  const bool ks_free = n_high >= o.min_specular_samples || n_lobe >= o.min_lobe_samples;
  // Remedy 3: too little specular evidence to free k_s and alpha: the few highlight samples
  // cannot be explained by a diffuse-only model, so they are left out (if anything else remains).
  if (!ks_free && n_high > 0 && size_t(n_high) < samples.size())
    samples.erase(std::remove_if(samples.begin(), samples.end(), [](const FitSample &x) { return x.highlight; }),
                  samples.end());
  double total_w = 0;
  for (const FitSample &x : samples) total_w += x.w;

  double rho0[3];
  diffuse_only_estimate(samples, rho0);
  const VertexProblem problem(samples, rho0, o.diffuse_prior * total_w, o.lobe);

  double alpha = std::min(std::max(double(o.alpha_init), double(o.alpha_min)), double(o.alpha_max));
  Linear best = problem.solve(alpha, ks_free, o);
  if (ks_free) {
    const double alpha_h = alpha_from_highlights(samples, rho0, o);
    const Linear alt = problem.solve(alpha_h, true, o);
    if (alt.energy < best.energy) best = alt, alpha = alpha_h;
  }

  // Scale of the data (objective of the zero model): floors below are relative to it, so that
  // the stopping rule does not depend on the photos' absolute brightness.
  const double data_energy = problem.energy(Linear(), nullptr) + 1e-300;
  int it = 0;
  bool converged = !ks_free;
  double damping = 1e-3;
  const double t_min = std::log(double(o.alpha_min)), t_max = std::log(double(o.alpha_max));
  while (ks_free && it < o.max_iterations && !converged) {
    ++it;
    if (best.ks <= 0) {  // no specular term: alpha is irrelevant, nothing to optimise
      converged = true;
      break;
    }
    double grad, curv;
    problem.derivatives(best, alpha, grad, curv);
    bool improved = false;
    for (int attempt = 0; attempt < 6 && !improved; ++attempt) {
      const double t =
          std::min(std::max(std::log(alpha) - grad / (curv * (1 + damping) + 1e-30 * data_energy), t_min), t_max);
      const double trial_alpha = std::exp(t);
      const Linear trial = problem.solve(trial_alpha, true, o);
      if (trial.energy < best.energy) {
        const double gain = (best.energy - trial.energy) / std::max(best.energy, 1e-14 * data_energy);
        best = trial, alpha = trial_alpha, improved = true, damping = std::max(damping / 3, 1e-7);
        if (gain < o.tolerance) converged = true;
      } else {
        damping *= 4;  // step rejected: shorter, more gradient-like step
      }
    }
    if (!improved) converged = true;  // no damped step improves: at a (local) minimum
  }

  store_linear(best, alpha, out);
  out.status = out.ks > 0 ? kFitFull : kFitDiffuseOnly;
  out.iterations = uint16_t(it);
  out.converged = converged ? 1 : 0;
  quality_metrics(samples, out, o.lobe, out);
}
} // namespace

void fit_vertex_cpu(const Sample *in, size_t count, const ReflectanceFitOptions &o, VertexFit &out) {
  fit_vertex(in, count, o, false, out);
}

void fit_vertex_weak(const Sample *in, size_t count, const ReflectanceFitOptions &o, VertexFit &out) {
  fit_vertex(in, count, o, true, out);
  if (out.status == kFitNone) return;
  out.status = kFitFromWeakSamples;
  out.dq *= 0.5f;
  out.sq *= 0.5f;
}

void recompute_fit_quality(const Sample *in, size_t count, const ReflectanceFitOptions &o, bool weak, VertexFit &fit) {
  std::vector<FitSample> samples;
  double w_high, w_other;
  usable_samples(in, count, o, samples, w_high, w_other, weak);
  quality_metrics(samples, fit, o.lobe, fit);
  if (weak) fit.dq *= 0.5f, fit.sq *= 0.5f;
}

void fit_chunk_cpu(const SampleChunk &chunk, const ReflectanceFitOptions &options, VertexFit *out) {
#pragma omp parallel for schedule(dynamic, 256)
  for (long long i = 0; i < (long long)chunk.vertex_count; ++i) {
    const uint32_t begin = chunk.offsets[size_t(i)], end = chunk.offsets[size_t(i) + 1];
    fit_vertex_cpu(chunk.samples.data() + begin, end - begin, options, out[i]);
  }
}

} // namespace vbrdf
