#pragma once
// Pi and the degree / radian conversions: one definition for the whole core.
//
// Each conversion keeps the order of operations its callers use, so that a figure printed or
// compared keeps its last bit: radians() and degrees() multiply first and divide second in double
// (a float argument is promoted first, exactly); degrees_f() multiplies in float and divides in
// double, as float code does with `x * 180 / kPi`. The constants serve loops that multiply by a
// precomputed factor (in double, or in float for the float-only coverage geometry).
namespace vbrdf {

constexpr double kPi = 3.14159265358979323846;
constexpr float kPiF = float(kPi);
constexpr double kRadiansPerDegree = kPi / 180.0;
constexpr float kRadiansPerDegreeF = kPiF / 180.0f;

// Degrees to radians: degrees * pi / 180 in double.
inline double radians(double degrees) { return degrees * kPi / 180.0; }
// Radians to degrees: radians * 180 / pi in double.
inline double degrees(double radians) { return radians * 180.0 / kPi; }
// A float angle to degrees: the product by 180 in float, the division by pi in double, rounded to float.
inline float degrees_f(float radians) { return float(radians * 180 / kPi); }

} // namespace vbrdf
