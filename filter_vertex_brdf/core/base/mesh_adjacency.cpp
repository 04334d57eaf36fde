#include "base/mesh_adjacency.h"

#include <algorithm>

namespace vbrdf {

MeshAdjacency build_mesh_adjacency(const MeshView &mesh) {
  const size_t n = mesh.vertex_count;
  std::vector<uint32_t> degree(n + 1, 0);
  for (size_t i = 0; i + 2 < mesh.index_count; i += 3)
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = mesh.indices[i + size_t(e)], b = mesh.indices[i + size_t((e + 1) % 3)];
      if (a < n && b < n && a != b) ++degree[a], ++degree[b];
    }
  MeshAdjacency adj;
  adj.offsets.assign(n + 1, 0);
  for (size_t v = 0; v < n; ++v) adj.offsets[v + 1] = adj.offsets[v] + degree[v];
  adj.neighbours.resize(adj.offsets[n]);
  std::vector<uint32_t> fill(adj.offsets.begin(), adj.offsets.end() - 1);
  for (size_t i = 0; i + 2 < mesh.index_count; i += 3)
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = mesh.indices[i + size_t(e)], b = mesh.indices[i + size_t((e + 1) % 3)];
      if (a < n && b < n && a != b) adj.neighbours[fill[a]++] = b, adj.neighbours[fill[b]++] = a;
    }
  // Deduplicate each list in place (an interior edge appears in two triangles).
  std::vector<uint32_t> offsets(n + 1, 0);
  size_t out = 0;
  for (size_t v = 0; v < n; ++v) {
    auto first = adj.neighbours.begin() + adj.offsets[v], last = adj.neighbours.begin() + adj.offsets[v + 1];
    std::sort(first, last);
    last = std::unique(first, last);
    offsets[v] = uint32_t(out);
    for (auto it = first; it != last; ++it) adj.neighbours[out++] = *it;
  }
  offsets[n] = uint32_t(out);
  adj.neighbours.resize(out);
  adj.offsets.swap(offsets);
  return adj;
}

std::vector<uint32_t> connected_components(const MeshAdjacency &adj, uint32_t *count) {
  const size_t n = adj.vertex_count();
  constexpr uint32_t kNone = UINT32_MAX;
  std::vector<uint32_t> comp(n, kNone), stack;
  uint32_t next = 0;
  for (size_t seed = 0; seed < n; ++seed) {
    if (comp[seed] != kNone) continue;
    comp[seed] = next;
    stack.assign(1, uint32_t(seed));
    while (!stack.empty()) {
      const uint32_t v = stack.back();
      stack.pop_back();
      for (uint32_t k = adj.offsets[v]; k < adj.offsets[v + 1]; ++k)
        if (comp[adj.neighbours[k]] == kNone) comp[adj.neighbours[k]] = next, stack.push_back(adj.neighbours[k]);
    }
    ++next;
  }
  if (count) *count = next;
  return comp;
}

} // namespace vbrdf
