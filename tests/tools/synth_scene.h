#pragma once
// Procedural test object for the synthesizer: a bumpy ground plate with a sphere, a torus and an
// open box standing on it (one mesh, several components, world +y up), with known, spatially
// varying per-vertex Phong parameters.
#include <cstdint>
#include <string>
#include <vector>

#include "synth_math.h"

namespace synth {

// Material regions (ids stored in the ground truth). Diffuse-only regions have ks == 0.
enum Region : int {
  kPlateMatte = 0,   // ks = 0
  kPlateGlossy = 1,  // ks 0.25..0.5, shininess 10..120 varying along the stripe
  kPlateDark = 2,    // kd 0.05..0.12, ks 0.35, shininess 60 (dark glossy plastic)
  kSphere = 3,       // ks 0.1..0.8 by latitude, shininess 2..200 by longitude
  kTorusMatte = 4,   // ks = 0
  kTorusGlossy = 5,  // ks 0.4, shininess 25
  kBoxSide = 6,      // ks = 0
  kBoxTop = 7,       // ks 0.7, shininess 150
  kRegionCount = 8
};
const char *region_name(int region);

struct Scene {
  std::vector<V3> pos, nrm;       // per vertex, world coordinates; normals unit, area-weighted
  std::vector<uint32_t> idx;      // triangles, counter-clockwise seen from outside
  std::vector<float> kd, ks, shininess;
  std::vector<V3> color;          // linear RGB, largest channel 1
  std::vector<int> region;
  std::vector<uint8_t> boundary;  // 1 = a 1-ring neighbour has another region
  V3 target;                      // point the cameras look at
  float frame_radius = 1;         // radius the cameras frame around target
  size_t vertex_count() const { return pos.size(); }
  size_t triangle_count() const { return idx.size() / 3; }
};

// Builds the scene with about `target_vertices` vertices (at least ~600).
Scene make_scene(int target_vertices);

} // namespace synth
