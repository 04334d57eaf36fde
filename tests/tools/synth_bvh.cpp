#include "synth_bvh.h"

#include <algorithm>
#include <cmath>

namespace synth {
namespace {

const int kLeafSize = 4;

// Moller-Trumbore; hits with t in (0, tmax) only.
bool hit_triangle(V3 o, V3 d, V3 a, V3 b, V3 c, float tmax) {
  const V3 e1 = b - a, e2 = c - a;
  const V3 p = cross(d, e2);
  const float det = dot(e1, p);
  if (std::fabs(det) < 1e-12f) return false;
  const float inv = 1.0f / det;
  const V3 s = o - a;
  const float u = dot(s, p) * inv;
  if (u < 0 || u > 1) return false;
  const V3 q = cross(s, e1);
  const float v = dot(d, q) * inv;
  if (v < 0 || u + v > 1) return false;
  const float t = dot(e2, q) * inv;
  return t > 0 && t < tmax;
}

bool hit_box(const float lo[3], const float hi[3], V3 o, V3 inv_d, float tmax) {
  float t0 = 0, t1 = tmax;
  for (int a = 0; a < 3; ++a) {
    float tn = (lo[a] - o[a]) * inv_d[a], tf = (hi[a] - o[a]) * inv_d[a];
    if (tn > tf) std::swap(tn, tf);
    t0 = std::max(t0, tn);
    t1 = std::min(t1, tf);
    if (t0 > t1) return false;
  }
  return true;
}

} // namespace

Bvh::Bvh(const std::vector<V3> &pos, const std::vector<uint32_t> &idx) : pos_(pos), idx_(idx) {
  const int n = int(idx.size() / 3);
  order_.resize(n);
  std::vector<V3> centroids(n);
  for (int t = 0; t < n; ++t) {
    order_[t] = t;
    centroids[t] = (pos[idx[3 * t]] + pos[idx[3 * t + 1]] + pos[idx[3 * t + 2]]) * (1.0f / 3);
  }
  nodes_.reserve(4 * size_t(n) / kLeafSize + 2);
  nodes_.push_back(Node());
  build(0, 0, n, centroids);
}

void Bvh::build(int self, int begin, int end, const std::vector<V3> &centroids) {
  Node node;
  float clo[3] = {1e30f, 1e30f, 1e30f}, chi[3] = {-1e30f, -1e30f, -1e30f};
  for (int a = 0; a < 3; ++a) node.lo[a] = 1e30f, node.hi[a] = -1e30f;
  for (int i = begin; i < end; ++i) {
    const int t = order_[i];
    for (int k = 0; k < 3; ++k) {
      const V3 p = pos_[idx_[3 * t + k]];
      for (int a = 0; a < 3; ++a) {
        node.lo[a] = std::min(node.lo[a], p[a]);
        node.hi[a] = std::max(node.hi[a], p[a]);
      }
    }
    for (int a = 0; a < 3; ++a) {
      clo[a] = std::min(clo[a], centroids[t][a]);
      chi[a] = std::max(chi[a], centroids[t][a]);
    }
  }
  if (end - begin <= kLeafSize) {
    node.first = begin;
    node.count = end - begin;
    nodes_[self] = node;
    return;
  }
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (chi[a] - clo[a] > chi[axis] - clo[axis]) axis = a;
  const int mid = (begin + end) / 2;
  // Ties broken by triangle index: the tree (and so every result) is the same on every run.
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                   [&](int a, int b) {
                     const float ca = centroids[a][axis], cb = centroids[b][axis];
                     return ca < cb || (ca == cb && a < b);
                   });
  node.first = int(nodes_.size());
  node.count = 0;
  nodes_[self] = node;
  nodes_.push_back(Node());
  nodes_.push_back(Node());
  build(node.first, begin, mid, centroids);
  build(node.first + 1, mid, end, centroids);
}

bool Bvh::occluded(V3 o, V3 d, float tmax) const {
  // Infinite components are fine for the slab test (IEEE: 0 * inf only when o is on a slab).
  const V3 inv(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node &n = nodes_[stack[--top]];
    if (!hit_box(n.lo, n.hi, o, inv, tmax)) continue;
    if (n.count == 0) {
      stack[top++] = n.first;
      stack[top++] = n.first + 1;
      continue;
    }
    for (int i = n.first; i < n.first + n.count; ++i) {
      const int t = order_[i];
      if (hit_triangle(o, d, pos_[idx_[3 * t]], pos_[idx_[3 * t + 1]], pos_[idx_[3 * t + 2]], tmax))
        return true;
    }
  }
  return false;
}

} // namespace synth
