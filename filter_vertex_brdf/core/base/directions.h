#pragma once
// Direction sets on the unit sphere: octahedral cells (binning normals) and golden-angle spirals
// (candidate directions, evenly spread). Plain float[3]; float arithmetic throughout, in a fixed
// order, so that every caller's directions are the same to the bit wherever they are computed.
#include <algorithm>
#include <cmath>

#include "base/angles.h"

namespace vbrdf {

// The cell of direction n on a res x res octahedral grid, in [0, res * res): the lower hemisphere
// folded onto the octahedron's outer triangles. n need not be unit; a zero (or NaN) vector is cell 0.
inline int octahedral_cell(const float n[3], int res) {
  const float a = std::fabs(n[0]) + std::fabs(n[1]) + std::fabs(n[2]);
  if (!(a > 0)) return 0;
  float u = n[0] / a, v = n[1] / a;
  if (n[2] < 0) {
    const float nu = (1 - std::fabs(v)) * (u >= 0 ? 1 : -1), nv = (1 - std::fabs(u)) * (v >= 0 ? 1 : -1);
    u = nu, v = nv;
  }
  const int i = std::min(res - 1, std::max(0, int((u * 0.5f + 0.5f) * float(res))));
  const int j = std::min(res - 1, std::max(0, int((v * 0.5f + 0.5f) * float(res))));
  return j * res + i;
}

// The i-th direction of a golden-angle spiral at height z in [-1, 1]: azimuth i times the golden
// angle pi (3 - sqrt 5), radius sqrt(1 - z^2).
inline void golden_spiral_direction(int i, float z, float out[3]) {
  const float r = std::sqrt(std::max(0.0f, 1 - z * z));
  const float phi = float(i) * kPi * (3 - std::sqrt(5.0f));
  out[0] = r * std::cos(phi), out[1] = r * std::sin(phi), out[2] = z;
}

// Direction i of `count` spread evenly over the whole sphere (the Fibonacci sphere): z from near 1
// down to near -1 in equal steps.
inline void fibonacci_sphere_direction(int i, int count, float out[3]) {
  golden_spiral_direction(i, 1 - (2 * float(i) + 1) / float(count), out);
}

// Direction i of `count` spread evenly over the cap z >= z_min (z_min in [-1, 1]).
inline void fibonacci_cap_direction(int i, int count, float z_min, float out[3]) {
  golden_spiral_direction(i, z_min + (1 - z_min) * (float(i) + 0.5f) / float(count), out);
}

} // namespace vbrdf
