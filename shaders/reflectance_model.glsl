// The per-vertex reflectance model, evaluated per fragment: the one GLSL copy shared by the relight
// renderer (core/relight/relight_render.cpp, the relight filter's images) and the live view
// (core/relight/live_relight.cpp, MeshLab's "Vertex BRDF: relight" render plugin). Both programs
// are "#version 330 core" + this file + their own main() (relight/reflectance_model_source.h); there is
// no #version here.
//
// Contract (the CPU's evaluate_reflectance, model/lobe.h, model/diffuse_form.h, term for term):
//   f = rho d + k_s g(s, alpha),  rho = k_d C,  unit irradiance; g = max(s, 0)^alpha, or GGX's
//      D(N.H)/D(1) with a^2 = 2 / (alpha + 2) when u_ggx_lobe != 0 (model/lobe.h lobe_value),
//      seen through the pixel's footprint: the normal's variance over one box pixel from the
//      fragment's derivatives (pixel_footprint_variance; samples/footprint.h takes the same from
//      the mesh for a photo's pixel resampled at a vertex), ggx_lobe_through_footprint
//   d: the diffuse factor, N.L (Lambert) or N.L T(max(N.L, 0.2)) T(max(N.E, 0.2)) / T(1)^2 (coated), per
//      vertex (`coated` 1 or 0, DiffuseForms; blended linearly across a triangle that has both);
//   s: the lobe's cosine, R.E with R = 2(N.L)N - L, or N.H when u_half_angle_lobe != 0;
//   N.L <= 0: attached shadow, black (the callers test it before calling reflectance_terms).
// Vertices with k_s = 0 carry the median shininess of the fitted lobes (chosen on the CPU), so
// that a lobe fades with k_s across a triangle instead of widening.
//
// Differences between the two users (stated here and in
// docs/live_relighting.md#differences-between-the-two-renderers):
//   - cast shadows: the relight renderer tests a shadow map; the live view has none (attached
//     shadows only), so where the object shadows itself the live view is lit;
//   - E: the relight renderer's camera is always perspective; the live view takes MeshLab's,
//     which is orthographic at its smallest field of view: then E is the view axis everywhere;
//   - output: the relight renderer writes linear values (clipped later, for comparisons); the
//     live view multiplies by the exposure, clips at 1 and encodes sRGB for the screen.

uniform int u_half_angle_lobe;        // 0: R.E, 1: N.H
uniform int u_ggx_lobe;               // 1: GGX lobe on N.H (LobeForm::GgxNH)
uniform float u_coat_index;           // kCoatIndex
uniform float u_coat_min_cosine;     // kCoatMinCosine

// The model's constants, each named once (model/lobe.h; tests/unit/test_model_constants.cpp checks
// every named constant here against the C++ model and fails on a bare copy of its value).
const float kMaxFootprintVariance = 0.18;  // the clamp on the footprint's normal variance
const float kLobeLogFloor = -80.0;         // the floor on alpha ln s: no ln 0, no denormals

// model/diffuse_form.h coat_transmission.
float coat_transmission(float c) {
  c = clamp(c, 0.0, 1.0);
  float sin_t = sqrt(max(0.0, 1.0 - c * c)) / u_coat_index;
  float cos_t = sqrt(max(0.0, 1.0 - sin_t * sin_t));
  float rs = (c - u_coat_index * cos_t) / (c + u_coat_index * cos_t);
  float rp = (u_coat_index * c - cos_t) / (u_coat_index * c + cos_t);
  return 1.0 - 0.5 * (rs * rs + rp * rp);
}

// model/diffuse_form.h diffuse_factor; `coated` in [0, 1] (interpolated vertex flag).
float diffuse_factor(float n_dot_l, float n_dot_e, float coated) {
  if (!(coated > 0.0) || !(n_dot_l > 0.0)) return n_dot_l;
  float t1 = coat_transmission(1.0);
  float coat = n_dot_l * coat_transmission(max(n_dot_l, u_coat_min_cosine)) * coat_transmission(max(n_dot_e, u_coat_min_cosine)) / (t1 * t1);
  return mix(n_dot_l, coat, min(coated, 1.0));
}

// model/lobe.h lobe_cosine: R.E, or N.H (0 when L = -E).
float lobe_cosine(vec3 n, vec3 l, vec3 e) {
  vec3 h = l + e;
  if (u_half_angle_lobe != 0) return dot(h, h) > 1e-12 ? dot(n, h) / length(h) : 0.0;
  return dot(2.0 * dot(n, l) * n - l, e);
}

// The interpolated vertex normal made unit length (a zero normal stays zero). Every renderer's main()
// starts with it and pixel_footprint_variance, in uniform control flow.
vec3 unit_normal(vec3 interpolated) {
  float len = length(interpolated);
  return len > 0.0 ? interpolated / len : interpolated;
}

// The variance of the unit shading normal n over this fragment's pixel (a box: 1/12 pixel^2 per
// axis) from its screen-space derivatives (samples/footprint.h). Call it in uniform control flow
// (before any early return): derivatives are undefined elsewhere.
float pixel_footprint_variance(vec3 n) {
  vec3 dx = dFdx(n), dy = dFdy(n);
  float v = (dot(dx, dx) + dot(dy, dy)) / 12.0;
  return v >= 0.0 ? v : 0.0;  // NaN from a degenerate normal: no footprint
}

// k_s g(s, alpha) for s > 0: s^alpha with the exponent's logarithm floored at kLobeLogFloor (no denormals,
// no NaN), or the GGX lobe (a positive denominator for alpha >= 0) seen through a footprint of
// normal variance v (model/lobe.h ggx_lobe_through_footprint: a_f^2 = min(a^2 + min(v, kMaxFootprintVariance), 1)).
float specular_term(float ks, float alpha, float s, float v) {
  if (!(ks > 0.0) || !(s > 0.0)) return 0.0;
  float c = min(s, 1.0);
  if (u_ggx_lobe != 0) {
    float a2 = 2.0 / (max(alpha, 0.0) + 2.0);
    float a2f = min(a2 + min(max(v, 0.0), kMaxFootprintVariance), 1.0);
    float den = a2f + (1.0 - c * c) * (1.0 - a2f);
    return ks * a2 * a2f / (den * den);  // as reflectance_fit.comp's ggx_lobe and lobe.h
  }
  return ks * exp(max(alpha * log(c), kLobeLogFloor));
}

// The model's two terms for unit n, l, e with N.L > 0: rho d and the specular (grey) value; v: the
// pixel's footprint variance (pixel_footprint_variance).
void reflectance_terms(vec3 rho, float ks, float alpha, float coated, vec3 n, vec3 l, vec3 e, float v, out vec3 diffuse,
                 out float specular) {
  diffuse = rho * diffuse_factor(dot(n, l), dot(n, e), coated);
  specular = specular_term(ks, alpha, lobe_cosine(n, l, e), v);
}

// A linear colour as the display shows it: clipped to [0, 1], then the sRGB transfer curve (the
// live view and the web viewer encode with it).
vec3 srgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}
