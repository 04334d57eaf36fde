#pragma once
// Per-vertex Phong fit: the contract shared by the CPU reference (phong_fit_cpu.cpp, double
// precision, OpenMP) and the GPU back end (shaders/phong_fit.comp, float32).
//
// Model, per colour channel c, light of unit irradiance and white colour (after calibration):
//     f_c = k_d d C_c + k_s g(s, alpha),  s = R.E or N.H, g = s^alpha or the GGX lobe (options.lobe,
//     samples/lobe.h lobe_value),
//     d = N.L, or N.L with the coat's Fresnel transmission (Sample::d: the gatherer's diffuse form,
//     samples/diffuse_form.h; the fit never evaluates the form itself)
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
// Safeguards: s^alpha = exp(alpha * ln s) with s <= 0 giving 0 and alpha*ln s clamped at -80 (the
// GGX form: a rational function of s and alpha with a positive denominator, lobe.h)
// (no ln 0, no overflow, no denormals); alpha is kept in [alpha_min, alpha_max]; k_d in
// [0, kd_max], k_s in [0, ks_max]; a singular k_s equation (no specular discrimination: all g_i
// ~ 0 or g proportional to d) gives k_s = 0; fewer than `min_specular_samples` highlight samples
// give the diffuse-only fit (k_s = 0, shininess 0 = "not determined") (remedy 3).
//
// Normalisation of the k_d C ambiguity: C_max = max_c C_c = 1 and k_d = max_c rho_c (k_d carries
// the magnitude); a black vertex has k_d = 0 and C = (0,0,0).
//
// Sentinels for vertices without any usable sample: status kFitNone, k_d = k_s = 0,
// shininess = 0, C = (0,0,0), dq = sq = 0, rmse = 0. Outputs are always finite.
#include <cstddef>
#include <cstdint>

#include "samples/samples.h"

namespace vbrdf {

struct PhongFitOptions {
  float alpha_init = 10.0f;      // initial shininess (thesis default)
  float alpha_min = 1.0f;        // bounds on shininess
  float alpha_max = 2000.0f;
  int max_iterations = 50;       // alpha steps (0 = initial estimate only); 50 = the knee (tests/benchmark)
  float tolerance = 1e-5f;       // relative objective improvement that counts as converged
  int min_specular_samples = 2;  // k_s and alpha are free with this many highlight samples (R.E > T_s)
  float lobe_threshold = 0.5f;   // ... or with min_lobe_samples samples with R.E above this
  int min_lobe_samples = 4;      //     (broad lobes show their energy below T_s)
  float specular_weight_cap = 1.0f;
  float diffuse_prior = 0.02f;
  float kd_max = 16.0f;
  float ks_max = 64.0f;
  float specular_threshold = 0.9f;  // T_s: which samples are highlight samples (for DQ/SQ and counts)
  // Fallback for vertices the strict rules leave without any usable sample (fit_vertex_weak):
  // grazing samples (N.L < T_d) carry their N.L weight like any other, and contaminated
  // (kMixedPixel) samples count with this weight factor.
  float mixed_sample_weight = 0.25f;
  // The lobe's form: which cosine Sample::lobe_cos holds and alpha applies to (lobe.h). The
  // thresholds above stay stated on R.E and are converted by lobe_threshold().
  LobeForm lobe = LobeForm::PhongRE;
};

enum FitStatus : uint8_t {
  kFitNone = 0,         // no usable sample: sentinels
  kFitDiffuseOnly = 1,  // k_s = 0 (not enough specular evidence)
  kFitFull = 2,         // all parameters fitted
  kFitFromNeighbours = 3,   // no usable sample of its own: parameters from the nearest fitted
                            //   vertices over the mesh (neighbour_fill.h); dq = sq = 0
  kFitFromWeakSamples = 4,  // no sample passes the strict rules: fitted from grazing and/or
                            //   contaminated (mixed-pixel) samples (fit_vertex_weak); k_s may be 0
};


struct VertexFit {
  float color[3];     // C, max channel 1
  float kd;           // k_d
  float ks;           // k_s
  float shininess;    // alpha (0 when not determined)
  float dq;           // diffuse quality in [0, 2] (thesis 4.7.1)
  float sq;           // specular quality in [0, 2]
  float rmse;         // sqrt(weighted mean squared residual per channel)
  uint16_t iterations;
  uint8_t status;     // FitStatus
  uint8_t converged;  // 1 when stopped by tolerance (not by the cap)
};

// Fits one vertex from its samples (any flags: unusable ones are skipped). Double precision.
void fit_vertex_cpu(const Sample *samples, size_t count, const PhongFitOptions &options, VertexFit &out);

// The fallback fit for a vertex without any strictly usable sample: the same model and method,
// over every lit, unsaturated sample with N.L > 0 (grazing ones with their N.L weight, mixed-pixel
// ones at options.mixed_sample_weight). Status kFitFromWeakSamples, or kFitNone when even these
// are absent (all shadowed or saturated). DQ and SQ are halved: weaker evidence than a strict fit.
void fit_vertex_weak(const Sample *samples, size_t count, const PhongFitOptions &options, VertexFit &out);

// Fits every vertex of a chunk (OpenMP). `out` has chunk.vertex_count entries.
void fit_chunk_cpu(const SampleChunk &chunk, const PhongFitOptions &options, VertexFit *out);

// Sets a diffuse-only result (k_s = 0) with diffuse reflectance rho = k_d C (normalised as above)
// and recomputes DQ, SQ and RMSE from the vertex's samples. The pipeline uses it to give
// diffuse-only vertices the robust basic colour estimate (diffuse_color.h) instead of the plain
// weighted mean of the fit.
void set_diffuse_only_reflectance(const Sample *samples, size_t count, const PhongFitOptions &options,
                                  const float rho[3], VertexFit &out);

// Recomputes DQ, SQ and RMSE of `fit` from the vertex's samples with the fit's usable-sample rules
// (weak: the fallback rules of fit_vertex_weak, and DQ/SQ halved). The material stage
// (materials.h) calls it after it changes k_s, alpha or k_d C. Parameters are not changed.
void recompute_fit_quality(const Sample *samples, size_t count, const PhongFitOptions &options, bool weak,
                           VertexFit &fit);

// Sets k_d and C from a diffuse reflectance rho = k_d C: k_d is its largest channel and C = rho / k_d
// (largest channel 1); C = 0 when k_d <= 0. The one place that splits k_d C; other fields untouched.
void set_kd_color(const double rho[3], VertexFit &fit);

// Evaluates the model (for rendering, relighting and tests). Writes 3 channels.
// d: the diffuse factor (Sample::d: N.L for Lambert, diffuse_factor() in general); lobe_cos and
// form: the lobe's cosine (Sample::lobe_cos) and the form the fit used (PhongFitOptions::lobe).
// footprint: the sample's Sample::footprint (the lobe seen through the photo's pixel footprint).
void evaluate_phong(const VertexFit &fit, float d, float lobe_cos, LobeForm form, float out_rgb[3],
                    float footprint = 0);

// True when the vertex has a reflectance model (any status but kFitNone).
inline bool has_model(const VertexFit &fit) { return fit.status != kFitNone; }

} // namespace vbrdf
