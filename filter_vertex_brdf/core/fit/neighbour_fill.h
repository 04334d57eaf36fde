#pragma once
// Neighbour fill: vertices the fit left without a model (no usable sample at all: every sample
// shadowed or saturated, or, on request, vertices no photo sees) take their parameters from the
// nearest modelled vertices over the mesh, ring by ring.
#include <cstddef>
#include <cstdint>

#include "base/mesh_view.h"
#include "fit/reflectance_fit.h"

namespace vbrdf {

struct NeighbourFillStats {
  size_t filled_seen = 0;      // seen vertices given a model (status kFitFromNeighbours)
  size_t filled_unseen = 0;    // unseen vertices given a model (only with unseen_rings > 0)
  size_t filled_nearest = 0;   // of filled_seen: in a part of the mesh without any modelled
                               //   vertex, from the nearest modelled vertex in space
  size_t unreachable_seen = 0; // seen vertices left without a model: no modelled vertex at all
  int rings = 0;               // rings walked
};

// fits[v] (mesh.vertex_count entries) is updated in place: every vertex with status kFitNone and
// seen[v] != 0 that is connected over the mesh's edges to a modelled vertex gets one; an unseen
// vertex (seen[v] == 0) only when it lies within `unseen_rings` edges of a modelled vertex
// (0 = never: vertices no photo sees keep "no model"). Propagation runs through filled vertices,
// one ring per pass, each pass reading only the previous passes' results (order-independent).
// A seen vertex whose connected part of the mesh has no modelled vertex copies the nearest
// modelled vertex in space (a kd-tree over the modelled vertices).
// Parameters: the average of the modelled edge neighbours, weighted by normal agreement
// (max(N.N', 0) + 0.05) over edge length, with sources that are themselves filled or weak
// (status 3/4) at half weight; rho = k_d C and k_s averaged, shininess averaged in log space
// over the neighbours with a lobe. Filled vertices get status kFitFromNeighbours, dq = sq = 0,
// rmse = 0. Degenerate edges (zero length) count with a length of 1e-6 of the bounding-box
// diagonal. Outputs are finite. O(passes x edges); memory O(vertices + edges).
NeighbourFillStats fill_from_neighbours(const MeshView &mesh, const uint8_t *seen, int unseen_rings, VertexFit *fits);

} // namespace vbrdf
