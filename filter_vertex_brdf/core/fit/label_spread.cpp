#include "fit/label_spread.h"

#include <algorithm>

namespace vbrdf {

SpreadRings spread_rings(const MeshAdjacency &adj, std::vector<uint8_t> seeded, const std::vector<uint8_t> &kept,
                         const std::vector<uint32_t> *component, uint32_t component_count) {
  const size_t n = adj.vertex_count();
  const size_t n_kept = std::min(n, kept.size());
  SpreadRings R;
  std::vector<uint8_t> reached = seeded;
  std::vector<uint32_t> frontier, next_frontier;
  auto queue_neighbours = [&](size_t v, std::vector<uint32_t> &q) {
    for (uint32_t k = adj.offsets[v]; k < adj.offsets[v + 1]; ++k) {
      const uint32_t u = adj.neighbours[k];
      if (!reached[u]) reached[u] = 1, q.push_back(u);
    }
  };
  for (size_t v = 0; v < n; ++v)
    if (seeded[v]) queue_neighbours(v, frontier);
  // Kept vertices still waiting for a label that can get one.
  size_t waiting = 0;
  if (component && component->size() == n) {
    std::vector<uint8_t> has_seed(component_count, 0);
    for (size_t v = 0; v < n; ++v)
      if (seeded[v]) has_seed[(*component)[v]] = 1;
    for (size_t v = 0; v < n_kept; ++v) waiting += kept[v] && !seeded[v] && has_seed[(*component)[v]];
  } else {
    for (size_t v = 0; v < n_kept; ++v) waiting += kept[v] && !seeded[v];
  }
  std::vector<std::vector<uint32_t>> rings;
  while (!frontier.empty() && waiting > 0) {
    for (uint32_t v : frontier) waiting -= v < n_kept && kept[v];  // (a reached vertex's component is seeded)
    rings.push_back(frontier);
    next_frontier.clear();
    for (uint32_t v : frontier) queue_neighbours(v, next_frontier);
    frontier.swap(next_frontier);
  }
  // Keep only what the kept vertices depend on: a ring-r vertex votes from its ring r - 1
  // neighbours (and the labelled ones), so walking the rings backwards from the kept vertices marks
  // every vertex whose label reaches one of them; the others are dropped (the same labels at the
  // kept vertices, a fraction of the votes when they are a subsample).
  std::vector<int32_t> ring_of(n, -1);
  for (size_t r = 0; r < rings.size(); ++r)
    for (uint32_t v : rings[r]) ring_of[v] = int32_t(r);
  std::vector<uint8_t> needed(n, 0);
  for (size_t r = rings.size(); r-- > 0;)
    for (uint32_t v : rings[r]) {
      if (!needed[v] && !(v < n_kept && kept[v])) continue;
      needed[v] = 1;
      if (r == 0) continue;
      for (uint32_t k = adj.offsets[v]; k < adj.offsets[v + 1]; ++k)
        if (ring_of[adj.neighbours[k]] == int32_t(r) - 1) needed[adj.neighbours[k]] = 1;
    }
  for (const std::vector<uint32_t> &ring : rings) {
    for (uint32_t v : ring)
      if (needed[v]) R.vertices.push_back(v);
    R.ring_end.push_back(R.vertices.size());
  }
  R.seeded = std::move(seeded);
  return R;
}

const SpreadRings &SpreadRingCache::rings(const MeshAdjacency &adj, std::vector<uint8_t> seeded,
                                          const std::vector<uint8_t> &kept, const std::vector<uint32_t> *component,
                                          uint32_t component_count) {
  for (const SpreadRings &r : kept_rings_)
    if (r.seeded == seeded) return r;
  constexpr size_t kKept = 4;  // the material stage alternates two sets
  if (kept_rings_.size() >= kKept) kept_rings_.erase(kept_rings_.begin());
  kept_rings_.push_back(spread_rings(adj, std::move(seeded), kept, component, component_count));
  return kept_rings_.back();
}

void spread_along_rings(const MeshAdjacency &adj, const SpreadRings &rings, int K, std::vector<int32_t> &label) {
  std::vector<int> count(size_t(std::max(K, 1)) + 1);
  std::vector<int32_t> ring_label;
  size_t begin = 0;
  for (size_t end : rings.ring_end) {
    ring_label.assign(end - begin, 0);
    for (size_t i = begin; i < end; ++i) {
      const uint32_t v = rings.vertices[i];
      std::fill(count.begin(), count.end(), 0);
      for (uint32_t k = adj.offsets[v]; k < adj.offsets[v + 1]; ++k) {
        const int32_t l = label[adj.neighbours[k]];
        if (l > 0 && l < int32_t(count.size())) ++count[size_t(l)];
      }
      ring_label[i - begin] = int32_t(std::max_element(count.begin() + 1, count.end()) - count.begin());
    }
    for (size_t i = begin; i < end; ++i) label[rings.vertices[i]] = ring_label[i - begin];
    begin = end;
  }
}

} // namespace vbrdf
