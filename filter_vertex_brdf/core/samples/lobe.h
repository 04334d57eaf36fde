#pragma once
// The specular lobe's form: the cosine that the shininess alpha raises to a power.
//   PhongRE  s = R.E, R = 2(N.L)N - L  (the thesis's Phong lobe)
//   BlinnNH  s = N.H, H = (L + E)/|L + E|  (Blinn-Phong; follows microfacet highlights, whose
//            lobe is a function of N.H, better away from the camera axis)
// E is the unit vector from the surface point to the camera centre, L towards the light.
// Every stage that evaluates the lobe (the gatherer's Sample::lobe_cos, the CPU and GPU fits, the
// material stage, the relight renderer and the sample-based evaluation) takes the cosine from
// lobe_cosine(), so one setting (PhongFitOptions::lobe) decides the form for all of them; the
// result stores it (per-vertex attribute lobe_form, and a PLY header comment).
//
// Thresholds stated on R.E (T_s, the broad-lobe threshold) apply to N.H through
// lobe_threshold(): in the plane of incidence the N-H angle is half the R-E angle, so
// R.E > t  <=>  N.H > cos(acos(t)/2) = sqrt((1 + t)/2) there.
#include <cmath>
#include <cstdint>
#include <string>

namespace vbrdf {

enum class LobeForm : uint8_t { PhongRE = 0, BlinnNH = 1 };

// "phong_r_dot_e" / "blinn_n_dot_h" (PLY comment, report, command-line value).
inline const char *lobe_form_name(LobeForm f) { return f == LobeForm::BlinnNH ? "blinn_n_dot_h" : "phong_r_dot_e"; }
// Short label for reports: "R.E" / "N.H".
inline const char *lobe_form_label(LobeForm f) { return f == LobeForm::BlinnNH ? "N.H" : "R.E"; }

// Parses a name of lobe_form_name() or the short forms "re", "phong", "nh", "blinn"; false if unknown.
inline bool parse_lobe_form(const std::string &text, LobeForm &out) {
  if (text == "phong_r_dot_e" || text == "re" || text == "phong") return out = LobeForm::PhongRE, true;
  if (text == "blinn_n_dot_h" || text == "nh" || text == "blinn") return out = LobeForm::BlinnNH, true;
  return false;
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
