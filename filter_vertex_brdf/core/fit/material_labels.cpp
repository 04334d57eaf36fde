#include "fit/material_labels.h"

#include <algorithm>
#include <cmath>

namespace vbrdf {
namespace material_stage {

// Vertices without a label take the most common label among their labelled neighbours, ring by
// ring through the mesh (vertices outside the stage pass labels on; spread_rings); an eligible
// vertex that no label reaches takes its data's best label.
void spread_labels(const Context &c, const Adjacency &adj, const std::vector<std::vector<double>> &cost, int K,
                   std::vector<int32_t> &label) {
  const size_t n = adj.vertex_count();
  std::vector<int32_t> lab(n, 0);
  std::vector<uint8_t> seeded(n, 0);
  for (size_t v = 0; v < std::min(n, c.n); ++v) lab[v] = c.eligible[v] ? label[v] : 0, seeded[v] = lab[v] > 0;
  SpreadRings scratch;
  const SpreadRings &rings = c.rings ? c.rings->rings(adj, std::move(seeded), c.eligible, c.component, c.component_count)
                                     : (scratch = spread_rings(adj, std::move(seeded), c.eligible, c.component, c.component_count));
  spread_along_rings(adj, rings, K, lab);
  for (uint32_t v : c.verts) {
    if (v < n && lab[v] > 0) {
      label[v] = lab[v];
      continue;
    }
    int best = 1;
    for (int m = 2; m <= K; ++m)
      if (cost[size_t(m)][v] < cost[size_t(best)][v]) best = m;
    label[v] = best;
  }
}

void assign_labels(const Context &c, const Adjacency &adj, const std::vector<Static> &S, int set,
                   const std::vector<LobeFit> &lobes, int K, std::vector<int32_t> &label) {
  std::vector<std::vector<double>> cost(size_t(K) + 1, std::vector<double>(c.n, 0.0));
  std::vector<int32_t> every(c.n, 0);
  for (uint32_t v : c.verts) every[v] = 1;
  std::vector<std::vector<double>> alphas(2, std::vector<double>(size_t(K)));
  for (int m = 1; m <= K; ++m) alphas[1][size_t(m) - 1] = lobes[size_t(m)].alpha;
  std::vector<std::vector<Lobe>> own;
  const std::vector<std::vector<Lobe>> &L = lobe_sums_at(c, set, every, alphas, size_t(K), c.lobe_buffers ? *c.lobe_buffers : own);
  for (int m = 1; m <= K; ++m)
    for (uint32_t v : c.verts) cost[size_t(m)][v] = energy_ks(S[v], L[size_t(m) - 1][v], lobes[size_t(m)].ks);
  std::vector<double> emin(c.n, 0), var;
  for (uint32_t v : c.verts) {
    double e = cost[1][v];
    for (int m = 2; m <= K; ++m) e = std::min(e, cost[size_t(m)][v]);
    emin[v] = e;
    if (S[v].n > 4) var.push_back(e / double(3 * S[v].n - 4));
  }
  const double floor_var = std::max(median_of(var), 1e-20);
  for (uint32_t v : c.verts) {
    const double var_v = S[v].n > 4 ? std::max(emin[v] / double(3 * S[v].n - 4), floor_var) : floor_var;
    for (int m = 1; m <= K; ++m) cost[size_t(m)][v] = (cost[size_t(m)][v] - emin[v]) / (2 * var_v);
  }
  // Only vertices with a highlight sample (kHighlight: R.E > T_s) decide by their data: for the others the
  // lobes differ only in their flanks, where a power lobe's form is least faithful. The GGX lobe
  // follows the flanks (its long tail is the microfacet highlight's), so there a sample in the flank
  // (MaterialOptions::deciding_flank) decides too: on the synthetic two-material scene 17 glossy
  // vertices without a training highlight were otherwise put with the diffuse material (k_s = 0, and
  // the held-out highlights they show then missed). ICM among the deciding vertices, then the others
  // take the label of the nearest deciding vertices over the mesh.
  std::vector<uint32_t> deciding;
  for (uint32_t v : c.verts)
    if (S[v].n_high > 0 || (c.ggx && S[v].n_flank > 0)) deciding.push_back(v);
    else label[v] = 0;
  std::vector<int> count(size_t(K) + 1);
  for (int sweep = 0; sweep < 20; ++sweep) {
    size_t changed = 0;
    for (uint32_t v : deciding) {
      std::fill(count.begin(), count.end(), 0);
      int labelled = 0;
      for (uint32_t k = adj.offsets[v]; k < adj.offsets[v + 1]; ++k) {
        const int32_t l = label[adj.neighbours[k]];
        if (l > 0 && l <= K) ++count[size_t(l)], ++labelled;
      }
      int best = label[v] > 0 && label[v] <= K ? label[v] : 1;
      double best_cost = 1e300;
      for (int m = 1; m <= K; ++m) {
        const double cm = cost[size_t(m)][v] + c.mo.coherence * double(labelled - count[size_t(m)]);
        if (cm < best_cost - 1e-12 || (std::fabs(cm - best_cost) <= 1e-12 && m == label[v])) best_cost = cm, best = m;
      }
      if (best != label[v]) label[v] = best, ++changed;
    }
    if (!changed) break;
  }
  spread_labels(c, adj, cost, K, label);
}

int compact_labels(const Context &c, int K, std::vector<int32_t> &label) {
  std::vector<size_t> count(size_t(K) + 1, 0);
  for (uint32_t v : c.verts)
    if (label[v] > 0) ++count[size_t(label[v])];
  std::vector<int32_t> map(size_t(K) + 1, 0);
  int k = 0;
  for (int m = 1; m <= K; ++m)
    if (count[size_t(m)]) map[size_t(m)] = ++k;
  for (size_t v = 0; v < c.n; ++v) label[v] = c.eligible[v] && label[v] > 0 ? map[size_t(label[v])] : 0;
  return k;
}

std::vector<int32_t> initial_labels(const Context &c, const Adjacency &adj, const std::vector<Static> &S, int set,
                                    double alpha, int K) {
  std::vector<int32_t> label(c.n, 0), ones(c.n, 0);
  for (size_t v = 0; v < c.n; ++v) ones[v] = c.eligible[v] ? 1 : 0;
  const std::vector<Lobe> L = lobe_sums(c, set, ones, std::vector<double>(2, alpha));
  std::vector<double> ks(c.n, 0), w(c.n, 0), infos;
  for (uint32_t v : c.verts) {
    double info, rhs;
    ks_equation(S[v], L[v], info, rhs);
    w[v] = info;
    ks[v] = info > 0 ? std::max(0.0, rhs / info) : 0;
    if (info > 0) infos.push_back(info);
  }
  const double min_info = 0.01 * median_of(infos);
  std::vector<size_t> order;
  for (uint32_t v : c.verts)
    if (w[v] > min_info && S[v].n_high > 0) order.push_back(v);
  for (size_t v = 0; v < c.n; ++v) label[v] = c.eligible[v] ? 1 : 0;
  if (K <= 1 || order.empty()) return label;
  for (size_t v = 0; v < c.n; ++v) label[v] = 0;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return ks[a] < ks[b]; });
  double total = 0;
  for (size_t v : order) total += w[v];
  std::vector<double> centre(static_cast<size_t>(K), 0.0);
  double acc = 0;
  size_t j = 0;
  for (int m = 0; m < K; ++m) {  // weighted quantiles (m + 0.5) / K
    const double target = total * (m + 0.5) / K;
    while (j + 1 < order.size() && acc + w[order[j]] < target) acc += w[order[j++]];
    centre[size_t(m)] = ks[order[j]];
  }
  std::vector<int32_t> assign(c.n, 0);
  for (int it = 0; it < 30; ++it) {
    std::vector<double> sw(size_t(K), 0), swx(size_t(K), 0);
    for (size_t v : order) {
      int best = 0;
      for (int m = 1; m < K; ++m)
        if (std::fabs(ks[v] - centre[size_t(m)]) < std::fabs(ks[v] - centre[size_t(best)])) best = m;
      assign[v] = best;
      sw[size_t(best)] += w[v], swx[size_t(best)] += w[v] * ks[v];
    }
    for (int m = 0; m < K; ++m)
      if (sw[size_t(m)] > 0) centre[size_t(m)] = swx[size_t(m)] / sw[size_t(m)];
  }
  for (size_t v : order) label[v] = assign[v] + 1;
  spread_labels(c, adj, std::vector<std::vector<double>>(size_t(K) + 1, std::vector<double>(c.n, 0.0)), K, label);
  return label;
}

Config cluster(const Context &c, const Adjacency &adj, const std::vector<Static> &S, int set, std::vector<int32_t> label,
               int K, int iterations, bool exact_ranges) {
  Config cfg;
  K = compact_labels(c, K, label);
  std::vector<LobeFit> lobes = fit_lobes(c, set, S, label, K);
  bool windowed = false;
  for (int it = 0; it < iterations && K > 1; ++it) {
    const std::vector<int32_t> before = label;
    assign_labels(c, adj, S, set, lobes, K, label);
    const int previous_k = K;
    K = compact_labels(c, K, label);
    const std::vector<LobeFit> previous = std::move(lobes);
    lobes = fit_lobes(c, set, S, label, K, K == previous_k ? &previous : nullptr, &windowed);
    if (label == before) break;
  }
  if (exact_ranges && windowed) lobes = fit_lobes(c, set, S, label, K);
  cfg.K = K, cfg.label = std::move(label), cfg.lobes = std::move(lobes);
  return cfg;
}

} // namespace material_stage
} // namespace vbrdf
