#pragma once
// Colour differences: linear sRGB (D65) -> CIE XYZ -> CIELAB (D65) and the CIEDE2000 formula.
// Used to score colour corrections (chart patches) and, later, photos against renderings.
// Linear sRGB values are relative to a perfect white reflector = (1, 1, 1); nothing is clamped
// (negative or > 1 values from a fitted correction still convert).
#include <cstddef>

namespace vbrdf {

// IEC 61966-2-1 matrix; the white (1,1,1) maps to the D65 white point with Y = 1.
void linear_srgb_to_xyz(const float rgb[3], float xyz[3]);

// CIELAB relative to the D65 white of linear_srgb_to_xyz (L* in [0,100] for Y in [0,1]).
void xyz_to_lab(const float xyz[3], float lab[3]);
void linear_srgb_to_lab(const float rgb[3], float lab[3]);

// CIEDE2000 (Sharma, Wu, Dalal 2005) with kL = kC = kH = 1. Symmetric, 0 for equal colours.
double ciede2000(const float lab1[3], const float lab2[3]);

// CIEDE2000 between two linear sRGB colours.
double delta_e2000_linear_srgb(const float rgb1[3], const float rgb2[3]);

// Mean CIEDE2000 over n pairs of linear sRGB colours (rows of 3 floats). Pairs whose `use` entry is
// false are skipped (`use` may be null). Returns 0 when no pair is used; `max_out` (optional)
// receives the largest difference.
double mean_delta_e2000(const float (*rgb1)[3], const float (*rgb2)[3], size_t n, const bool *use = nullptr,
                        double *max_out = nullptr);

} // namespace vbrdf
