#include "fit/material_lobes.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vbrdf {
namespace material_stage {

std::vector<double> alpha_grid(const ReflectanceFitOptions &o) {
  const double lo = std::max(1.0, double(o.alpha_min)), hi = std::max(double(o.alpha_max), 2 * lo);
  std::vector<double> g;
  for (int j = 0;; ++j) {
    const double a = lo * std::exp2(double(j) / kGridStepsPerDoubling);
    if (a >= hi * (1 - 1e-9)) break;
    g.push_back(a);
  }
  g.push_back(hi);
  return g;
}

// Grid indices [first, last] of one material's alpha search.
struct GridWindow {
  size_t first = 0, last = 0;
};

// Pooled energies and k_s of materials 1..K (label[v]) at every grid alpha, in one pass over each
// vertex's samples: E[m][i], KS[m][i] (k_s in closed form with rho eliminated per vertex, clamped to
// [0, ks_max]; the energy at that k_s with rho re-solved). With `window` (index m: material m's grid
// range), only that range is evaluated (the same values there; E = +infinity, KS = 0 outside).
void grid_energies(const Context &c, int set, const std::vector<Static> &S, const std::vector<int32_t> &label, int K,
                   const std::vector<double> &grid, std::vector<std::vector<double>> &E, std::vector<std::vector<double>> &KS,
                   const std::vector<GridWindow> *window = nullptr) {
  const size_t ng = grid.size();
  auto range_of = [&](size_t m) { return window ? (*window)[m] : GridWindow{0, ng - 1}; };
  std::vector<uint8_t> squared(ng, 0);  // grid[i] = 2 grid[i - kGridStepsPerDoubling]: (lobe)^2
  for (size_t i = kGridStepsPerDoubling; i < ng; ++i)  // (power forms only: GGX is no power of s)
    squared[i] = !c.ggx && std::fabs(grid[i] - 2 * grid[i - kGridStepsPerDoubling]) <= 1e-12 * grid[i];
  std::vector<uint32_t> verts;
  for (uint32_t v : c.verts)
    if (label[v] > 0) verts.push_back(v);
  // Per vertex, the lobe sums at every grid alpha as five arrays of ng (add_to_lobes); a sample's GGX
  // lobe costs one division per grid point (a^2 per grid point computed once).
  constexpr size_t kSums = 5;
  std::vector<double> sums(verts.size() * kSums * ng, 0.0);
  std::vector<double> a2(ng);
  for (size_t i = 0; i < ng; ++i) a2[i] = ggx_a2(grid[i]);
  const auto &entries = c.store.entries();
#pragma omp parallel if (verts.size() > 2000)
  {
    std::vector<double> g(ng);  // the sample's lobe at every grid alpha (one buffer per thread)
#pragma omp for schedule(dynamic, 64)
    for (long long t = 0; t < (long long)verts.size(); ++t) {
      const size_t v = verts[size_t(t)];
      const GridWindow r = range_of(size_t(label[v]));
      double *vertex_sums = &sums[size_t(t) * kSums * ng];
      for (uint64_t k = c.store.first(v); k < c.store.last(v); ++k) {
        const Entry &e = entries[k];
        const float ls = (*c.lobe_keys)[k];
        if (ls > 0 || !c.in_set(e, set)) continue;
        if (c.ggx) {
          const double u = -double(ls);
          const double vc = clamped_footprint(e.v);
          for (size_t i = r.first; i <= r.last; ++i) g[i] = ggx_lobe_through_clamped_footprint(u, a2[i], vc);
        } else {  // the squaring chain from the grid's start (cheap), so the window's values are the full grid's
          for (size_t i = 0; i <= r.last; ++i)
            g[i] = squared[i] ? square_lobe(g[i - kGridStepsPerDoubling]) : lobe_of(ls, grid[i], false);
        }
        add_to_lobes(vertex_sums, ng, e, g.data(), r.first, r.last);
      }
    }
  }
  auto lobe_at = [&](size_t t, size_t i) { return lobe_from_sums(&sums[t * kSums * ng], ng, i); };
  E.assign(size_t(K) + 1, std::vector<double>(ng, 0.0));
  KS = E;
  std::vector<std::vector<double>> num = E, den = E;
  for (size_t t = 0; t < verts.size(); ++t) {
    const size_t m = size_t(label[verts[t]]);
    const GridWindow r = range_of(m);
    for (size_t i = r.first; i <= r.last; ++i) {
      double info, rhs;
      ks_equation(S[verts[t]], lobe_at(t, i), info, rhs);
      num[m][i] += rhs, den[m][i] += info;
    }
  }
  for (int m = 1; m <= K; ++m)
    for (size_t i = 0; i < ng; ++i)
      KS[size_t(m)][i] = pooled_ks(num[size_t(m)][i], den[size_t(m)][i], c.o);
  for (size_t t = 0; t < verts.size(); ++t) {
    const size_t m = size_t(label[verts[t]]);
    const GridWindow r = range_of(m);
    for (size_t i = r.first; i <= r.last; ++i) E[m][i] += energy_ks(S[verts[t]], lobe_at(t, i), KS[m][i]);
  }
  for (int m = 1; m <= K; ++m) {
    const GridWindow r = range_of(size_t(m));
    for (size_t i = 0; i < ng; ++i)
      if (i < r.first || i > r.last) E[size_t(m)][i] = std::numeric_limits<double>::infinity(), KS[size_t(m)][i] = 0;
  }
}

// The grid index whose alpha is nearest `alpha` in ln alpha.
size_t nearest_grid_index(const std::vector<double> &grid, double alpha) {
  size_t best = 0;
  for (size_t i = 1; i < grid.size(); ++i)
    if (std::fabs(std::log(grid[i] / alpha)) < std::fabs(std::log(grid[best] / alpha))) best = i;
  return best;
}

// True when the minimum of energies `e` over window w lies on an edge of w that is not the grid's
// own end.
bool minimum_on_window_edge(const std::vector<double> &e, const GridWindow &w, size_t ng) {
  const size_t i = size_t(std::min_element(e.begin(), e.end()) - e.begin());
  return (w.first > 0 && i == w.first) || (w.last + 1 < ng && i == w.last);
}

// The vertices the alpha grid search of fit_lobes looks at: every k-th labelled one, k such that
// about kGridVertices remain (all of them on smaller meshes). A material's pooled lobe is an
// average over its vertices, so an even subsample finds the same alpha; the chosen alpha is then
// evaluated on every vertex. On the benchmark's 100 k vertices the stage takes 4.7 s with the
// subsample against 7.3 s on every vertex (alpha of the main glossy material 86.0 against 84.9);
// meshes under 8000 eligible vertices are searched on every vertex.
constexpr size_t kGridVertices = 8000;
std::vector<int32_t> grid_labels(const Context &c, const std::vector<int32_t> &label) {
  size_t labelled = 0;
  for (uint32_t v : c.verts) labelled += label[v] > 0;
  const size_t stride = (labelled + kGridVertices - 1) / kGridVertices;
  if (stride <= 1) return label;
  std::vector<int32_t> out(label.size(), 0);
  size_t k = 0;
  for (uint32_t v : c.verts)
    if (label[v] > 0 && k++ % stride == 0) out[v] = label[v];
  return out;
}

std::vector<LobeFit> fit_lobes(const Context &c, int set, const std::vector<Static> &S, const std::vector<int32_t> &label,
                               int K, const std::vector<LobeFit> *previous, bool *windowed) {
  const std::vector<double> grid = alpha_grid(c.o);
  std::vector<std::vector<double>> E(size_t(K) + 1, std::vector<double>(grid.size(), 0.0)), KS = E;
  std::vector<LobeFit> fit(size_t(K) + 1);
  const std::vector<int32_t> sub_label = grid_labels(c, label);
  const bool subsampled = sub_label != label;
  // k_s = 0 energies.
  for (uint32_t v : c.verts)
    if (label[v] > 0) fit[size_t(label[v])].energy_zero += energy_ks(S[v], Lobe(), 0);
  // Pooled k_s and energies of every material at the alphas whose lobe sums are in L.
  auto evaluate = [&](const std::vector<int32_t> &which, const std::vector<Lobe> &L, std::vector<double> &ks_out,
                      std::vector<double> &e_out) {
    std::vector<double> num(size_t(K) + 1, 0), den(size_t(K) + 1, 0);
    for (uint32_t v : c.verts) {
      if (which[v] <= 0) continue;
      double info, rhs;
      ks_equation(S[v], L[v], info, rhs);
      num[size_t(which[v])] += rhs, den[size_t(which[v])] += info;
    }
    ks_out.assign(size_t(K) + 1, 0);
    e_out.assign(size_t(K) + 1, 0);
    for (int m = 1; m <= K; ++m)
      ks_out[size_t(m)] = pooled_ks(num[size_t(m)], den[size_t(m)], c.o);
    for (uint32_t v : c.verts)
      if (which[v] > 0) e_out[size_t(which[v])] += energy_ks(S[v], L[v], ks_out[size_t(which[v])]);
  };
  // Given the previous lobes of the same materials (the alternations of cluster), each material's
  // search is a window of +-kWindowSteps grid points around its previous alpha: the lobes move
  // little from one alternation to the next. When a minimum falls on a window's edge, the whole grid
  // is searched: the lobe is the whole grid's whenever the energy has no second, lower basin outside
  // the window. alpha_lo/hi then span at most the window (`*windowed` is set): cluster searches the
  // whole grid once more where the report needs them.
  bool searched = false;
  if (previous && previous->size() == size_t(K) + 1) {
    constexpr size_t kWindowSteps = 4;
    std::vector<GridWindow> window(size_t(K) + 1, GridWindow{0, grid.size() - 1});
    for (int m = 1; m <= K; ++m) {
      const size_t i = nearest_grid_index(grid, (*previous)[size_t(m)].alpha);
      window[size_t(m)] = {i > kWindowSteps ? i - kWindowSteps : 0, std::min(grid.size() - 1, i + kWindowSteps)};
    }
    grid_energies(c, set, S, sub_label, K, grid, E, KS, &window);
    searched = true;
    for (int m = 1; m <= K && searched; ++m)
      searched = !minimum_on_window_edge(E[size_t(m)], window[size_t(m)], grid.size());
  }
  if (windowed) *windowed = searched;
  if (!searched) grid_energies(c, set, S, sub_label, K, grid, E, KS);
  std::vector<double> refined(size_t(K) + 1, 1.0);
  for (int m = 1; m <= K; ++m) {
    const std::vector<double> &e = E[size_t(m)];
    const size_t i = size_t(std::min_element(e.begin(), e.end()) - e.begin());
    LobeFit &f = fit[size_t(m)];
    f.alpha = grid[i], f.ks = KS[size_t(m)][i], f.energy = e[i];
    f.alpha_lo = f.alpha_hi = grid[i];
    for (size_t j = 0; j < grid.size(); ++j)
      if (e[j] <= 1.01 * e[i] + 1e-300) f.alpha_lo = std::min(f.alpha_lo, grid[j]), f.alpha_hi = std::max(f.alpha_hi, grid[j]);
    refined[size_t(m)] = f.alpha;
    const double h = std::log(grid[1] / grid[0]);
    if (i > 0 && i + 1 < grid.size() && std::fabs(std::log(grid[i + 1] / grid[i]) - h) < 1e-9) {
      // parabola through the three points, in t = ln alpha (uniform spacing)
      const double d2 = e[i - 1] - 2 * e[i] + e[i + 1];
      if (d2 > 0) {
        const double dt = 0.5 * h * (e[i - 1] - e[i + 1]) / d2;
        refined[size_t(m)] = std::exp(std::log(grid[i]) + std::max(-h, std::min(h, dt)));
      }
    }
  }
  // The refined alpha on every vertex and, when the grid saw a subsample, the grid's best too (the
  // reference the refined alpha must beat), in one pass.
  std::vector<std::vector<double>> alphas(size_t(K) + 1, std::vector<double>(2, 1.0));
  for (int m = 1; m <= K; ++m) alphas[size_t(m)] = {refined[size_t(m)], fit[size_t(m)].alpha};
  std::vector<std::vector<Lobe>> own;
  const std::vector<std::vector<Lobe>> &L =
      lobe_sums_at(c, set, label, alphas, subsampled ? 2 : 1, c.lobe_buffers ? *c.lobe_buffers : own);
  std::vector<double> ks, e;
  if (subsampled) {
    evaluate(label, L[1], ks, e);
    for (int m = 1; m <= K; ++m) fit[size_t(m)].ks = ks[size_t(m)], fit[size_t(m)].energy = e[size_t(m)];
  }
  evaluate(label, L[0], ks, e);
  for (int m = 1; m <= K; ++m)
    if (e[size_t(m)] < fit[size_t(m)].energy)
      fit[size_t(m)].alpha = refined[size_t(m)], fit[size_t(m)].ks = ks[size_t(m)], fit[size_t(m)].energy = e[size_t(m)];
  return fit;
}

} // namespace material_stage
} // namespace vbrdf
