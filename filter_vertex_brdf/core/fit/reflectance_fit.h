#pragma once
// Per-vertex reflectance fit: the contract shared by the CPU reference (reflectance_fit_cpu.cpp, double
// precision, OpenMP) and the GPU back end (shaders/reflectance_fit.comp, float32).
//
// Model, per colour channel c, light of unit irradiance and white colour (after calibration):
//     f_c = k_d d C_c + k_s g(s, alpha),  s = R.E or N.H, g = s^alpha or the GGX lobe (options.lobe,
//     model/lobe.h lobe_value),
//     d = N.L, or N.L with the coat's Fresnel transmission (Sample::d: the gatherer's diffuse form,
//     model/diffuse_form.h; the fit never evaluates the form itself)
// Objective: sum over usable samples i of w_i * sum_c (P_ic - f_c)^2 + prior, with
//     w_i = d_i (N.L_i in the thesis, ch. 5) times the sample's photo resolution weight (resolution_weight,
//     1 with one camera), highlight samples rescaled so that their total weight is at
//     most `specular_weight_cap` times the weight of the other samples (diffuse-hole remedy 1),
//     prior = diffuse_prior * W * sum_c (rho_c - rho0_c)^2, rho = k_d C, rho0 the diffuse-only
//     estimate, W the total weight (remedy 2: a weak pull towards the diffuse-only fit).
// Usable samples: lit (no shadow flag), unsaturated, clean pixel (no kMixedPixel), N.L > 0, and
// not grazing (kGrazing) unless a highlight. Highlight samples: s > lobe_threshold(lobe, T_s)
// (R.E > T_s for the Phong form; the same cone in the plane of incidence for N.H).
//
// Method (variable projection of the thesis's 4.6 cycle): for fixed alpha the model is linear in
// (rho_r, rho_g, rho_b, k_s), so the "(k_d, k_s)" and "colour" stages are solved exactly and
// jointly in closed form (4x4 normal equations reduced to one scalar, non-negativity by an
// active set). alpha is then updated by a Levenberg-Marquardt-damped Newton step on t = ln(alpha)
// using the envelope gradient, with step rejection (damping x4) when the objective grows.
// One iteration = one alpha step + exact linear re-solve. Stops when the relative improvement
// is below `tolerance`, after `max_iterations`, or when no damped step improves.
//
// Safeguards: s^alpha = exp(alpha * ln s) with s <= 0 giving 0 and alpha*ln s clamped at kLobeLogFloor (the
// GGX form: a rational function of s and alpha with a positive denominator, lobe.h)
// (no ln 0, no overflow, no denormals); alpha is kept in [alpha_min, alpha_max]; k_d in
// [0, kd_max], k_s in [0, ks_max]; a singular k_s equation (no specular discrimination: all g_i
// ~ 0 or g proportional to d) gives k_s = 0; fewer than `min_specular_samples` highlight samples
// give the diffuse-only fit (k_s = 0, shininess 0 = "not determined") (remedy 3).
//
// The parameters, their normalisation, sentinels and evaluation: model/vertex_model.h. Outputs are
// always finite.
#include <cstddef>
#include <cstdint>

#include "model/defaults.h"
#include "model/vertex_model.h"  // VertexFit, FitStatus, set_kd_color, evaluate_reflectance
#include "samples/samples.h"

namespace vbrdf {

struct ReflectanceFitOptions {
  float alpha_init = kDefaultInitialShininess;  // initial shininess
  float alpha_min = kMinShininess;               // bounds on shininess
  float alpha_max = kMaxShininess;
  int max_iterations = kDefaultMaxIterations;     // alpha steps (0 = initial estimate only)
  float tolerance = 1e-5f;       // relative objective improvement that counts as converged
  int min_specular_samples = kDefaultMinSpecularSamples;  // k_s and alpha are free with this many highlight samples (R.E > T_s)
  float lobe_threshold = 0.5f;   // ... or with min_lobe_samples samples with R.E above this
  int min_lobe_samples = 4;      //     (broad lobes show their energy below T_s)
  float specular_weight_cap = 1.0f;
  float diffuse_prior = 0.02f;
  float kd_max = 16.0f;
  float ks_max = 64.0f;
  float specular_threshold = kDefaultSpecularThreshold;  // T_s: which samples are highlight samples (for DQ/SQ and counts)
  // Fallback for vertices the strict rules leave without any usable sample (fit_vertex_weak):
  // grazing samples (N.L < T_d) carry their N.L weight like any other, and contaminated
  // (kMixedPixel) samples count with this weight factor.
  float mixed_sample_weight = 0.25f;
  // The lobe's form: which cosine Sample::lobe_cos holds and alpha applies to (lobe.h). The
  // thresholds above stay stated on R.E and are converted by lobe_threshold().
  LobeForm lobe = kDefaultLobe;
};

// Fits one vertex from its samples (any flags: unusable ones are skipped). Double precision.
void fit_vertex_cpu(const Sample *samples, size_t count, const ReflectanceFitOptions &options, VertexFit &out);

// The fallback fit for a vertex without any strictly usable sample: the same model and method,
// over every lit, unsaturated sample with N.L > 0 (grazing ones with their N.L weight, mixed-pixel
// ones at options.mixed_sample_weight). Status kFitFromWeakSamples, or kFitNone when even these
// are absent (all shadowed or saturated). DQ and SQ are halved: weaker evidence than a strict fit.
void fit_vertex_weak(const Sample *samples, size_t count, const ReflectanceFitOptions &options, VertexFit &out);

// Fits every vertex of a chunk (OpenMP). `out` has chunk.vertex_count entries.
void fit_chunk_cpu(const SampleChunk &chunk, const ReflectanceFitOptions &options, VertexFit *out);

// Sets a diffuse-only result (k_s = 0) with diffuse reflectance rho = k_d C (normalised as above)
// and recomputes DQ, SQ and RMSE from the vertex's samples. The pipeline uses it to give
// diffuse-only vertices the robust basic colour estimate (diffuse_color.h) instead of the plain
// weighted mean of the fit.
void set_diffuse_only_reflectance(const Sample *samples, size_t count, const ReflectanceFitOptions &options,
                                  const float rho[3], VertexFit &out);

// Recomputes DQ, SQ and RMSE of `fit` from the vertex's samples with the fit's usable-sample rules
// (weak: the fallback rules of fit_vertex_weak, and DQ/SQ halved). The material stage
// (materials.h) calls it after it changes k_s, alpha or k_d C. Parameters are not changed.
void recompute_fit_quality(const Sample *samples, size_t count, const ReflectanceFitOptions &options, bool weak,
                           VertexFit &fit);

} // namespace vbrdf
