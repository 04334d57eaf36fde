// Property test over 10^6 random vertices, many of them degenerate: no NaN/Inf, every parameter
// within its documented bounds (or its documented sentinel).
#include <cmath>
#include <gtest/gtest.h>
#include <random>

#include "fit/reflectance_fit.h"
#include "reflectance_test_util.h"
#include "thesis_settings.h"

using namespace vbrdf;

namespace {
// Kinds of degenerate vertex the fit must survive.
enum Kind { kRandom, kAllEqual, kSingle, kAllGrazing, kSToZero, kSToOne, kDuplicateLights, kZeroPixels,
            kSaturatedOnly, kNaNSample, kHugeValues, kKinds };

std::vector<Sample> make_vertex(Kind kind, std::mt19937 &rng) {
  std::uniform_real_distribution<float> u(0, 1);
  test::TrueReflectance t{{u(rng), u(rng), u(rng)}, u(rng) * 2, 1 + u(rng) * 999};
  const int n = 1 + int(u(rng) * 24);
  auto s = test::synth_samples(t, n, 0.05f * u(rng), rng);
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
  default: break;
  }
  return s;
}

bool within(float v, float lo, float hi) { return std::isfinite(v) && v >= lo && v <= hi; }
} // namespace

TEST(ReflectanceFitStress, MillionRandomAndDegenerateVertices) {
  const ReflectanceFitOptions o = vbrdf::test::thesis_fit_options();
  std::mt19937 rng(12345);
  const int n_vertices = 1000000;
  SampleChunk chunk;
  chunk.vertex_count = n_vertices;
  chunk.offsets.push_back(0);
  for (int v = 0; v < n_vertices; ++v) {
    const auto s = make_vertex(Kind(v % kKinds), rng);
    chunk.samples.insert(chunk.samples.end(), s.begin(), s.end());
    chunk.offsets.push_back(uint32_t(chunk.samples.size()));
  }
  std::vector<VertexFit> fits(n_vertices);
  fit_chunk_cpu(chunk, o, fits.data());
  int bad = 0, counts[3] = {0, 0, 0};
  for (int v = 0; v < n_vertices; ++v) {
    const VertexFit &f = fits[size_t(v)];
    bool ok = within(f.kd, 0, o.kd_max) && within(f.ks, 0, o.ks_max) && within(f.dq, 0, 2) && within(f.sq, 0, 2) &&
              within(f.rmse, 0, 1e30f) && f.status <= kFitFull;
    for (float c : f.color) ok &= within(c, 0, 1);
    ok &= f.shininess == 0 || within(f.shininess, o.alpha_min, o.alpha_max);
    ok &= (f.status == kFitFull) == (f.ks > 0);
    if (f.status == kFitNone) ok &= f.kd == 0 && f.ks == 0 && f.shininess == 0;
    if (!ok && bad++ < 5)
      std::printf("vertex %d (kind %d): kd %g ks %g a %g C %g %g %g dq %g sq %g rmse %g status %d\n", v, v % kKinds,
                  f.kd, f.ks, f.shininess, f.color[0], f.color[1], f.color[2], f.dq, f.sq, f.rmse, f.status);
    ++counts[f.status];
  }
  std::printf("none %d, diffuse-only %d, full %d\n", counts[0], counts[1], counts[2]);
  EXPECT_EQ(bad, 0);
  EXPECT_GT(counts[kFitNone], 0);  // saturated-only vertices have no usable sample
  EXPECT_GT(counts[kFitFull], 0);
}
