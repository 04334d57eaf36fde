#pragma once
// The material stage's labelling (materials.h): which material each vertex belongs to, by its own
// data under the materials' lobes and its mesh neighbours, and the alternation with the lobe fits.
#include <cstdint>
#include <vector>

#include "fit/material_lobes.h"

namespace vbrdf {
namespace material_stage {

// Labels by the data (energy under each lobe over the residual variance) and the neighbours (ICM).
void assign_labels(const Context &c, const Adjacency &adj, const std::vector<Static> &S, int set,
                   const std::vector<LobeFit> &lobes, int K, std::vector<int32_t> &label);

// Drops empty materials and renumbers 1..K'; returns K'.
int compact_labels(const Context &c, int K, std::vector<int32_t> &label);

// Initial labels for K materials: weighted 1-D k-means of the per-vertex k_s at the pooled alpha.
std::vector<int32_t> initial_labels(const Context &c, const Adjacency &adj, const std::vector<Static> &S, int set,
                                    double alpha, int K);

struct Config {
  int K = 0;
  std::vector<int32_t> label;
  std::vector<LobeFit> lobes;
};

// Alternates lobe fits and assignments on `set`, starting from `label`. After the first, the lobe
// fits search a window around the previous alphas (fit_lobes); `exact_ranges`: the last fit is
// redone on the whole grid if it was windowed (the same lobes, alpha_lo/hi of the whole grid).
Config cluster(const Context &c, const Adjacency &adj, const std::vector<Static> &S, int set, std::vector<int32_t> label,
               int K, int iterations, bool exact_ranges = false);

} // namespace material_stage
} // namespace vbrdf
