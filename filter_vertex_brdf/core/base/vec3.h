#pragma once
// The small vocabulary of the core: 3-vectors on plain arrays (the layout MeshView and the GL
// buffers use), pi, and the number formats and timer of the reports; one definition instead of a
// copy per file. Where a file works with vcglib's
// Point3 (camera, visibility_cpu) it uses vcglib's operators instead.
#include <chrono>
#include <cmath>
#include <sstream>
#include <string>

namespace vbrdf {

constexpr double kPi = 3.14159265358979323846;

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

// "1.23" for fixed(1.234, 2): the number format of the reports and logs.
inline std::string fixed(double v, int digits = 2) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

// "12.3%" for percent(123, 1000): shares in reports ("0%" when `whole` is 0).
inline std::string percent(double part, double whole) {
  return whole > 0 ? fixed(100.0 * part / whole, 1) + "%" : "0%";
}

// Seconds since `start` on the steady clock: the stage timings of the reports.
using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

} // namespace vbrdf
