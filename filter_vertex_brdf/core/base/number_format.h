#pragma once
// The number formats of the reports, logs and messages: one definition each.
#include <cstdio>
#include <sstream>
#include <string>

namespace vbrdf {

// "1.23" for fixed(1.234, 2).
inline std::string fixed(double v, int digits = 2) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

// "12.3%" for percent(123, 1000): shares ("0%" when `whole` is 0).
inline std::string percent(double part, double whole) {
  return whole > 0 ? fixed(100.0 * part / whole, 1) + "%" : "0%";
}

// A printf `format` whose conversions take up to four doubles (%f, %g, %e, %.1f ...), at any length.
inline std::string formatted(const char *format, double a = 0, double b = 0, double c = 0, double d = 0) {
  const int n = std::snprintf(nullptr, 0, format, a, b, c, d);
  if (n <= 0) return "";
  std::string out(size_t(n) + 1, '\0');
  std::snprintf(&out[0], out.size(), format, a, b, c, d);
  out.resize(size_t(n));
  return out;
}

// "1 viewpoint", "3 viewpoints": a count and its noun, plural with an "s" unless the count is 1.
inline std::string counted(size_t n, const std::string &noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

// Three significant digits, "%.3g": errors and scale labels.
inline std::string three_significant(double v) { return formatted("%.3g", v); }

} // namespace vbrdf
