#pragma once
// Bounding-volume hierarchy over the scene's triangles for exact occlusion rays (cast shadows and
// camera visibility in the ground truth). Median split, deterministic build.
#include <cstdint>
#include <vector>

#include "synth_math.h"

namespace synth {

class Bvh {
 public:
  Bvh(const std::vector<V3> &pos, const std::vector<uint32_t> &idx);

  // True when the segment origin + t * dir, 0 < t < tmax, hits any triangle.
  bool occluded(V3 origin, V3 dir, float tmax) const;

 private:
  struct Node {
    float lo[3], hi[3];
    int first;  // leaf: first index into order_; inner: index of the left child (right = +1)
    int count;  // leaf: triangle count; inner: 0
  };
  void build(int self, int begin, int end, const std::vector<V3> &centroids);

  const std::vector<V3> &pos_;
  const std::vector<uint32_t> &idx_;
  std::vector<int> order_;
  std::vector<Node> nodes_;
};

} // namespace synth
