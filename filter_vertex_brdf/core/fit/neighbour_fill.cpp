#include "fit/neighbour_fill.h"
#include "base/mesh_adjacency.h"
#include "base/vec3.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <vcg/space/index/kdtree/kdtree.h>

namespace vbrdf {

namespace {

using Adjacency = MeshAdjacency;

// The weighted average of the modelled neighbours of v (model[u] != 0); false when there is none.
bool average_of_neighbours(const MeshView &mesh, const Adjacency &adj, const std::vector<uint8_t> &model,
                           const VertexFit *fits, size_t v, float min_length, VertexFit &out) {
  double wsum = 0, rho[3] = {0, 0, 0}, ks = 0, log_alpha = 0, w_alpha = 0;
  const float *p = mesh.positions + 3 * v, *nv = mesh.normals + 3 * v;
  for (uint32_t k = adj.offsets[v]; k < adj.offsets[v + 1]; ++k) {
    const uint32_t u = adj.neighbours[k];
    if (!model[u]) continue;
    const VertexFit &f = fits[u];
    const float *q = mesh.positions + 3 * u;
    const float d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    const float length = std::max(std::sqrt(dot3(d, d)), min_length);
    double w = (std::max(dot3(nv, mesh.normals + 3 * u), 0.0f) + 0.05) / length;
    if (f.status == kFitFromNeighbours || f.status == kFitFromWeakSamples) w *= 0.5;
    if (!(w > 0) || !std::isfinite(w)) continue;
    wsum += w;
    for (int c = 0; c < 3; ++c) rho[c] += w * double(f.kd) * double(f.color[c]);
    ks += w * double(f.ks);
    if (f.ks > 0 && f.shininess > 0) log_alpha += w * std::log(double(f.shininess)), w_alpha += w;
  }
  if (!(wsum > 0)) return false;
  out = VertexFit{{0, 0, 0}, 0, 0, 0, 0, 0, 0, 0, kFitFromNeighbours, 0};
  for (double &r : rho) r /= wsum;
  set_kd_color(rho, out);
  if (w_alpha > 0) {  // a lobe only where some neighbour has one
    out.ks = float(ks / wsum);
    out.shininess = out.ks > 0 ? float(std::exp(log_alpha / w_alpha)) : 0.0f;
  }
  return true;
}

} // namespace

NeighbourFillStats fill_from_neighbours(const MeshView &mesh, const uint8_t *seen, int unseen_rings, VertexFit *fits) {
  NeighbourFillStats stats;
  const size_t n = mesh.vertex_count;
  std::vector<uint8_t> model(n);
  size_t missing = 0;
  for (size_t v = 0; v < n; ++v) {
    model[v] = has_model(fits[v]) ? 1 : 0;
    missing += !model[v] && seen[v];
  }
  if (missing == 0 && unseen_rings <= 0) return stats;
  const Adjacency adj = build_mesh_adjacency(mesh);
  const float min_length = 1e-6f * std::max(compute_bounds(mesh).diagonal(), 1e-30f);
  std::vector<uint32_t> front;
  std::vector<VertexFit> filled;
  // Ring 1: every eligible vertex next to a modelled one; later rings: the eligible neighbours of
  // the vertices the previous ring filled (so the walk costs O(edges), not O(rings x vertices)).
  const auto eligible = [&](uint32_t v, int ring) { return !model[v] && (seen[v] || ring <= unseen_rings); };
  std::vector<uint8_t> queued(n, 0);
  for (size_t v = 0; v < n; ++v) {
    if (!eligible(uint32_t(v), 1)) continue;
    for (uint32_t k = adj.offsets[v]; k < adj.offsets[v + 1]; ++k)
      if (model[adj.neighbours[k]]) {
        front.push_back(uint32_t(v));
        queued[v] = 1;
        break;
      }
  }
  for (int ring = 1; !front.empty(); ++ring) {
    stats.rings = ring;
    filled.assign(front.size(), VertexFit());
    std::vector<uint8_t> ok(front.size(), 0);
#pragma omp parallel for schedule(static)
    for (long long i = 0; i < (long long)front.size(); ++i)
      ok[size_t(i)] = average_of_neighbours(mesh, adj, model, fits, front[size_t(i)], min_length, filled[size_t(i)]);
    std::vector<uint32_t> next;
    for (size_t i = 0; i < front.size(); ++i) {  // commit after the pass: order-independent
      queued[front[i]] = 0;
      if (!ok[i]) continue;  // no usable weight: left for a later ring's neighbours to retry
      fits[front[i]] = filled[i];
      model[front[i]] = 1;
      ++(seen[front[i]] ? stats.filled_seen : stats.filled_unseen);
    }
    for (size_t i = 0; i < front.size(); ++i) {
      if (!ok[i]) continue;
      const uint32_t v = front[i];
      for (uint32_t k = adj.offsets[v]; k < adj.offsets[v + 1]; ++k) {
        const uint32_t u = adj.neighbours[k];
        if (!queued[u] && eligible(u, ring + 1)) queued[u] = 1, next.push_back(u);
      }
    }
    front.swap(next);
  }
  // Seen vertices in parts of the mesh without any modelled vertex (a small separate piece whose
  // samples are all shadowed or clipped): the nearest modelled vertex in space (vcglib kd-tree).
  std::vector<uint32_t> isolated, sources;
  for (size_t v = 0; v < n; ++v) {
    if (seen[v] && !model[v]) isolated.push_back(uint32_t(v));
    if (model[v]) sources.push_back(uint32_t(v));
  }
  if (!isolated.empty() && !sources.empty()) {
    std::vector<vcg::Point3f> points(sources.size());
    for (size_t i = 0; i < sources.size(); ++i) {
      const float *q = mesh.positions + 3 * size_t(sources[i]);
      points[i] = vcg::Point3f(q[0], q[1], q[2]);
    }
    vcg::KdTree<float> tree(vcg::ConstDataWrapper<vcg::Point3f>(points.data(), int(points.size())));
    for (uint32_t v : isolated) {
      const float *p = mesh.positions + 3 * size_t(v);
      unsigned int nearest = 0;
      float distance = 0;
      tree.doQueryClosest(vcg::Point3f(p[0], p[1], p[2]), nearest, distance);
      VertexFit f = fits[sources[nearest]];
      f.status = kFitFromNeighbours;
      f.dq = f.sq = f.rmse = 0;
      f.iterations = 0;
      f.converged = 0;
      fits[v] = f;
      ++stats.filled_seen;
      ++stats.filled_nearest;
    }
  }
  for (size_t v = 0; v < n; ++v) stats.unreachable_seen += seen[v] && !has_model(fits[v]);
  return stats;
}

} // namespace vbrdf
