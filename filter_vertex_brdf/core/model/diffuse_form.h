#pragma once
// The diffuse term's form: the factor d that k_d C multiplies, f_c = k_d d C_c + specular.
//   Lambert  d = N.L  (the thesis)
//   Coated   d = N.L T(max(N.L, c)) T(max(N.E, c)) / T(1)^2, c = kCoatMinCosine: a diffuse body
//            under a clear dielectric coat (varnish, glaze, wax, the plastic of most glossy
//            objects). Light enters and leaves through the coat, so the body's light is scaled by
//            the coat's Fresnel transmission T on the way in and on the way out (unpolarised
//            Fresnel, refractive index kCoatIndex). Normalised so that d = N.L at normal incidence
//            and exitance: k_d C is the albedo seen head-on.
// Why: a Lambertian k_d has no exit-angle term, so a vertex that one camera sees at a grazing
// angle gets a darker k_d than a camera facing it sees (spot: fitted/true albedo 0.77 at N.E < 0.1);
// a second camera, or relighting from another view, then disagrees. Reciprocity makes the form
// testable from one camera: T on the light side is the same curve as on the view side, and d / N.L
// is symmetric in N.L and N.E.
// Why the clamp, on both sides: a real coat is rough, and a rough coat transmits much more at
// grazing angles than a smooth one (the shared scenes' GGX coats: 0.70 of the head-on value at 85
// degrees where a smooth coat gives 0.41). T(max(cos, 0.2)) follows the rough coats' curves within
// 0.04-0.18 from 0 to 85 degrees. Measured (docs/decisions/diffuse_form.md, tests/benchmark/
// oracle_eval.py): with the true albedo and lobe, clamping the light side too cut the spot pair's
// clean-pixel error from 0.76 to 0.66; in the fit, 0.2 beat 0.15, 0.25 and 0.3 over the spot pair
// and the bunny and teapot scenes together.
//
// Safeguards: both cosines are clamped below at kCoatMinCosine before T, so d never falls below
// (T(c)/T(1))^2 N.L; d <= 0 exactly when N.L <= 0 (the value is N.L there, unchanged, so
// attached-shadow tests and signed checks still hold); finite for any finite input.
//
// Every stage takes d from diffuse_factor(): the gatherer stores it in Sample::d, so the CPU and GPU
// fits, DQ/SQ, the material stage, coverage and the sample-based evaluation use the form without
// knowing it; the relight renderer's shader and the live view evaluate the same expression (GLSL
// copy in shaders/reflectance_model.glsl). The result stores it (per-vertex attribute diffuse_form, PLY
// header comment).
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace vbrdf {

enum class DiffuseForm : uint8_t { Lambert = 0, Coated = 1 };

constexpr float kCoatIndex = 1.5f;       // refractive index of the coat (varnishes, plastics: 1.45-1.55)
constexpr float kCoatMinCosine = 0.2f;   // clamp on N.L and N.E before T (see "Why the clamp" above)

// How the fit's diffuse form is decided. Auto: a pilot fit on each form with photos held out picks
// it per scene (fit/diffuse_choice.h; docs/decisions/diffuse_form.md has the measurements behind
// it); Lambert / Coated: as given. The default is the table's (defaults.h kFitDiffuseChoice).
enum class DiffuseTermChoice { Auto = 0, Lambert = 1, Coated = 2 };

// "lambert" / "coated" (PLY comment, report, command-line value).
inline const char *diffuse_form_name(DiffuseForm f) { return f == DiffuseForm::Coated ? "coated" : "lambert"; }

// Parses diffuse_form_name() values; false if unknown.
inline bool parse_diffuse_form(const std::string &text, DiffuseForm &out) {
  if (text == "lambert") return out = DiffuseForm::Lambert, true;
  if (text == "coated") return out = DiffuseForm::Coated, true;
  return false;
}

// Unpolarised Fresnel transmission into a dielectric of index kCoatIndex at incidence cosine c
// (clamped to [0, 1]): 1 - (r_s^2 + r_p^2) / 2. T(1) = 0.96, T(0) = 0.
inline float coat_transmission(float c) {
  c = std::fmin(std::fmax(c, 0.0f), 1.0f);
  const float sin_t = std::sqrt(std::fmax(0.0f, 1.0f - c * c)) / kCoatIndex;
  const float cos_t = std::sqrt(std::fmax(0.0f, 1.0f - sin_t * sin_t));
  const float rs = (c - kCoatIndex * cos_t) / (c + kCoatIndex * cos_t);
  const float rp = (kCoatIndex * c - cos_t) / (kCoatIndex * c + cos_t);
  return 1.0f - 0.5f * (rs * rs + rp * rp);
}

// The diffuse factor d for the cosines N.L and N.E of unit vectors (see the header comment).
inline float diffuse_factor(DiffuseForm f, float n_dot_l, float n_dot_e) {
  if (f == DiffuseForm::Lambert || !(n_dot_l > 0)) return n_dot_l;
  const float t1 = coat_transmission(1.0f);
  return n_dot_l * coat_transmission(std::fmax(n_dot_l, kCoatMinCosine)) * coat_transmission(std::fmax(n_dot_e, kCoatMinCosine)) / (t1 * t1);
}

// The form over a mesh: one form everywhere, or, where a coated material lies beside a bare one
// (diffuse_choice.h's coat map), one per vertex.
struct DiffuseForms {
  DiffuseForm uniform = DiffuseForm::Lambert;            // where `coated` is null or too short
  std::shared_ptr<const std::vector<uint8_t>> coated;  // per vertex: 1 coated, 0 Lambert; null: uniform
  DiffuseForm at(size_t v) const {
    if (coated && v < coated->size()) return (*coated)[v] ? DiffuseForm::Coated : DiffuseForm::Lambert;
    return uniform;
  }
  bool varies() const { return coated != nullptr; }
  static DiffuseForms everywhere(DiffuseForm f) { return DiffuseForms{f, nullptr}; }
};

// "lambert", "coated", or "coated on N of M vertices" (report).
inline std::string describe_diffuse_forms(const DiffuseForms &forms) {
  if (!forms.varies()) return diffuse_form_name(forms.uniform);
  size_t n = 0;
  for (uint8_t c : *forms.coated) n += c != 0;
  return "coated on " + std::to_string(n) + " of " + std::to_string(forms.coated->size()) +
         " vertices, lambert elsewhere";
}

} // namespace vbrdf
