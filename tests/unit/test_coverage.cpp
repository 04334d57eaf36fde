// Coverage classes and next-best-light suggestion (thesis Algorithms 1-3, spatial bins).
#include <cmath>
#include <gtest/gtest.h>
#include <random>

#include "coverage/coverage.h"
#include "test_scenes.h"

using namespace vbrdf;

namespace {
const float kEye[3] = {0, 0, 10}, kTarget[3] = {0, 0, 0}, kUp[3] = {0, 1, 0};
Shot front_camera() { return test::make_look_at_shot(kEye, kTarget, kUp, 800, 640, 480); }

void random_unit(std::mt19937 &rng, float out[3]) {
  std::normal_distribution<float> g(0, 1);
  float l = 0;
  do {
    for (int k = 0; k < 3; ++k) out[k] = g(rng);
    l = std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
  } while (l < 1e-3f);
  for (int k = 0; k < 3; ++k) out[k] /= l;
}
float dot3(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
} // namespace

TEST(Coverage, ClassesFromCounts) {
  EXPECT_EQ(classify_coverage({0, 0, 0}), kUnseen);
  EXPECT_EQ(classify_coverage({3, 0, 1}), kSeenNotDiffuse);
  EXPECT_EQ(classify_coverage({3, 2, 0}), kDiffuseNoSpecular);
  EXPECT_EQ(classify_coverage({3, 2, 1}), kFullyCovered);
  EXPECT_EQ(classify_coverage({3, 2, 1}, 3), kSeenNotDiffuse);
}

TEST(Coverage, IdealLightsSatisfyTheirConditionsAndAreAlwaysPlaceable) {
  const Shot shot = front_camera();
  const LightSuggestionSettings s;
  std::mt19937 rng(3);
  int diffuse_ok = 0, specular_ok = 0, tried = 0;
  for (int i = 0; i < 20000; ++i) {
    float n[3], e[3], l[3];
    random_unit(rng, n);
    random_unit(rng, e);
    e[2] = std::fabs(e[2]) + 0.5f;  // eye directions roughly towards the camera (+z)
    const float len = std::sqrt(dot3(e, e));
    for (float &c : e) c /= len;
    if (dot3(n, e) <= 0.05f) continue;
    ++tried;
    if (ideal_diffuse_light(n, e, shot, s, l)) {
      ++diffuse_ok;
      ASSERT_TRUE(light_is_placeable(shot, l, s.min_elevation_deg));
      ASSERT_TRUE(light_covers_diffuse(n, e, l, s));
      ASSERT_GE(dot3(n, l), s.diffuse_threshold - 1e-5f);
    }
    if (ideal_specular_light(n, e, shot, s, l)) {
      ++specular_ok;
      ASSERT_TRUE(light_is_placeable(shot, l, s.min_elevation_deg));  // never below the horizon
      ASSERT_TRUE(light_covers_specular(n, e, l, s));
    }
  }
  std::printf("front-facing vertices %d: diffuse light found %d, specular light found %d\n", tried, diffuse_ok, specular_ok);
  EXPECT_GT(diffuse_ok, tried * 9 / 10);
  EXPECT_LT(specular_ok, tried);  // strongly tilted normals need a light behind the object: refused
}

TEST(Coverage, DiffuseIdealIsTheNormalUnlessThatIsAHighlight) {
  const Shot shot = front_camera();
  const LightSuggestionSettings s;
  const float n[3] = {0.6f, 0, 0.8f}, e[3] = {0, 0, 1};  // R = N, R.E = 0.8 < T_s: the normal itself
  float l[3];
  ASSERT_TRUE(ideal_diffuse_light(n, e, shot, s, l));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(l[k], n[k], 1e-5f);
  const float facing[3] = {0, 0, 1};  // normal = eye: the normal is a highlight; tilt to T_s - margin
  ASSERT_TRUE(ideal_diffuse_light(facing, e, shot, s, l));
  const float r[3] = {2 * l[2] * facing[0] - l[0], 2 * l[2] * facing[1] - l[1], 2 * l[2] * facing[2] - l[2]};
  EXPECT_NEAR(std::acos(dot3(r, e)), std::acos(s.specular_threshold) + s.margin_deg * 3.14159265f / 180, 1e-3f);
}

TEST(Coverage, GreedyPicksTheLargestGroupAndMatchesBruteForce) {
  // Two patches facing different directions: 300 vertices tilted left, 100 tilted up.
  const Shot shot = front_camera();
  MeshData mesh;
  auto add_patch = [&](int count, const float n[3], float x0) {
    for (int i = 0; i < count; ++i) {
      mesh.positions.insert(mesh.positions.end(), {x0 + 0.001f * (i % 20), 0.001f * (i / 20), 0});
      mesh.normals.insert(mesh.normals.end(), {n[0], n[1], n[2]});
    }
  };
  const float left[3] = {-0.6f, 0, 0.8f}, up[3] = {0, 0.6f, 0.8f};
  add_patch(300, left, -0.5f);
  add_patch(100, up, 0.5f);
  std::vector<uint8_t> visible(400, 1);
  std::vector<float> needs(400, 1.0f);
  const LightSuggestionSettings s;
  const LightSuggestion best = suggest_next_light(mesh.view(), shot, visible.data(), needs.data(), CoverageKind::Specular, s);
  ASSERT_TRUE(best.valid);
  EXPECT_EQ(best.covered_vertices, 300u);
  EXPECT_EQ(best.needing_vertices, 400u);
  EXPECT_LT(best.dir_cam[0], 0);  // mirror of the eye about a left-tilted normal points left
  const LightSuggestion brute =
      suggest_next_light_brute_force(mesh.view(), shot, visible.data(), needs.data(), CoverageKind::Specular, s);
  EXPECT_EQ(brute.covered_vertices, best.covered_vertices);
  // Weights from fit quality change the answer: make the small patch matter more.
  for (int v = 300; v < 400; ++v) needs[size_t(v)] = 5.0f;
  const LightSuggestion weighted = suggest_next_light(mesh.view(), shot, visible.data(), needs.data(), CoverageKind::Specular, s);
  EXPECT_EQ(weighted.covered_vertices, 100u);
  EXPECT_GT(weighted.dir_cam[1], 0);
}

TEST(Coverage, BinnedSuggestionIsCloseToBruteForceOnASphere) {
  const Shot shot = front_camera();
  const float c[3] = {0, 0, 0};
  const MeshData mesh = test::make_sphere(c, 1.0f, 30, 60);
  const size_t n = mesh.positions.size() / 3;
  std::vector<uint8_t> visible(n);
  for (size_t v = 0; v < n; ++v) visible[v] = mesh.normals[3 * v + 2] > 0.1f;  // front half
  std::vector<float> needs(n, 1.0f);
  const LightSuggestionSettings s;
  for (CoverageKind kind : {CoverageKind::Diffuse, CoverageKind::Specular}) {
    const auto binned = suggest_next_light(mesh.view(), shot, visible.data(), needs.data(), kind, s);
    const auto brute = suggest_next_light_brute_force(mesh.view(), shot, visible.data(), needs.data(), kind, s);
    std::printf("%s: binned covers %zu, brute force %zu of %zu\n", kind == CoverageKind::Diffuse ? "diffuse" : "specular",
                binned.covered_vertices, brute.covered_vertices, brute.needing_vertices);
    ASSERT_TRUE(binned.valid);
    EXPECT_GE(double(binned.covered_vertices), 0.95 * double(brute.covered_vertices));
    EXPECT_TRUE(light_is_placeable(shot, binned.dir_world, s.min_elevation_deg));
  }
}
