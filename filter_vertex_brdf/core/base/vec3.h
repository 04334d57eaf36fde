#pragma once
// The small vocabulary of the core: 3-vectors, pi (angles.h), the number formats (number_format.h) and the timer of the reports;
// one definition instead of a copy per file. 3-vectors come in three forms, each where it fits:
//  - plain float[3] / std::array<float, 3> at interfaces and in storage (the layout MeshView, the
//    samples and the GL buffers use), with dot3 / cross3 / normalize3 below;
//  - Vec3 by value, where geometry reads best as formulas (coverage's light search);
//  - vcglib's Point3 only where vcglib's own API takes it (shots, kd-tree, ray caster), with
//    vcglib's operators; double-precision calibration maths uses OpenCV's / Eigen's types.
#include <chrono>
#include <cmath>
#include <sstream>
#include <string>

#include "base/angles.h"         // kPi
#include "base/number_format.h"  // fixed, percent

namespace vbrdf {

template <typename T>
inline T dot3(const T *a, const T *b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

template <typename T>
inline void cross3(const T *a, const T *b, T *out) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

// Scales v to unit length and returns its former length; a zero (or non-finite-length) vector is
// left as it is (no NaN).
template <typename T>
inline T normalize3(T *v) {
  const T n = std::sqrt(dot3(v, v));
  if (n > 0 && std::isfinite(n))
    for (int i = 0; i < 3; ++i) v[i] /= n;
  return n;
}

// A float 3-vector by value.
struct Vec3 {
  float x = 0, y = 0, z = 0;
};
inline Vec3 vec3_of(const float *p) { return {p[0], p[1], p[2]}; }
inline void store(Vec3 a, float *out) { out[0] = a.x, out[1] = a.y, out[2] = a.z; }
inline float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 add(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 scale(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
// Unit length; the zero vector stays zero (no NaN).
inline Vec3 normalized(Vec3 a) {
  const float l = std::sqrt(dot(a, a));
  return l > 0 ? scale(a, 1 / l) : Vec3{0, 0, 0};
}
// v mirrored about the unit normal n: 2 (n.v) n - v (the thesis's R for v = L).
inline Vec3 reflect_about(Vec3 v, Vec3 n) { return add(scale(n, 2 * dot(n, v)), scale(v, -1)); }

// Seconds since `start` on the steady clock: the stage timings of the reports.
using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

} // namespace vbrdf
