#pragma once
// Vertex adjacency of a triangle mesh, compressed: the neighbours of v are
// neighbours[offsets[v] .. offsets[v + 1]), sorted, each undirected edge stored in both directions
// once. Indices out of range and degenerate edges (a == b) are skipped. Used by the neighbour fill,
// the material stage and the diffuse form's coat map.
#include <cstdint>
#include <vector>

#include "base/mesh_view.h"

namespace vbrdf {

struct MeshAdjacency {
  std::vector<uint32_t> offsets;     // vertex_count + 1 entries
  std::vector<uint32_t> neighbours;
  size_t vertex_count() const { return offsets.empty() ? 0 : offsets.size() - 1; }
};

MeshAdjacency build_mesh_adjacency(const MeshView &mesh);

// The connected component of every vertex: 0..count-1, numbered in order of their lowest vertex
// (an isolated vertex is a component of its own). O(vertices + edges).
std::vector<uint32_t> connected_components(const MeshAdjacency &adj, uint32_t *count = nullptr);

} // namespace vbrdf
