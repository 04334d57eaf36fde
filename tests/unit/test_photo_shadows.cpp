// Shadows the photos show but the mesh does not cast (fit/photo_shadows.h).
#include <gtest/gtest.h>

#include <random>

#include "fit/photo_shadows.h"
#include "reflectance_test_util.h"
#include "thesis_settings.h"

namespace vbrdf {
namespace {

// Lambertian samples of rho = (0.5, 0.4, 0.3) with d in [0.5, 1] (none grazing), 1 % noise; the
// first `dark` of them photographed in a shadow the mesh does not cast (5 % of their light).
std::vector<Sample> lit_samples(int n, int dark, std::mt19937 &rng) {
  const test::TrueReflectance truth{{0.5f, 0.4f, 0.3f}, 0.0f, 10.0f};
  std::vector<Sample> s = test::synth_samples(truth, n, 0.01f, rng, 0);
  std::uniform_real_distribution<float> u(0.5f, 1.0f);
  for (int i = 0; i < n; ++i) {
    const float d = u(rng), scale = d / s[size_t(i)].d;
    s[size_t(i)].d = d;
    s[size_t(i)].flags = 0;
    for (float &c : s[size_t(i)].rgb) c *= scale * (i < dark ? 0.05f : 1.0f);
  }
  return s;
}

SampleChunk one_vertex(const std::vector<Sample> &samples) {
  SampleChunk chunk;
  chunk.vertex_count = 1;
  chunk.offsets = {0, uint32_t(samples.size())};
  chunk.samples = samples;
  return chunk;
}

float rho_error(const VertexFit &f) {
  const float truth[3] = {0.5f, 0.4f, 0.3f};
  float worst = 0;
  for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(f.kd * f.color[c] - truth[c]) / truth[c]);
  return worst;
}

TEST(PhotoShadows, DarkSamplesAreLeftOutAndTheVertexRefitted) {
  std::mt19937 rng(7);
  SampleChunk chunk = one_vertex(lit_samples(12, 3, rng));
  const ReflectanceFitOptions options = vbrdf::test::thesis_fit_options();
  VertexFit fit;
  fit_vertex_cpu(chunk.samples.data(), chunk.samples.size(), options, fit);
  const float before = rho_error(fit);
  EXPECT_GT(before, 0.1f) << "the shadowed samples should drag an unguarded fit down";

  size_t flagged = 0, refitted = 0;
  refit_photo_shadows(chunk, options, PhotoShadowSettings(), &fit, flagged, refitted);
  EXPECT_EQ(flagged, 3u);
  EXPECT_EQ(refitted, 1u);
  for (size_t k = 0; k < chunk.samples.size(); ++k)
    EXPECT_EQ((chunk.samples[k].flags & kCastShadow) != 0, k < 3) << "sample " << k;
  EXPECT_LT(rho_error(fit), 0.03f) << "before: " << before;
  EXPECT_TRUE(has_model(fit));
}

TEST(PhotoShadows, OffChangesNothing) {
  std::mt19937 rng(7);
  SampleChunk chunk = one_vertex(lit_samples(12, 3, rng));
  VertexFit fit;
  fit_vertex_cpu(chunk.samples.data(), chunk.samples.size(), vbrdf::test::thesis_fit_options(), fit);
  const VertexFit before = fit;
  PhotoShadowSettings off;
  off.enabled = false;
  size_t flagged = 0, refitted = 0;
  refit_photo_shadows(chunk, vbrdf::test::thesis_fit_options(), off, &fit, flagged, refitted);
  EXPECT_EQ(flagged + refitted, 0u);
  EXPECT_EQ(fit.kd, before.kd);
}

TEST(PhotoShadows, SafeguardsKeepMostSamplesAndEnoughOfThem) {
  std::mt19937 rng(11);
  const ReflectanceFitOptions options = vbrdf::test::thesis_fit_options();
  // More than half dark: the "shadow" is the vertex's own colour, nothing is flagged.
  std::vector<Sample> most_dark = lit_samples(12, 7, rng);
  VertexFit fit;
  fit_vertex_cpu(most_dark.data(), most_dark.size(), options, fit);
  EXPECT_EQ(flag_photo_shadows(fit, most_dark.data(), most_dark.size(), PhotoShadowSettings()), 0u);
  // Flagging would leave fewer than kPhotoShadowMinRemaining samples.
  std::vector<Sample> few = lit_samples(4, 2, rng);
  fit_vertex_cpu(few.data(), few.size(), options, fit);
  EXPECT_EQ(flag_photo_shadows(fit, few.data(), few.size(), PhotoShadowSettings()), 0u);
  for (const Sample &s : few) EXPECT_EQ(s.flags & kCastShadow, 0);
}

TEST(PhotoShadows, BrightAndFaintSamplesAreNotShadows) {
  std::mt19937 rng(3);
  std::vector<Sample> s = lit_samples(10, 0, rng);
  VertexFit fit;
  fit_vertex_cpu(s.data(), s.size(), vbrdf::test::thesis_fit_options(), fit);
  s[0].rgb[0] = s[0].rgb[1] = s[0].rgb[2] = 0.9f;  // a glint: brighter than the model, not a shadow
  for (float &c : s[1].rgb) c *= 0.05f;            // dark, but where the model predicts almost nothing:
  s[1].d = 0.01f;                                  //   below min_predicted, so no evidence either way
  for (float &c : s[1].rgb) c = 0.0001f;
  EXPECT_EQ(flag_photo_shadows(fit, s.data(), s.size(), PhotoShadowSettings()), 0u);
  VertexFit none;  // no model, no judgement
  none.status = kFitNone;
  for (float &c : s[2].rgb) c *= 0.01f;
  EXPECT_EQ(flag_photo_shadows(none, s.data(), s.size(), PhotoShadowSettings()), 0u);
}

} // namespace
} // namespace vbrdf
