// Diffuse colour estimate (thesis 4.4 with the normalisation erratum fixed).
#include <cmath>
#include <gtest/gtest.h>
#include <random>

#include "samples/diffuse_color.h"

using namespace vbrdf;

namespace {
Sample diffuse_sample(const float rho[3], float d, float noise = 0, uint16_t flags = 0) {
  Sample s{{rho[0] * d + noise, rho[1] * d + noise, rho[2] * d + noise}, d, 0.1f, 0, flags};
  return s;
}
SampleChunk one_vertex(const std::vector<Sample> &samples) {
  SampleChunk c;
  c.vertex_count = 1;
  c.offsets = {0, uint32_t(samples.size())};
  c.samples = samples;
  return c;
}
} // namespace

TEST(Diffuse, LeastSquaresRecoversReflectanceExactly) {
  const float rho[3] = {0.6f, 0.3f, 0.1f};
  std::vector<Sample> s = {diffuse_sample(rho, 0.55f), diffuse_sample(rho, 0.8f), diffuse_sample(rho, 1.0f)};
  float out[3];
  ASSERT_TRUE(least_squares_reflectance(s.data(), s.size(), out));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[c], rho[c], 1e-6);
}

TEST(Diffuse, ThesisSimplifiedFormulaWouldBeWrong) {
  // sum P_i / k_d (thesis "simplification", k_d = 1) grows with the photo count; ours does not.
  const float rho[3] = {0.5f, 0.5f, 0.5f};
  std::vector<Sample> s;
  for (int i = 0; i < 8; ++i) s.push_back(diffuse_sample(rho, 0.6f + 0.05f * i));
  DiffuseEstimate est;
  estimate_diffuse_chunk(one_vertex(s), &est);
  float thesis = 0;
  for (const Sample &x : s) thesis += x.rgb[0];
  EXPECT_NEAR(est.rgb[0], 0.5f, 1e-5);
  EXPECT_GT(std::fabs(thesis - 0.5f), 1.0f);
}

TEST(Diffuse, UsesOnlyDiffuseSamplesAndCountsClasses) {
  const float rho[3] = {0.4f, 0.4f, 0.4f};
  std::vector<Sample> s = {diffuse_sample(rho, 0.9f), diffuse_sample(rho, 0.7f),
                           diffuse_sample(rho, 0.95f, 0.5f, kHighlight),   // specular: bright, excluded
                           diffuse_sample(rho, 0.8f, -0.3f, kCastShadow),  // shadowed: dark, excluded
                           diffuse_sample(rho, 0.3f, 0.0f, kGrazing),
                           diffuse_sample(rho, 0.9f, 0.6f, kSaturated | kHighlight)};
  DiffuseEstimate est;
  estimate_diffuse_chunk(one_vertex(s), &est);
  EXPECT_TRUE(est.valid);
  EXPECT_EQ(est.n_seen, 6);
  EXPECT_EQ(est.n_diffuse, 2);
  EXPECT_EQ(est.n_specular, 1);  // the saturated highlight is not specular evidence
  EXPECT_NEAR(est.rgb[1], 0.4f, 1e-6);
}

TEST(Diffuse, RobustPassRemovesAnUnflaggedShadowSample) {
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0, 0.005f);
  const float rho[3] = {0.5f, 0.4f, 0.3f};
  std::vector<Sample> s;
  for (int i = 0; i < 12; ++i) s.push_back(diffuse_sample(rho, 0.55f + 0.04f * i, noise(rng)));
  s.push_back(diffuse_sample(rho, 0.9f, -0.4f));  // shadow edge the depth pass missed
  DiffuseEstimate est;
  estimate_diffuse_chunk(one_vertex(s), &est);
  EXPECT_EQ(est.n_rejected, 1);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(est.rgb[c], rho[c], 0.01f);
}

TEST(Diffuse, NoUsableSampleGivesInvalidNotNaN) {
  const float rho[3] = {0.5f, 0.5f, 0.5f};
  std::vector<Sample> s = {diffuse_sample(rho, 0.9f, 0, kCastShadow)};
  DiffuseEstimate est;
  estimate_diffuse_chunk(one_vertex(s), &est);
  EXPECT_FALSE(est.valid);
  EXPECT_EQ(est.n_seen, 1);
  for (float v : est.rgb) EXPECT_EQ(v, 0.0f);
  estimate_diffuse_chunk(one_vertex({}), &est);
  EXPECT_FALSE(est.valid);
  EXPECT_EQ(est.n_seen, 0);
}

TEST(Diffuse, MixedPixelsAreUsedOnlyWhenNothingCleanRemains) {
  const float rho[3] = {0.5f, 0.5f, 0.5f}, dark[3] = {0.1f, 0.1f, 0.1f};
  DiffuseEstimate est;
  // A clean sample wins over mixed ones.
  estimate_diffuse_chunk(one_vertex({diffuse_sample(rho, 0.8f), diffuse_sample(dark, 0.8f, 0, kMixedPixel)}), &est);
  EXPECT_FALSE(est.from_mixed_pixels);
  EXPECT_NEAR(est.rgb[0], 0.5f, 1e-6);
  EXPECT_EQ(est.n_diffuse, 1);
  // Only mixed samples: used, and said so.
  estimate_diffuse_chunk(one_vertex({diffuse_sample(dark, 0.8f, 0, kMixedPixel)}), &est);
  EXPECT_TRUE(est.valid);
  EXPECT_TRUE(est.from_mixed_pixels);
  EXPECT_NEAR(est.rgb[0], 0.1f, 1e-6);
}
