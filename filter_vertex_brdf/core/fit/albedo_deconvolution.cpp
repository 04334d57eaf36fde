#include "fit/albedo_deconvolution.h"

#include <algorithm>
#include <cmath>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/Sparse>

namespace vbrdf {

namespace {
// The range of b over a row's vertices, per channel (the footprint's darkest and brightest fit).
void row_range(const FootprintRows &rows, size_t k, const float *b, double low[3], double high[3]) {
  for (int c = 0; c < 3; ++c) low[c] = 1e30, high[c] = -1e30;
  for (uint32_t e = rows.offsets[k]; e < rows.offsets[k + 1]; ++e)
    for (int c = 0; c < 3; ++c) {
      const double bu = b[3 * size_t(rows.entry_vertex[e]) + size_t(c)];
      low[c] = std::min(low[c], bu), high[c] = std::max(high[c], bu);
    }
}
} // namespace

bool footprint_spans_an_edge(const FootprintRows &rows, size_t k, const float *b, float edge_contrast) {
  double low[3], high[3];
  row_range(rows, k, b, low, high);
  return spans_albedo_edge(low, high, edge_contrast);
}

namespace {
// One solve over the vertices with candidate[v] != 0 (the others held at b): writes their x
// (clamped to their footprints' ranges) and returns false when CG failed. `iterations` gets CG's
// largest count over the channels.
bool solve_candidates(const FootprintRows &rows, const float *b, const std::vector<uint8_t> &candidate,
                      const DeconvolutionSettings &settings, float *x, int &iterations) {
  const size_t n = candidate.size();
  std::vector<int32_t> unknown_of(n, -1);
  std::vector<uint32_t> vertex_of;
  std::vector<size_t> used_rows;
  for (size_t k = 0; k < rows.rows(); ++k) {
    const uint32_t v = rows.row_vertex[k];
    if (!candidate[v]) continue;
    used_rows.push_back(k);
    if (unknown_of[v] < 0) unknown_of[v] = int32_t(vertex_of.size()), vertex_of.push_back(v);
  }
  const size_t n_unknowns = vertex_of.size();
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::MatrixXd target(long(used_rows.size()), 3);
  for (size_t i = 0; i < used_rows.size(); ++i) {
    const size_t k = used_rows[i];
    const double s = std::sqrt(double(rows.row_share[k]));
    double held[3] = {0, 0, 0};  // the held vertices' part of the sample
    for (uint32_t e = rows.offsets[k]; e < rows.offsets[k + 1]; ++e) {
      const uint32_t u = rows.entry_vertex[e];
      if (unknown_of[u] >= 0)
        triplets.emplace_back(long(i), unknown_of[u], s * rows.entry_weight[e]);
      else
        for (int c = 0; c < 3; ++c) held[c] += rows.entry_weight[e] * b[3 * size_t(u) + size_t(c)];
    }
    for (int c = 0; c < 3; ++c) target(long(i), c) = s * (b[3 * size_t(rows.row_vertex[k]) + size_t(c)] - held[c]);
  }
  Eigen::SparseMatrix<double, Eigen::RowMajor> W(long(used_rows.size()), long(n_unknowns));
  W.setFromTriplets(triplets.begin(), triplets.end());
  const double lambda = std::min(std::max(double(settings.lambda), 1e-3), 1e6);
  Eigen::SparseMatrix<double> A = Eigen::SparseMatrix<double>(W.transpose()) * W;
  Eigen::MatrixXd prior(long(n_unknowns), 3);
  for (size_t u = 0; u < n_unknowns; ++u)
    for (int c = 0; c < 3; ++c) prior(long(u), c) = b[3 * size_t(vertex_of[u]) + size_t(c)];
  for (size_t u = 0; u < n_unknowns; ++u) A.coeffRef(long(u), long(u)) += lambda;
  const Eigen::MatrixXd rhs = W.transpose() * target + lambda * prior;

  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> cg;
  cg.setMaxIterations(std::max(1, settings.max_iterations));
  cg.setTolerance(std::max(double(settings.tolerance), 1e-12));
  cg.compute(A);
  Eigen::MatrixXd solution(long(n_unknowns), 3);
  iterations = 0;
  for (int c = 0; c < 3; ++c) {
    solution.col(c) = cg.solveWithGuess(rhs.col(c), prior.col(c));  // from the fit's values
    iterations = std::max(iterations, int(cg.iterations()));
  }
  if (cg.info() == Eigen::NumericalIssue || !solution.allFinite()) return false;
  // No new extremes: within the range of the fit's colours over each of the vertex's footprints
  // (the value of a sharp step lies between its sides; beyond is ringing).
  std::vector<uint8_t> set(n, 0);
  for (size_t k : used_rows) {
    const uint32_t v = rows.row_vertex[k];
    double low[3], high[3];
    row_range(rows, k, b, low, high);
    for (int c = 0; c < 3; ++c) {
      float &out = x[3 * size_t(v) + size_t(c)];
      const double value = set[v] ? double(out) : solution(unknown_of[v], c);
      out = float(std::min(std::max(value, low[c]), high[c]));
    }
    set[v] = 1;
  }
  return true;
}

// |sum_u W x_u - b_v| of row k, largest over the channels, relative to the row's brightest b.
double row_misfit(const FootprintRows &rows, size_t k, const float *b, const float *x) {
  double low[3], high[3], seen[3] = {0, 0, 0};
  row_range(rows, k, b, low, high);
  for (uint32_t e = rows.offsets[k]; e < rows.offsets[k + 1]; ++e)
    for (int c = 0; c < 3; ++c) seen[c] += rows.entry_weight[e] * x[3 * size_t(rows.entry_vertex[e]) + size_t(c)];
  const double top = std::max(high[0], std::max(high[1], high[2]));
  double worst = 0;
  for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(seen[c] - b[3 * size_t(rows.row_vertex[k]) + size_t(c)]));
  return top > 0 ? worst / top : 0.0;
}
} // namespace

DeconvolutionStats deconvolve_albedo(const FootprintRows &rows, size_t vertex_count, const float *b,
                                     const uint8_t *write, const DeconvolutionSettings &settings, float *x,
                                     uint8_t *deconvolved) {
  DeconvolutionStats stats;
  std::copy(b, b + 3 * vertex_count, x);
  if (deconvolved) std::fill(deconvolved, deconvolved + vertex_count, uint8_t(0));
  // Candidates: the vertices to write whose footprint (any of its rows) spans an edge.
  std::vector<uint8_t> candidate(vertex_count, 0);
  for (size_t k = 0; k < rows.rows(); ++k) {
    const uint32_t v = rows.row_vertex[k];
    if ((!write || write[v]) && footprint_spans_an_edge(rows, k, b, settings.edge_contrast)) candidate[v] = 1;
  }
  stats.edge_vertices = size_t(std::count(candidate.begin(), candidate.end(), uint8_t(1)));
  if (stats.edge_vertices == 0) {
    stats.note = "no footprint spans an albedo edge (contrast above " +
                 std::to_string(int(std::lround(100 * settings.edge_contrast))) + " %): nothing to deconvolve";
    return stats;
  }
  // Solve; vertices whose footprints the result does not reproduce (the footprint model does not
  // hold there: e.g. a texture finer than the mesh, whose sample is not a blend of the vertices'
  // values) go back to b and are held; again, at most max_rounds times.
  std::vector<float> trial(x, x + 3 * vertex_count);
  for (int round = 0; round < std::max(1, settings.max_rounds); ++round) {
    std::copy(b, b + 3 * vertex_count, trial.begin());
    int iterations = 0;
    if (!solve_candidates(rows, b, candidate, settings, trial.data(), iterations)) {
      stats.note = "the solve failed (non-finite values): the fit's colours kept";
      return stats;
    }
    stats.iterations += iterations;
    size_t rejected = 0;
    for (size_t k = 0; k < rows.rows(); ++k) {
      const uint32_t v = rows.row_vertex[k];
      if (candidate[v] && row_misfit(rows, k, b, trial.data()) > settings.misfit_tolerance) candidate[v] = 0, ++rejected;
    }
    stats.rounds = round + 1;
    if (rejected == 0) break;
  }
  // The last round's rejects (when the rounds ran out) keep b; the others keep that round's values.
  for (size_t v = 0; v < vertex_count; ++v)
    if (candidate[v])
      for (int c = 0; c < 3; ++c) x[3 * v + size_t(c)] = trial[3 * v + size_t(c)];
  stats.solved = true;
  double sum = 0;
  for (size_t k = 0; k < rows.rows(); ++k) {
    const uint32_t v = rows.row_vertex[k];
    if (!candidate[v]) continue;
    ++stats.rows;
    const double m = row_misfit(rows, k, b, x);
    sum += m * m;
  }
  for (size_t v = 0; v < vertex_count; ++v)
    if (candidate[v]) {
      ++stats.written;
      if (deconvolved) deconvolved[v] = 1;
    }
  stats.reblur_rms = stats.rows ? std::sqrt(sum / double(stats.rows)) : 0.0;
  return stats;
}

} // namespace vbrdf
