#pragma once
// The material stage's shared vocabulary (materials.h; internal to core/fit/material_*.cpp and
// materials.cpp): the context the stage runs in, the per-vertex sums of its samples that the pooled
// lobe fits, the labelling and the per-vertex solves share, and the closed forms on those sums.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "base/mesh_adjacency.h"
#include "fit/label_spread.h"
#include "fit/material_samples.h"
#include "fit/materials.h"
#include "model/lobe.h"

namespace vbrdf {
namespace material_stage {

using Entry = MaterialSampleStore::Entry;
enum SampleSet { kAll = 0, kTrain = 1, kHeld = 2 };

// Per-vertex sums that do not depend on the lobe: a = sum w d^2, p_c = sum w d P_c, pp_c = sum w P_c^2.
struct Static {
  double a = 0, p[3] = {0, 0, 0}, pp[3] = {0, 0, 0};
  uint32_t n = 0, n_high = 0;
  uint32_t n_flank = 0;  // samples in the lobe's flank (MaterialOptions::deciding_flank)
};
// Lobe sums at one alpha: b = sum w d g, g2 = sum w g^2, q_c = sum w g P_c, g = the lobe g(s, alpha).
struct Lobe {
  double b = 0, g2 = 0, q[3] = {0, 0, 0};
};

struct Context {
  const MaterialSampleStore &store;
  const ReflectanceFitOptions &o;
  const MaterialOptions &mo;
  // Per entry, the lobe's key x (lobe_key): +1 for s <= 0 (no lobe); else ln(min(s, 1)) for the
  // power forms, -(1 - s^2) for GGX (both <= 0).
  const std::vector<float> *lobe_keys = nullptr;
  std::vector<uint8_t> eligible;  // per vertex: refitted by the material stage
  std::vector<uint32_t> verts;    // the eligible vertices, ascending (the loops visit only these:
                                  // on a subsample 3 000 of 100 k)
  size_t n = 0;
  bool subsampled = false;    // eligible is a subsample of the stage's vertices (selection_subsample)
  bool ggx = false;  // o.lobe == GgxNH: lobe_of evaluates GGX, and no (s^alpha)^2 shortcut
  const std::vector<uint32_t> *component = nullptr;  // per mesh vertex, its connected component
  uint32_t component_count = 0;
  SpreadRingCache *rings = nullptr;  // spread_labels' rings for this context's vertices (one cache per context)
  // Lobe sums buffers of c.n entries reused by the calls of fit_lobes and assign_labels (never both
  // at once): lobe_sums_at then writes only the entries it computes (one pool per context).
  std::vector<std::vector<Lobe>> *lobe_buffers = nullptr;

  // Per raster index (Entry::raster is 16 bits): 1 when it is held out in this context's fold
  // (heldout_folds.h), filled by fit_materials; a table, not a division per sample in the loops.
  const std::vector<uint8_t> *held_raster = nullptr;

  bool in_set(const Entry &e, int set) const {
    if (set == kAll) return true;
    const bool held = (*held_raster)[e.raster] != 0;
    return set == kHeld ? held : !held;
  }
};

// The entry key of Context::lobe_keys for a lobe cosine s.
inline float lobe_key(float s, bool ggx) {
  if (!(s > 0)) return 1.0f;
  s = std::min(s, 1.0f);
  return ggx ? -(1.0f - s * s) : std::log(s);
}

// The lobe g(s, alpha) at one alpha from entry keys (model/lobe.h lobe_value, the same values);
// GGX's a^2 is computed once for the many samples a loop evaluates at that alpha.
struct LobeAt {
  double alpha = 1, a2 = 1;
  bool ggx = false;
  LobeAt() = default;
  LobeAt(double alpha_, bool ggx_) : alpha(alpha_), a2(ggx_a2(alpha_)), ggx(ggx_) {}
  // footprint: the entry's v (Entry::v), GGX only (lobe.h ggx_lobe_through_footprint).
  double operator()(float key, float footprint) const {
    if (key > 0) return 0;
    if (ggx) return ggx_lobe_through_footprint(-double(key), a2, footprint);
    return std::exp(std::max(alpha * double(key), kLobeLogFloor));
  }
};
inline double lobe_of(float key, double alpha, bool ggx) { return LobeAt(alpha, ggx)(key, 0.0f); }

// (s^alpha)^2 = s^(2 alpha), as 0 below lobe_of's floor exp(kLobeLogFloor): repeated squaring would otherwise
// walk through denormals (slow, and meaningless as a weight).
inline double square_lobe(double g) { return g < 1.8e-35 ? 0.0 : g * g; }

// Per-vertex sums (Static) of the eligible vertices over the samples of `set` (zero elsewhere).
std::vector<Static> static_sums(const Context &c, int set);

// Adds sample e with lobe value g = s^alpha to the lobe sums.
inline void add_to_lobe(Lobe &L, const Entry &e, double g) {
  L.b += double(e.w) * e.d * g, L.g2 += double(e.w) * g * g;
  for (int ch = 0; ch < 3; ++ch) L.q[ch] += double(e.w) * g * e.rgb[ch];
}

// Lobe sums at many alphas kept as five arrays (b, g2, q_r, q_g, q_b; array j starts at sums +
// j * stride), so that the loops over the alphas run on contiguous doubles (vectorised).
// add_to_lobe for sample e at the alphas [first, last] whose lobe values are g[first..last]: the same
// arithmetic (a zero lobe adds zeros: the same sums).
inline void add_to_lobes(double *sums, size_t stride, const Entry &e, const double *g, size_t first, size_t last) {
  double *b = sums, *g2 = sums + stride, *q0 = sums + 2 * stride, *q1 = sums + 3 * stride, *q2 = sums + 4 * stride;
  const double w = e.w, wd = w * e.d, r0 = e.rgb[0], r1 = e.rgb[1], r2 = e.rgb[2];
  for (size_t i = first; i <= last; ++i) {
    const double gi = g[i], wg = w * gi;
    b[i] += wd * gi, g2[i] += wg * gi, q0[i] += wg * r0, q1[i] += wg * r1, q2[i] += wg * r2;
  }
}
// The Lobe at alpha index i of such arrays.
inline Lobe lobe_from_sums(const double *sums, size_t stride, size_t i) {
  Lobe L;
  L.b = sums[i], L.g2 = sums[stride + i];
  for (int ch = 0; ch < 3; ++ch) L.q[ch] = sums[(2 + size_t(ch)) * stride + i];
  return L;
}

// Pooled k_s from summed k_s equations (num = sum rhs, den = sum info), in [0, ks_max]; 0 without information.
inline double pooled_ks(double num, double den, const ReflectanceFitOptions &o) {
  return den > 0 ? std::min(std::max(num / den, 0.0), double(o.ks_max)) : 0.0;
}

// Lobe sums of every eligible labelled vertex at `count` alphas in one pass over its samples: buffer
// j, entry v holds the sums at alpha_of[label[v]][j] (lobe_sums' values; the samples are read once
// however many alphas, where separate passes would each stream them from memory). `out`'s buffers
// (kept between calls: the context's pool) keep what they held at the other vertices: no pass over
// all c.n entries per call (on a subsample the choice asks for 3 000 of 100 k vertices many times).
const std::vector<std::vector<Lobe>> &lobe_sums_at(const Context &c, int set, const std::vector<int32_t> &label,
                                                   const std::vector<std::vector<double>> &alpha_of, size_t count,
                                                   std::vector<std::vector<Lobe>> &out);

// Lobe sums of every eligible labelled vertex at alpha_of[label[v]], in a new vector (zero elsewhere).
std::vector<Lobe> lobe_sums(const Context &c, int set, const std::vector<int32_t> &label, const std::vector<double> &alpha_of);

// k_s information and right-hand side after eliminating rho: I = 3 (g2 - b^2/a), r = sum_c (q_c - b p_c / a).
inline void ks_equation(const Static &S, const Lobe &L, double &info, double &rhs) {
  const double inv_a = S.a > 0 ? 1.0 / S.a : 0.0;
  info = std::max(0.0, 3 * (L.g2 - L.b * L.b * inv_a));
  rhs = 0;
  for (int ch = 0; ch < 3; ++ch) rhs += L.q[ch] - L.b * S.p[ch] * inv_a;
}

// Energy (the weighted sum of squared residuals) of k_s and rho fixed, from the sums; >= 0.
inline double energy_fixed(const Static &S, const Lobe &L, double ks, const double rho[3]) {
  double e = 0;
  for (int ch = 0; ch < 3; ++ch)
    e += S.pp[ch] - 2 * rho[ch] * S.p[ch] - 2 * ks * L.q[ch] + rho[ch] * rho[ch] * S.a + 2 * rho[ch] * ks * L.b +
         ks * ks * L.g2;
  return std::max(0.0, e);
}

// Energy with k_s fixed and rho re-solved exactly (non-negative); rho written when given.
inline double energy_ks(const Static &S, const Lobe &L, double ks, double *rho_out = nullptr) {
  double rho[3];
  for (int ch = 0; ch < 3; ++ch) rho[ch] = S.a > 0 ? std::max(0.0, (S.p[ch] - L.b * ks) / S.a) : 0.0;
  if (rho_out) std::copy(rho, rho + 3, rho_out);
  return energy_fixed(S, L, ks, rho);
}

using Adjacency = MeshAdjacency;

// The median of v (the upper one for an even count); 0 for an empty v.
double median_of(std::vector<double> v);

} // namespace material_stage
} // namespace vbrdf
