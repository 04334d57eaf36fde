// Property test over 10^6 random vertices, many of them degenerate: no NaN/Inf, every parameter
// within its documented bounds (or its documented sentinel).
#include <cfloat>
#include <cmath>
#include <gtest/gtest.h>
#include <random>

#include "fit/reflectance_fit.h"
#include "reflectance_test_util.h"
#include "thesis_settings.h"

using namespace vbrdf;

namespace {
using test::degenerate_vertex;
using test::DegenerateKind;
using test::kDegenerateKinds;

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
    const auto s = degenerate_vertex(DegenerateKind(v % kDegenerateKinds), rng);
    chunk.samples.insert(chunk.samples.end(), s.begin(), s.end());
    chunk.offsets.push_back(uint32_t(chunk.samples.size()));
  }
  std::vector<VertexFit> fits(n_vertices);
  fit_chunk_cpu(chunk, o, fits.data());
  int bad = 0, counts[3] = {0, 0, 0};
  for (int v = 0; v < n_vertices; ++v) {
    const VertexFit &f = fits[size_t(v)];
    bool ok = within(f.kd, 0, o.kd_max) && within(f.ks, 0, o.ks_max) && within(f.dq, 0, 2) && within(f.sq, 0, 2) &&
              within(f.rmse, 0, FLT_MAX) && f.status <= kFitFull;
    for (float c : f.color) ok &= within(c, 0, 1);
    ok &= f.shininess == 0 || within(f.shininess, o.alpha_min, o.alpha_max);
    ok &= (f.status == kFitFull) == (f.ks > 0);
    if (f.status == kFitNone) ok &= f.kd == 0 && f.ks == 0 && f.shininess == 0;
    if (!ok && bad++ < 5)
      std::printf("vertex %d (kind %d): kd %g ks %g a %g C %g %g %g dq %g sq %g rmse %g status %d\n", v, v % kDegenerateKinds,
                  f.kd, f.ks, f.shininess, f.color[0], f.color[1], f.color[2], f.dq, f.sq, f.rmse, f.status);
    ++counts[f.status];
  }
  std::printf("none %d, diffuse-only %d, full %d\n", counts[0], counts[1], counts[2]);
  EXPECT_EQ(bad, 0);
  EXPECT_GT(counts[kFitNone], 0);  // saturated-only vertices have no usable sample
  EXPECT_GT(counts[kFitFull], 0);
}
