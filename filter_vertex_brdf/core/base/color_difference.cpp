#include "base/color_difference.h"
#include "base/vec3.h"

#include <algorithm>
#include <cmath>

namespace vbrdf {

namespace {
constexpr double kSrgbToXyz[3][3] = {{0.4124564, 0.3575761, 0.1804375},
                                     {0.2126729, 0.7151522, 0.0721750},
                                     {0.0193339, 0.1191920, 0.9503041}};

double white(int i) { return kSrgbToXyz[i][0] + kSrgbToXyz[i][1] + kSrgbToXyz[i][2]; }

// CIE 1976 companding; cbrt keeps the sign for the negative values a fitted correction can give.
double lab_f(double t) {
  constexpr double d = 6.0 / 29.0;
  return t > d * d * d ? std::cbrt(t) : t / (3 * d * d) + 4.0 / 29.0;
}


// Hue angle in degrees in [0, 360); 0 for a neutral colour (the formula's convention).
double hue_deg(double b, double a) {
  if (a == 0 && b == 0) return 0;
  const double h = degrees(std::atan2(b, a));
  return h < 0 ? h + 360 : h;
}
} // namespace

void linear_srgb_to_xyz(const float rgb[3], float xyz[3]) {
  for (int i = 0; i < 3; ++i)
    xyz[i] = float(kSrgbToXyz[i][0] * rgb[0] + kSrgbToXyz[i][1] * rgb[1] + kSrgbToXyz[i][2] * rgb[2]);
}

void xyz_to_lab(const float xyz[3], float lab[3]) {
  const double fx = lab_f(xyz[0] / white(0)), fy = lab_f(xyz[1] / white(1)), fz = lab_f(xyz[2] / white(2));
  lab[0] = float(116 * fy - 16);
  lab[1] = float(500 * (fx - fy));
  lab[2] = float(200 * (fy - fz));
}

void linear_srgb_to_lab(const float rgb[3], float lab[3]) {
  float xyz[3];
  linear_srgb_to_xyz(rgb, xyz);
  xyz_to_lab(xyz, lab);
}

double ciede2000(const float lab1[3], const float lab2[3]) {
  const double L1 = lab1[0], a1 = lab1[1], b1 = lab1[2];
  const double L2 = lab2[0], a2 = lab2[1], b2 = lab2[2];
  const double c_bar = 0.5 * (std::hypot(a1, b1) + std::hypot(a2, b2));
  const double c7 = std::pow(c_bar, 7), p25 = std::pow(25.0, 7);
  const double g = 0.5 * (1 - std::sqrt(c7 / (c7 + p25)));
  const double a1p = (1 + g) * a1, a2p = (1 + g) * a2;
  const double c1p = std::hypot(a1p, b1), c2p = std::hypot(a2p, b2);
  const double h1p = hue_deg(b1, a1p), h2p = hue_deg(b2, a2p);

  const double dLp = L2 - L1, dCp = c2p - c1p;
  double dhp = 0;
  if (c1p * c2p != 0) {
    dhp = h2p - h1p;
    if (dhp > 180) dhp -= 360;
    else if (dhp < -180) dhp += 360;
  }
  const double dHp = 2 * std::sqrt(c1p * c2p) * std::sin(radians(dhp / 2));

  const double Lp_bar = 0.5 * (L1 + L2), Cp_bar = 0.5 * (c1p + c2p);
  double hp_bar = h1p + h2p;
  if (c1p * c2p != 0) {
    if (std::fabs(h1p - h2p) <= 180) hp_bar = 0.5 * (h1p + h2p);
    else if (h1p + h2p < 360) hp_bar = 0.5 * (h1p + h2p + 360);
    else hp_bar = 0.5 * (h1p + h2p - 360);
  }
  const double t = 1 - 0.17 * std::cos(radians(hp_bar - 30)) + 0.24 * std::cos(radians(2 * hp_bar)) +
                   0.32 * std::cos(radians(3 * hp_bar + 6)) - 0.20 * std::cos(radians(4 * hp_bar - 63));
  const double d_theta = 30 * std::exp(-std::pow((hp_bar - 275) / 25, 2));
  const double cp7 = std::pow(Cp_bar, 7);
  const double rc = 2 * std::sqrt(cp7 / (cp7 + p25));
  const double l50 = (Lp_bar - 50) * (Lp_bar - 50);
  const double sl = 1 + 0.015 * l50 / std::sqrt(20 + l50);
  const double sc = 1 + 0.045 * Cp_bar;
  const double sh = 1 + 0.015 * Cp_bar * t;
  const double rt = -std::sin(radians(2 * d_theta)) * rc;
  const double tl = dLp / sl, tc = dCp / sc, th = dHp / sh;
  return std::sqrt(std::max(0.0, tl * tl + tc * tc + th * th + rt * tc * th));
}

double delta_e2000_linear_srgb(const float rgb1[3], const float rgb2[3]) {
  float lab1[3], lab2[3];
  linear_srgb_to_lab(rgb1, lab1);
  linear_srgb_to_lab(rgb2, lab2);
  return ciede2000(lab1, lab2);
}

double mean_delta_e2000(const float (*rgb1)[3], const float (*rgb2)[3], size_t n, const bool *use, double *max_out) {
  double sum = 0, mx = 0;
  size_t count = 0;
  for (size_t i = 0; i < n; ++i) {
    if (use && !use[i]) continue;
    const double d = delta_e2000_linear_srgb(rgb1[i], rgb2[i]);
    sum += d;
    mx = std::max(mx, d);
    ++count;
  }
  if (max_out) *max_out = mx;
  return count ? sum / double(count) : 0.0;
}

} // namespace vbrdf
