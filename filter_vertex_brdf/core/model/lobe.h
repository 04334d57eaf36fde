#pragma once
// The specular lobe's form: the cosine s the lobe is a function of, and the function g(s, alpha)
// (1 at s = 1) that k_s multiplies.
//   PhongRE  s = R.E, R = 2(N.L)N - L, g = s^alpha  (the thesis's Phong lobe)
//   BlinnNH  s = N.H, H = (L + E)/|L + E|, g = s^alpha  (Blinn-Phong; follows microfacet
//            highlights, whose lobe is a function of N.H, better away from the camera axis)
//   GgxNH    s = N.H, g = [a^2 / (a^2 + (1 - s^2)(1 - a^2))]^2, a^2 = 2 / (alpha + 2): the GGX
//            (Trowbridge-Reitz) microfacet distribution D(N.H) / D(1) of roughness a, with alpha
//            the usual Phong-equivalent exponent of that roughness (alpha = 2/a^2 - 2, the shared
//            scenes' `phong_shininess_approx`). Same peak curvature family, but the long tails of
//            real highlights: with the true parameters it predicts the spot pair's clean pixels at
//            0.62 / 0.59 against Blinn-Phong's 0.83 / 0.84 (docs/decisions/true_reflectance.md).
// E is the unit vector from the surface point to the camera centre, L towards the light.
// Every stage that evaluates the lobe (the gatherer's Sample::lobe_cos, the CPU and GPU fits, the
// material stage, the relight renderer and the sample-based evaluation) takes the cosine from
// lobe_cosine(), so one setting (ReflectanceFitOptions::lobe) decides the form for all of them; the
// result stores it (per-vertex attribute lobe_form, and a PLY header comment).
//
// Thresholds stated on R.E (T_s, the broad-lobe threshold) apply to N.H through
// lobe_threshold(): in the plane of incidence the N-H angle is half the R-E angle, so
// R.E > t  <=>  N.H > cos(acos(t)/2) = sqrt((1 + t)/2) there.
#include <cmath>
#include <cstdint>
#include <string>

namespace vbrdf {

enum class LobeForm : uint8_t { PhongRE = 0, BlinnNH = 1, GgxNH = 2 };
constexpr int kLobeFormCount = 3;

// "phong_r_dot_e" / "blinn_n_dot_h" / "ggx_n_dot_h" (PLY comment, report, command-line value).
inline const char *lobe_form_name(LobeForm f) {
  return f == LobeForm::GgxNH ? "ggx_n_dot_h" : f == LobeForm::BlinnNH ? "blinn_n_dot_h" : "phong_r_dot_e";
}
// Short label for reports: "R.E" / "N.H" / "GGX N.H".
inline const char *lobe_form_label(LobeForm f) {
  return f == LobeForm::GgxNH ? "GGX N.H" : f == LobeForm::BlinnNH ? "N.H" : "R.E";
}

// Parses a name of lobe_form_name() or the short forms "re", "phong", "nh", "blinn", "ggx"; false if unknown.
inline bool parse_lobe_form(const std::string &text, LobeForm &out) {
  if (text == "phong_r_dot_e" || text == "re" || text == "phong") return out = LobeForm::PhongRE, true;
  if (text == "blinn_n_dot_h" || text == "nh" || text == "blinn") return out = LobeForm::BlinnNH, true;
  if (text == "ggx_n_dot_h" || text == "ggx") return out = LobeForm::GgxNH, true;
  return false;
}

// True for the forms whose g is s^alpha (the fits' ln s shortcuts and s^(2 alpha) = (s^alpha)^2).
inline bool lobe_is_power(LobeForm f) { return f != LobeForm::GgxNH; }

// GGX's squared roughness a^2 for a Phong-equivalent exponent alpha >= 0: in (0, 1].
inline double ggx_a2(double alpha) { return 2.0 / (alpha + 2.0); }
// The GGX lobe from u = 1 - s^2 in [0, 1] and a2 = ggx_a2(alpha) (loops over many samples at one
// alpha compute a2 once): in (0, 1], 1 at u = 0.
inline double ggx_lobe_of_u_a2(double u, double a2) {
  const double r = a2 / (a2 + u * (1 - a2));
  return r * r;
}
// The GGX lobe from u = 1 - s^2 in [0, 1] (the material stage keeps u per sample): in (0, 1], 1 at u = 0.
inline double ggx_lobe_of_u(double u, double alpha) { return ggx_lobe_of_u_a2(u, ggx_a2(alpha)); }

// The photo's pixel footprint (Sample::footprint, samples/footprint.h): a pixel, and the bilinear
// sample at the vertex, average the surface over a patch whose shading normals spread around the
// vertex's; a sharp highlight is then seen broader and lower than the surface's own lobe. For
// GGX the footprint's normal (slope) variance v, summed over both axes, adds to the squared
// roughness at the same lobe energy: a Beckmann-like distribution of roughness a has slope variance
// a^2 / 2 per axis, so a^2 + v is the matched sum (geometric specular antialiasing, Kaplanyan et al.
// 2016, Tokuyoshi & Kaplanyan 2019; they add 2 v, which is safer against aliasing but broader than
// the photos: on bunny_two_materials_dir32 it left the relit error 1 % higher). The lobe seen
// through the footprint is (a^2 / a_f^2) D(N.H; a_f) / D(1; a_f) with a_f^2 = min(a^2 + v, 1): g at
// v = 0, lower and broader above. The fits and every prediction of a photo's pixel take it, so that
// alpha is the surface's own (the exponent compared with the truth) and another camera is predicted
// through its own footprint. The power forms (R.E, N.H) ignore v (the thesis's lobe, kept as it
// was). v is clamped to kMaxFootprintVariance (Tokuyoshi & Kaplanyan's clamp, 0.18).
constexpr double kMaxFootprintVariance = 0.18;

// The floor on alpha ln s of the power forms: exp of it is 1.8e-35, far above float's denormals, and
// ln 0 never reaches exp.
constexpr double kLobeLogFloor = -80.0;

// GGX seen through a footprint whose variance is already clamped, v_clamped = min(v,
// kMaxFootprintVariance) >= 0 (clamped_footprint), from u = 1 - s^2 and a2 = ggx_a2(alpha): no
// branch, for loops over many a2 at one sample (vectorises); at 0 equal to ggx_lobe_of_u_a2 up to
// rounding.
inline double ggx_lobe_through_clamped_footprint(double u, double a2, double v_clamped) {
  const double a2f = std::fmin(a2 + v_clamped, 1.0), den = a2f + u * (1 - a2f);
  return a2 * a2f / (den * den);  // (a^2 / a_f^2) (a_f^2 / den)^2 with one division
}
inline double clamped_footprint(double v) { return v > 0 ? std::fmin(v, kMaxFootprintVariance) : 0.0; }

// GGX seen through a footprint of normal variance v (see above; v <= 0 or NaN: none), from
// u = 1 - s^2 and a2 = ggx_a2(alpha): in (0, 1]; exactly ggx_lobe_of_u_a2(u, a2) at v = 0.
inline double ggx_lobe_through_footprint(double u, double a2, double v) {
  if (!(v > 0)) return ggx_lobe_of_u_a2(u, a2);
  return ggx_lobe_through_clamped_footprint(u, a2, clamped_footprint(v));
}

// g(s, alpha) of the form (see the header comment), for alpha >= 0. s <= 0 gives 0; s is clamped at
// 1. Power forms: exp(max(alpha ln s, kLobeLogFloor)) (no ln 0, no overflow, no denormals). GGX: a^2 in
// (0, 1] for alpha >= 0, the denominator >= a^2 > 0, so g is in (0, 1] for s > 0 (never 0: the
// GGX tail is long; 1e-38-ish only for alpha near 1e38).
// `footprint`: the sample's footprint variance v (above; GGX only), 0 = the surface's own lobe.
inline double lobe_value(LobeForm f, double s, double alpha, double footprint = 0) {
  if (!(s > 0)) return 0;
  s = s < 1 ? s : 1;
  if (lobe_is_power(f)) {
    const double x = alpha * std::log(s);
    return std::exp(x > kLobeLogFloor ? x : kLobeLogFloor);
  }
  return ggx_lobe_through_footprint(1 - s * s, ggx_a2(alpha), footprint);
}

// d g / d ln(alpha) at (s, alpha, footprint): the fits' Newton step on t = ln alpha. 0 for s <= 0,
// and for s >= 1 without a footprint (there g = 1 whatever alpha; through a footprint the peak
// a^2 / a_f^2 still depends on alpha); 0 where a_f^2 is clamped at 1 and s < 1 would not matter.
inline double lobe_dvalue_dlog_alpha(LobeForm f, double s, double alpha, double footprint = 0) {
  if (!(s > 0)) return 0;
  const double v = lobe_is_power(f) || !(footprint > 0) ? 0.0 : std::fmin(footprint, kMaxFootprintVariance);
  if (s >= 1 && v == 0) return 0;
  s = s < 1 ? s : 1;
  if (lobe_is_power(f)) return lobe_value(f, s, alpha) * std::log(s) * alpha;
  const double a2 = 2.0 / (alpha + 2.0), u = 1 - s * s;
  const double da2_dt = -2 * alpha / ((alpha + 2) * (alpha + 2));  // d a^2 / d ln alpha
  const double a2f = a2 + v;
  if (a2f >= 1) return da2_dt;  // g = a^2 (a_f^2 clamped at 1: r = 1)
  const double den = a2f + u * (1 - a2f), r = a2f / den;
  // g = (a^2 / a_f^2) r^2 with d a_f^2 / d a^2 = 1 and d r^2 / d a_f^2 = 2 r u / den^2.
  const double dg_da2 = r * r * (a2f - a2) / (a2f * a2f) + a2 / a2f * 2 * r * u / (den * den);
  return dg_da2 * da2_dt;
}

// The lobe's cosine for unit vectors n, l (towards the light) and e (towards the camera).
// N.H with L = -E (H undefined) is 0.
inline float lobe_cosine(LobeForm f, const float n[3], const float l[3], const float e[3]) {
  const float nl = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
  const float ne = n[0] * e[0] + n[1] * e[1] + n[2] * e[2];
  const float le = l[0] * e[0] + l[1] * e[1] + l[2] * e[2];
  if (f == LobeForm::PhongRE) return 2 * nl * ne - le;  // R.E
  const float h2 = 2 + 2 * le;                          // |L + E|^2
  return h2 > 1e-12f ? (nl + ne) / std::sqrt(h2) : 0.0f;
}

// A threshold stated on R.E, as a threshold on the form's cosine (see the header comment).
inline float lobe_threshold(LobeForm f, float t_re) {
  if (f == LobeForm::PhongRE) return t_re;
  const float t = std::fmin(std::fmax(t_re, -1.0f), 1.0f);
  return std::sqrt((1 + t) / 2);
}

// The R.E that a cosine of the form corresponds to in the plane of incidence (2 c^2 - 1 for N.H):
// DQ/SQ's sampling term stays on the thesis's R.E scale whichever form is fitted.
inline float lobe_as_r_dot_e(LobeForm f, float c) {
  if (f == LobeForm::PhongRE) return c;
  return c > 0 ? 2 * c * c - 1 : -1.0f;
}

} // namespace vbrdf
