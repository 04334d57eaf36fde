#include "fit/material_solve.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/color_difference.h"

namespace vbrdf {
namespace material_stage {

namespace {

// Per material, its vertices' mean k_s information at the material's alpha: the scale of both priors.
std::vector<double> mean_ks_information(const Context &c, const std::vector<Static> &S_fit, int fit_set,
                                        const std::vector<int32_t> &label, const std::vector<LobeFit> &lobes, int K) {
  std::vector<double> alpha_of(size_t(K) + 1, 1.0);
  for (int m = 1; m <= K; ++m) alpha_of[size_t(m)] = lobes[size_t(m)].alpha;
  const std::vector<Lobe> L0 = lobe_sums(c, fit_set, label, alpha_of);
  std::vector<double> mean_info(size_t(K) + 1, 0), cnt(size_t(K) + 1, 0);
  for (uint32_t v : c.verts) {
    if (label[v] <= 0) continue;
    double info, rhs;
    ks_equation(S_fit[v], L0[v], info, rhs);
    if (info > 0) mean_info[size_t(label[v])] += info, cnt[size_t(label[v])] += 1;
  }
  for (int m = 1; m <= K; ++m) mean_info[size_t(m)] = cnt[size_t(m)] > 0 ? mean_info[size_t(m)] / cnt[size_t(m)] : 0;
  return mean_info;
}

// The choices' distinct k_s priors, in order of first use; prior_index receives each choice's.
std::vector<double> distinct_priors(const std::vector<Choice> &choices, std::vector<size_t> &prior_index) {
  std::vector<double> priors;
  prior_index.assign(choices.size(), 0);
  for (size_t ch = 0; ch < choices.size(); ++ch) {
    const auto it = std::find(priors.begin(), priors.end(), double(choices[ch].prior));
    prior_index[ch] = size_t(it - priors.begin());
    if (it == priors.end()) priors.push_back(double(choices[ch].prior));
  }
  return priors;
}

} // namespace

std::vector<double> solve_vertices(const Context &c, const std::vector<Static> &S_fit, const std::vector<Static> &S_score,
                                   int fit_set, int score_set, const std::vector<int32_t> &label,
                                   const std::vector<LobeFit> &lobes, const std::vector<uint8_t> &diffuse, int K,
                                   const std::vector<Choice> &choices, Params *params,
                                   const std::vector<uint8_t> *wanted) {
  const std::vector<double> mean_info = mean_ks_information(c, S_fit, fit_set, label, lobes, K);
  const size_t nc = choices.size();
  std::vector<size_t> prior_index;
  const std::vector<double> priors = distinct_priors(choices, prior_index);
  // Only the material's own alpha (k = kAlphaCentre) is needed when no choice has a per-vertex alpha.
  const bool same_sets = fit_set == score_set;  // then the score's lobe sums are the fit's
  const bool centre_only = std::all_of(choices.begin(), choices.end(), [](const Choice &ch) { return ch.alpha_prior < 0; });
  std::vector<double> score(c.verts.size() * nc, 0.0);  // by position in c.verts
  if (params) params->ks.assign(c.n, 0), params->rho.assign(3 * c.n, 0), params->alpha.assign(c.n, 0);
  const auto &E = c.store.entries();
#pragma omp parallel for schedule(dynamic, 256) if (c.store.entries().size() > 200000)
  for (long long t = 0; t < (long long)c.verts.size(); ++t) {
    const size_t v = c.verts[size_t(t)];
    if (label[v] <= 0 || (wanted && !(*wanted)[v])) continue;
    const size_t m = size_t(label[v]);
    if (diffuse[m]) {
      double rho[3];
      energy_ks(S_fit[v], Lobe(), 0, rho);
      const double e = energy_fixed(S_score[v], Lobe(), 0, rho);
      for (size_t ch = 0; ch < nc; ++ch) score[size_t(t) * nc + ch] = e;
      if (params) std::copy(rho, rho + 3, &params->rho[3 * v]);
      continue;
    }
    Lobe Lf[kAlphaSteps], Ls[kAlphaSteps];
    double alpha[kAlphaSteps];
    LobeAt lobe[kAlphaSteps];
    bool doubling = !c.ggx;  // alpha[k + 4] = 2 alpha[k] everywhere (no bound clipped one), power form
    for (int k = 0; k < kAlphaSteps; ++k) {
      const double a = lobes[m].alpha * std::pow(2.0, (k - kAlphaCentre) / 4.0);
      alpha[k] = std::min(std::max(a, double(c.o.alpha_min)), double(c.o.alpha_max));
      lobe[k] = LobeAt(alpha[k], c.ggx);
      doubling = doubling && alpha[k] == a;
    }
    const int k_first = centre_only ? kAlphaCentre : 0, k_last = centre_only ? kAlphaCentre : kAlphaSteps - 1;
    double log_ratio[kAlphaSteps];  // ln(alpha / the material's alpha): the alpha prior's variable
    for (int k = k_first; k <= k_last; ++k) log_ratio[k] = std::log(alpha[k] / lobes[m].alpha);
    double g_of[kAlphaSteps] = {};
    // Lobe sums at every alpha of the fit and of the score samples (add_to_lobes).
    double fit_sums[5 * kAlphaSteps] = {}, score_sums[5 * kAlphaSteps] = {};
    double a2[kAlphaSteps];
    for (int k = 0; k < kAlphaSteps; ++k) a2[k] = lobe[k].a2;
    for (uint64_t i = c.store.first(v); i < c.store.last(v); ++i) {
      const Entry &e = E[i];
      const bool f = c.in_set(e, fit_set), sc = c.in_set(e, score_set);
      const float key = (*c.lobe_keys)[i];
      if ((!f && !sc) || key > 0) continue;
      if (c.ggx) {
        const double u = -double(key);
        const double vc = clamped_footprint(e.v);
        for (int k = k_first; k <= k_last; ++k) g_of[k] = ggx_lobe_through_clamped_footprint(u, a2[k], vc);
      } else if (doubling && !centre_only) {  // 4 exponentials, the rest by squaring: s^(2 alpha) = (s^alpha)^2
        for (int k = 0; k < 4; ++k) g_of[k] = lobe[k](key, e.v);
        for (int k = 4; k < kAlphaSteps; ++k) g_of[k] = square_lobe(g_of[k - 4]);
      } else {
        for (int k = k_first; k <= k_last; ++k) g_of[k] = lobe[k](key, e.v);
      }
      if (f) add_to_lobes(fit_sums, kAlphaSteps, e, g_of, size_t(k_first), size_t(k_last));
      if (sc && !same_sets) add_to_lobes(score_sums, kAlphaSteps, e, g_of, size_t(k_first), size_t(k_last));
    }
    for (int k = k_first; k <= k_last; ++k)
      Lf[k] = lobe_from_sums(fit_sums, kAlphaSteps, size_t(k)), Ls[k] = lobe_from_sums(score_sums, kAlphaSteps, size_t(k));
    // k_s and the objective without the alpha prior depend on a choice's k_s prior only: computed once
    // per distinct prior and alpha, then each choice adds its alpha prior (the same arithmetic).
    double info[kAlphaSteps], rhs[kAlphaSteps];
    for (int k = k_first; k <= k_last; ++k) ks_equation(S_fit[v], Lf[k], info[k], rhs[k]);
    for (size_t p = 0; p < priors.size(); ++p) {
      const double lambda = priors[p] * mean_info[m];
      double ks_of[kAlphaSteps], base[kAlphaSteps];
      for (int k = k_first; k <= k_last; ++k) {
        double ks = info[k] + lambda > 0 ? (rhs[k] + lambda * lobes[m].ks) / (info[k] + lambda) : lobes[m].ks;
        ks = std::min(std::max(ks, 0.0), double(c.o.ks_max));
        ks_of[k] = ks;
        base[k] = energy_ks(S_fit[v], Lf[k], ks) + lambda * (ks - lobes[m].ks) * (ks - lobes[m].ks);
      }
      for (size_t ch = 0; ch < nc; ++ch) {
        if (prior_index[ch] != p) continue;
        const double mu = choices[ch].alpha_prior * mean_info[m] * lobes[m].ks * lobes[m].ks;
        int best_k = kAlphaCentre;
        double best_obj = 1e300;
        for (int k = k_first; k <= k_last; ++k) {
          if (choices[ch].alpha_prior < 0 && k != kAlphaCentre) continue;
          const double t = log_ratio[k];
          const double obj = base[k] + std::max(0.0, double(mu)) * t * t;
          if (obj < best_obj) best_obj = obj, best_k = k;
        }
        const double best_ks = ks_of[best_k];
        double rho[3];
        energy_ks(S_fit[v], Lf[best_k], best_ks, rho);
        score[size_t(t) * nc + ch] = energy_fixed(S_score[v], same_sets ? Lf[best_k] : Ls[best_k], best_ks, rho);
        if (params && ch == 0) {
          params->ks[v] = best_ks, params->alpha[v] = alpha[best_k];
          std::copy(rho, rho + 3, &params->rho[3 * v]);
        }
      }
    }
  }
  std::vector<double> total(nc, 0.0);
  for (size_t t = 0; t < c.verts.size(); ++t)
    if (S_fit[c.verts[t]].n > 0)
      for (size_t ch = 0; ch < nc; ++ch) total[ch] += score[t * nc + ch];
  return total;
}

std::vector<uint8_t> diffuse_flags(const std::vector<LobeFit> &lobes, const std::vector<double> &median_kd, int K,
                                   const MaterialOptions &mo, LobeForm form) {
  std::vector<uint8_t> d(size_t(K) + 1, 0);
  // min_lobe_alpha is stated on R.E; an N.H exponent is about 4 times the R.E one for one lobe.
  const double min_alpha = mo.min_lobe_alpha * (form != LobeForm::PhongRE ? 4.0 : 1.0);
  for (int m = 1; m <= K; ++m) {
    const LobeFit &L = lobes[size_t(m)];
    const double gain = L.energy_zero > 0 ? (L.energy_zero - L.energy) / L.energy_zero : 0.0;
    d[size_t(m)] = L.ks <= mo.diffuse_ks_fraction * median_kd[size_t(m)] || L.alpha <= min_alpha || gain < mo.min_lobe_gain;
  }
  return d;
}

std::vector<double> median_kd_of(const Context &c, const std::vector<VertexFit> &fits, const std::vector<int32_t> &label, int K) {
  std::vector<std::vector<double>> kd(size_t(K) + 1);
  for (uint32_t v : c.verts)
    if (label[v] > 0) kd[size_t(label[v])].push_back(fits[v].kd);
  std::vector<double> out(size_t(K) + 1, 0);
  for (int m = 1; m <= K; ++m) out[size_t(m)] = median_of(kd[size_t(m)]);
  return out;
}

void robust_rho(const Context &c, size_t v, double ks, double alpha, double rho[3]) {
  const auto &E = c.store.entries();
  const LobeAt lobe(alpha, c.ggx);
  std::vector<double> res;
  for (uint64_t i = c.store.first(v); i < c.store.last(v); ++i) {
    const Entry &e = E[i];
    const double g = ks > 0 ? ks * lobe((*c.lobe_keys)[i], e.v) : 0.0;
    double r = 0;
    for (int ch = 0; ch < 3; ++ch) r += std::fabs(e.rgb[ch] - rho[ch] * e.d - g);
    res.push_back(r / 3);
  }
  if (res.size() < 6) return;
  std::vector<double> sorted = res;
  const double med = median_of(sorted);
  for (double &x : sorted) x = std::fabs(x - med);
  const double mad = 1.4826 * median_of(sorted);
  if (!(mad > 0)) return;
  double a = 0, p[3] = {0, 0, 0};
  size_t kept = 0;
  for (uint64_t i = c.store.first(v), j = 0; i < c.store.last(v); ++i, ++j) {
    if (std::fabs(res[j] - med) > 3 * mad) continue;
    const Entry &e = E[i];
    const double g = ks > 0 ? ks * lobe((*c.lobe_keys)[i], e.v) : 0.0;
    a += double(e.w) * e.d * e.d;
    for (int ch = 0; ch < 3; ++ch) p[ch] += double(e.w) * e.d * (e.rgb[ch] - g);
    ++kept;
  }
  if (kept < 4 || !(a > 0)) return;
  for (int ch = 0; ch < 3; ++ch) rho[ch] = std::max(0.0, p[ch] / a);
}

bool keeps_own_fit(const MaterialOptions &mo, bool diffuse_material, const VertexFit &f) {
  return mo.keep_full_fits && !diffuse_material && f.status == kFitFull && f.ks > 0;
}

std::vector<GivingTest> test_giving(const Context &sel, const std::vector<Static> &S_train, const std::vector<int32_t> &label,
                                    const std::vector<uint8_t> &diffuse, int K, const Choice &choice,
                                    const std::vector<VertexFit> &fits) {
  const std::vector<LobeFit> train_lobes = fit_lobes(sel, kTrain, S_train, label, K);
  const MaterialSampleStore &store = sel.store;
  auto has_heldout_sample = [&](uint32_t v) {
    for (uint64_t k = store.first(v); k < store.last(v); ++k)
      if (sel.in_set(store.entries()[k], kHeld)) return true;
    for (uint64_t k = store.grazing_first(v); k < store.grazing_last(v); ++k)
      if (sel.in_set(store.grazing_entries()[k], kHeld)) return true;
    return false;
  };
  // The vertices without a lobe of their own; of them, those both sides of the split see are judged.
  std::vector<GivingTest> out(size_t(K) + 1);
  std::vector<uint8_t> tested(sel.n, 0);
  for (uint32_t v : sel.verts) {
    const int32_t m = label[v];
    if (m <= 0 || diffuse[size_t(m)] || keeps_own_fit(sel.mo, false, fits[v])) continue;
    if (S_train[v].n > 0 && has_heldout_sample(v))
      tested[v] = 1;
    else
      ++out[size_t(m)].unjudged;
  }
  Params P;  // with the lobe (the chosen priors), fitted on the training photos
  solve_vertices(sel, S_train, S_train, kTrain, kTrain, label, train_lobes, diffuse, K, {choice}, &P, &tested);
  for (uint32_t v : sel.verts) {
    if (!tested[v]) continue;
    double rho[3];  // without a lobe: the diffuse-only least squares on the training photos
    energy_ks(S_train[v], Lobe(), 0, rho);
    const LobeAt lobe(P.alpha[v], sel.ggx);
    GivingTest &g = out[size_t(label[v])];
    double with_sum = 0, without_sum = 0;
    auto score = [&](const Entry &e, float key) {
      if (!sel.in_set(e, kHeld)) return;
      const double gk = lobe(key, e.v);
      float with[3], without[3];
      for (int ch = 0; ch < 3; ++ch) {
        with[ch] = float(P.rho[3 * v + size_t(ch)] * e.d + P.ks[v] * gk);
        without[ch] = float(rho[ch] * e.d);
      }
      with_sum += delta_e2000_linear_srgb(with, e.rgb), without_sum += delta_e2000_linear_srgb(without, e.rgb);
      ++g.samples;
    };
    for (uint64_t k = store.first(v); k < store.last(v); ++k) score(store.entries()[k], (*sel.lobe_keys)[k]);
    for (uint64_t k = store.grazing_first(v); k < store.grazing_last(v); ++k)
      score(store.grazing_entries()[k], lobe_key(store.grazing_entries()[k].s, sel.ggx));
    g.with_lobe += with_sum, g.without_lobe += without_sum;
    g.diff_sq += (with_sum - without_sum) * (with_sum - without_sum);
    ++g.vertices;
  }
  return out;
}

} // namespace material_stage
} // namespace vbrdf
