// Window depth back to view depth (gl/gl_depth.h linear_depth_from_window), as the visibility
// tests' shader does for depth-only shadow passes. No GL needed: the projections are the light
// views' own (gl/light_view.h).
#include <gtest/gtest.h>

#include <cmath>

#include "gl/gl_depth.h"
#include "gl/light_view.h"
#include "inputs/light_source.h"

namespace vbrdf {
namespace {

// The window depth GL stores for a point at view depth `depth` (view z = -depth) under `p`.
float window_depth(const float p[16], float depth) {
  const float z = -depth;
  const float clip_z = p[10] * z + p[14], clip_w = p[11] * z + p[15];
  return 0.5f * clip_z / clip_w + 0.5f;
}

void expect_round_trip(const LightView &v, float near_depth, float far_depth) {
  for (int k = 0; k <= 10; ++k) {
    const float depth = near_depth + (far_depth - near_depth) * float(k) / 10.0f;
    const float w = window_depth(v.projection, depth);
    ASSERT_GE(w, 0.0f);
    ASSERT_LE(w, 1.0f);
    EXPECT_NEAR(linear_depth_from_window(v.projection, w), depth, 1e-4f * far_depth) << "depth " << depth;
  }
}

TEST(GlDepth, WindowDepthOfADirectionalLightGoesBackToViewDepth) {
  const float origin[3] = {10, -3, 2};
  const float radius = 2.5f;
  const LightView v = make_light_view(LightSource::directional({{0.3f, 0.4f, 0.866f}}), origin, radius);
  ASSERT_FALSE(v.perspective);
  // The sphere lies between the near and far planes; probe a little inside them.
  const float mid = linear_depth_from_window(v.projection, 0.5f);
  expect_round_trip(v, mid - 0.99f * radius, mid + 0.99f * radius);
  EXPECT_LT(linear_depth_from_window(v.projection, 0.0f), linear_depth_from_window(v.projection, 1.0f));
}

TEST(GlDepth, WindowDepthOfAPointLightGoesBackToViewDepth) {
  const float origin[3] = {0, 0, 0};
  const float radius = 1.0f;
  LightSource light;
  light.positional = true;
  light.position = {{0.0f, 0.0f, 5.0f}};
  const LightView v = make_light_view(light, origin, radius);
  ASSERT_TRUE(v.perspective);
  expect_round_trip(v, 4.05f, 5.95f);
}

} // namespace
} // namespace vbrdf
