#pragma once
// Synthetic per-vertex samples from known Phong parameters (for fit tests and benchmarks).
#include <cmath>
#include <random>
#include <vector>

#include "fit/reflectance_fit.h"

namespace vbrdf {
namespace test {

struct TrueReflectance {
  float rho[3];  // k_d * C
  float ks, alpha;
};

// n samples: a third (at least `n_highlight` if given >= 0) near the specular peak
// (s in [1 - 4/alpha, 1]), the rest spread over d in [0.1, 1], s in [-1, 0.9]; relative
// Gaussian noise `noise` on every channel. Flags set as the gatherer would (T_s = 0.9).
inline std::vector<Sample> synth_samples(const TrueReflectance &t, int n, float noise, std::mt19937 &rng,
                                         int n_highlight = -1) {
  std::uniform_real_distribution<float> u(0, 1);
  std::normal_distribution<float> gauss(0, 1);
  const int nh = n_highlight >= 0 ? std::min(n, n_highlight) : n / 3;
  std::vector<Sample> out;
  for (int i = 0; i < n; ++i) {
    Sample s{};
    s.d = 0.1f + 0.9f * u(rng);
    s.lobe_cos = i < nh ? 1.0f - std::min(0.099f, 4.0f / t.alpha) * u(rng) : -1.0f + 1.9f * u(rng);
    const float g = s.lobe_cos > 0 ? std::pow(s.lobe_cos, t.alpha) : 0.0f;
    for (int c = 0; c < 3; ++c) {
      const float clean = t.rho[c] * s.d + t.ks * g;
      s.rgb[c] = std::max(0.0f, clean * (1 + noise * gauss(rng)));
    }
    s.flags = (s.lobe_cos > 0.9f ? kHighlight : 0) | (s.d < 0.5f ? kGrazing : 0);
    out.push_back(s);
  }
  return out;
}

// The kinds of degenerate vertex every fit back end must survive (the stress tests' inputs).
enum DegenerateKind { kRandom, kAllEqual, kSingle, kAllGrazing, kSToZero, kSToOne, kDuplicateLights, kZeroPixels,
                      kSaturatedOnly, kNaNSample, kHugeValues, kTinyValues, kExtremeValues, kInfNdotL, kDegenerateKinds };

// One vertex's samples of `kind`: 1-24 samples of a random reflectance, then made degenerate.
inline std::vector<Sample> degenerate_vertex(DegenerateKind kind, std::mt19937 &rng) {
  std::uniform_real_distribution<float> u(0, 1);
  TrueReflectance t{{u(rng), u(rng), u(rng)}, u(rng) * 2, 1 + u(rng) * 999};
  const int n = 1 + int(u(rng) * 24);
  auto s = synth_samples(t, n, 0.05f * u(rng), rng);
  switch (kind) {
  case kAllEqual: for (auto &x : s) x = s[0]; break;
  case kSingle: s.resize(1); break;
  case kAllGrazing: for (auto &x : s) x.d = 1e-4f * u(rng), x.flags |= kGrazing; break;
  case kSToZero: for (auto &x : s) x.lobe_cos = 1e-30f * u(rng); break;
  case kSToOne: for (auto &x : s) x.lobe_cos = 1.0f - 1e-7f * u(rng), x.flags |= kHighlight; break;
  case kDuplicateLights: for (auto &x : s) x.d = s[0].d, x.lobe_cos = s[0].lobe_cos; break;
  case kZeroPixels: for (auto &x : s) x.rgb[0] = x.rgb[1] = x.rgb[2] = 0; break;
  case kSaturatedOnly: for (auto &x : s) x.flags |= kSaturated; break;
  case kNaNSample: s[0].rgb[1] = std::nanf(""), s.back().lobe_cos = std::nanf(""); break;
  case kHugeValues: for (auto &x : s) x.rgb[0] *= 1e6f; break;
  case kTinyValues: for (auto &x : s) for (float &c : x.rgb) c *= 1e-30f; break;
  case kExtremeValues: for (auto &x : s) for (float &c : x.rgb) c *= 1e30f; break;  // squares overflow float
  case kInfNdotL: s[0].d = INFINITY; break;
  default: break;
  }
  return s;
}

} // namespace test
} // namespace vbrdf
