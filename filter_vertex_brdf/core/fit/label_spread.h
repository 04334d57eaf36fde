#pragma once
// Labels spread over a mesh ring by ring (the material stage's, material_labels.cpp): ring 0 is the
// unlabelled neighbours of the labelled vertices, ring r + 1 the unlabelled, not yet reached
// neighbours of ring r, and each ring takes the most common label among its neighbours labelled in
// earlier rings. The rings depend on which vertices are labelled, not on their labels, so a caller
// that asks again and again with the same labelled set keeps them (SpreadRingCache) instead of
// walking the mesh per call.
#include <cstdint>
#include <vector>

#include "base/mesh_adjacency.h"

namespace vbrdf {

struct SpreadRings {
  std::vector<uint8_t> seeded;      // per mesh vertex: labelled (what the rings were made for)
  std::vector<uint32_t> vertices;   // the rings, one after the other
  std::vector<size_t> ring_end;     // ring r is vertices[ring_end[r - 1] (0 for r = 0), ring_end[r])
};

// The rings for the labelled vertices `seeded` (one flag per mesh vertex). Only the vertices the
// caller keeps a label of (`kept`: a flag per vertex for the first kept.size() vertices) matter: the
// rings stop once every kept vertex that can be reached has been (with `component`, the connected
// component of every mesh vertex, e.g. connected_components: those in a component without a
// labelled vertex cannot), and hold only the vertices whose votes reach a kept vertex. O(reached
// vertices + their edges).
SpreadRings spread_rings(const MeshAdjacency &adj, std::vector<uint8_t> seeded, const std::vector<uint8_t> &kept,
                         const std::vector<uint32_t> *component, uint32_t component_count);

// The last few rings asked for, for one `kept` set and one mesh (the caller keeps one cache per set).
class SpreadRingCache {
public:
  const SpreadRings &rings(const MeshAdjacency &adj, std::vector<uint8_t> seeded, const std::vector<uint8_t> &kept,
                           const std::vector<uint32_t> *component, uint32_t component_count);

private:
  std::vector<SpreadRings> kept_rings_;
};

// Gives the vertices of `rings` labels, ring by ring, in `label` (per mesh vertex; 0 = none, labels
// 1..K): each takes the most common label among its neighbours labelled before its ring (ties: the
// smallest label).
void spread_along_rings(const MeshAdjacency &adj, const SpreadRings &rings, int K, std::vector<int32_t> &label);

} // namespace vbrdf
