#pragma once
// The material stage's per-vertex solves (materials.h): every vertex's k_s, alpha and k_d C under its
// material's lobe for a choice of priors, their held-out error, and the test that decides whether a
// glossy material's lobe is given to the vertices without one of their own.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fit/material_lobes.h"

namespace vbrdf {
namespace material_stage {

// Per-vertex parameters of a labelling, for one choice of priors: alpha = the material's alpha times
// 2^(k/4), k in [-8, 8] (only k = 0 when alpha_prior < 0), with a quadratic prior on ln alpha of
// weight alpha_prior x (the material's mean k_s information x k_s^2); k_s regularised towards the
// material's with weight prior x the mean information; rho re-solved exactly.
struct Choice {
  float prior;        // k_s prior strength
  float alpha_prior;  // < 0: the material's alpha only
};
constexpr int kAlphaSteps = 17, kAlphaCentre = 8;

struct Params {
  std::vector<double> ks, rho, alpha;  // rho: 3 per vertex
};

// For every choice, the error of its parameters (fitted on `fit_set`) at `score_set` (summed over
// the vertices), and, when `params` is given, the parameters of choice 0. `wanted` (may be null):
// per vertex, 0 = its parameters are not needed (skipped: its params and score stay 0; the priors'
// scale is still taken over every labelled vertex).
std::vector<double> solve_vertices(const Context &c, const std::vector<Static> &S_fit, const std::vector<Static> &S_score,
                                   int fit_set, int score_set, const std::vector<int32_t> &label,
                                   const std::vector<LobeFit> &lobes, const std::vector<uint8_t> &diffuse, int K,
                                   const std::vector<Choice> &choices, Params *params,
                                   const std::vector<uint8_t> *wanted = nullptr);

// Per material 1..K: 1 when it is diffuse (its pooled lobe's k_s below diffuse_ks_fraction of its
// median k_d, its alpha at or below min_lobe_alpha (4x for the N.H forms), or its energy gain below
// min_lobe_gain).
std::vector<uint8_t> diffuse_flags(const std::vector<LobeFit> &lobes, const std::vector<double> &median_kd, int K,
                                   const MaterialOptions &mo, LobeForm form);

// Per material 1..K: the median k_d of its vertices' own fits.
std::vector<double> median_kd_of(const Context &c, const std::vector<VertexFit> &fits, const std::vector<int32_t> &label, int K);

// One robust pass on k_d C with the lobe fixed (as the basic colour's, diffuse_color.h): samples
// whose residual exceeds 3 scaled MADs (shadow edges the depth passes miss) are dropped and rho is
// re-solved from the rest; unchanged when fewer than 4 samples remain.
void robust_rho(const Context &c, size_t v, double ks, double alpha, double rho[3]);

// Step 3's rule: a vertex of a glossy material whose own fit found a lobe keeps it (keep_full_fits).
bool keeps_own_fit(const MaterialOptions &mo, bool diffuse_material, const VertexFit &f);

// Whether a glossy material's lobe predicts the held-out photos of its vertices that have no lobe of
// their own better than no lobe does (the per-vertex fit's diffuse-only answer), in CIEDE2000 per
// held-out sample (clean and grazing) over step 1's subsample, the lobes refitted on the training
// photos of the final labels (MaterialOptions::min_giving_gain, giving_confidence). Only vertices
// that the training photos see (at least one training sample in the store) are judged: without
// one, both answers are guesses (no diffuse colour at all), and "a lobe beats black" is no evidence
// (with 4 photos of two cameras, most of one camera's vertices have only the held-out photo). Nor
// are vertices without a held-out sample: a paired difference of exactly 0 is no evidence either,
// and counted it pulls the mean towards "no gain".
struct GivingTest {
  double with_lobe = 0, without_lobe = 0;  // summed CIEDE2000 over the held-out samples
  double diff_sq = 0;  // sum over the vertices of (their summed CIEDE2000 with minus without)^2
  size_t vertices = 0;                     // judged subsample vertices without a lobe of their own
                                           //   (with a training and a held-out sample)
  size_t unjudged = 0;                     // such vertices without a training or a held-out sample (left out)
  size_t samples = 0;
  // Pools another split's test (the folds of heldout_folds.h): each (vertex, split) pair
  // is one paired difference.
  GivingTest &operator+=(const GivingTest &o) {
    with_lobe += o.with_lobe, without_lobe += o.without_lobe, diff_sq += o.diff_sq;
    vertices += o.vertices, unjudged += o.unjudged, samples += o.samples;
    return *this;
  }
  double mean_with() const { return samples ? with_lobe / double(samples) : 0; }
  double mean_without() const { return samples ? without_lobe / double(samples) : 0; }
  // Mean per-vertex difference (with minus without) and its standard error (0 for fewer than two vertices).
  double mean_difference() const { return vertices ? (with_lobe - without_lobe) / double(vertices) : 0; }
  double standard_error() const {
    if (vertices < 2) return 0;
    const double n = double(vertices), mean = mean_difference();
    return std::sqrt(std::max(0.0, diff_sq / n - mean * mean) / (n - 1));
  }
  // With no vertex to judge: given only when there was none to give to (no evidence is no gain).
  bool gives(const MaterialOptions &mo) const {
    if (vertices == 0) return unjudged == 0;
    if (vertices < 2) return false;
    return with_lobe < (1 - double(mo.min_giving_gain)) * without_lobe &&
           mean_difference() + double(mo.giving_confidence) * standard_error() < 0;
  }
};
std::vector<GivingTest> test_giving(const Context &sel, const std::vector<Static> &S_train, const std::vector<int32_t> &label,
                                    const std::vector<uint8_t> &diffuse, int K, const Choice &choice,
                                    const std::vector<VertexFit> &fits);

} // namespace material_stage
} // namespace vbrdf
