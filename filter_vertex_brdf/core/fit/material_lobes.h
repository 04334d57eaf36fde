#pragma once
// The material stage's pooled lobes (materials.h): one lobe per material, k_s and alpha, from the
// samples of all its vertices.
#include <cstdint>
#include <vector>

#include "fit/material_sums.h"

namespace vbrdf {
namespace material_stage {

struct LobeFit {
  double ks = 0, alpha = 1, energy = 0, energy_zero = 0, alpha_lo = 1, alpha_hi = 1;
};

// The alpha grid of the pooled lobe search: alpha_min 2^(j/3) (three steps per doubling, so that a
// sample's lobe at every grid alpha costs three exponentials and squarings: s^(2a) = (s^a)^2), the
// last point alpha_max.
constexpr int kGridStepsPerDoubling = 3;
std::vector<double> alpha_grid(const ReflectanceFitOptions &o);

// Pooled lobes of materials 1..K (label[v]) on `set`: alpha over a log grid (on grid_labels'
// subsample) with parabolic refinement in ln alpha, k_s in closed form (rho eliminated per vertex);
// the grid's best alpha and the refined one are then evaluated on every labelled vertex and the
// better kept (energies, k_s: from every vertex; alpha_lo/hi: from the grid's subsample).
std::vector<LobeFit> fit_lobes(const Context &c, int set, const std::vector<Static> &S, const std::vector<int32_t> &label,
                               int K, const std::vector<LobeFit> *previous = nullptr, bool *windowed = nullptr);

} // namespace material_stage
} // namespace vbrdf
