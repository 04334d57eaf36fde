// Sizes of the visibility depth passes (visibility/pass_size.h): from the mesh's projected edges,
// within their clamps, overridable, and the divided camera's pixel mapping. (Agreement of passes
// at these sizes with the CPU ray caster: test_visibility.cpp.)
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "base/errors.h"
#include "gl/light_view.h"
#include "test_scenes.h"
#include "visibility/pass_size.h"

namespace vbrdf {
namespace {

MeshData grid_mesh(int n) { return test::make_grid(n, 1.0f, 0.0f); }  // plane y = 0, 2 x 2, normals +y

// Median length, in texels of a `size` map, of every triangle edge as the light view projects its
// end points (independent of pass_size.cpp's algebra).
float median_edge_texels(const MeshData &m, const LightView &lv, const float origin[3], int size) {
  std::vector<float> texels;
  const size_t triangles = m.indices.size() / 3;
  for (size_t t = 0; t < triangles; ++t) {
    float local[3][3];
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) local[k][c] = m.positions[3 * m.indices[3 * t + size_t(k)] + size_t(c)] - origin[c];
    float wx[3], wy[3], depth;
    for (int k = 0; k < 3; ++k) light_view_project(lv, local[k], size, wx[k], wy[k], depth);
    for (int k = 0; k < 3; ++k) texels.push_back(std::hypot(wx[(k + 1) % 3] - wx[k], wy[(k + 1) % 3] - wy[k]));
  }
  std::nth_element(texels.begin(), texels.begin() + long(texels.size() / 2), texels.end());
  return texels[texels.size() / 2];
}

TEST(PassSize, ShadowMapResolvesTheEdgesAsTheLightSeesThem) {
  const float origin[3] = {0, 0, 0};
  VisibilitySettings s;
  for (int n : {101, 301}) {
    const MeshData m = grid_mesh(n);
    const EdgeSample edges = sample_edges(m.view(), origin);
    const int upper = resolved_shadow_map_size(m.view(), s);
    int previous = 0, overhead = 0;
    // Overhead, then ever more grazing, tilted along the grid's diagonal: the grid's x and z edges
    // (2 of the 3 edges of each face) shrink in the light's view.
    for (float tilt : {0.0f, 0.8f, 1.3f}) {
      const float side = std::sin(tilt) * std::sqrt(0.5f);
      const LightView lv = make_light_view(LightSource::directional({{side, std::cos(tilt), side}}), origin, 1.5f);
      const int size = light_pass_size(edges, lv, s, upper);
      EXPECT_GE(size, kMinShadowMapSize);
      EXPECT_LE(size, upper);
      EXPECT_EQ(size % 64, 0);
      const float texels = median_edge_texels(m, lv, origin, size);
      std::printf("  %d x %d grid, tilt %.1f: map %d (at most %d), median edge %.2f texels\n", n, n, tilt, size, upper,
                  texels);
      // The rule: the median edge spans >= kShadowTexelsPerEdge texels (sampling and one edge per
      // face: within 15 %), unless a clamp holds the size.
      if (size > kMinShadowMapSize && size < upper) {
        EXPECT_GE(texels, 0.85f * kShadowTexelsPerEdge);
        EXPECT_LE(texels, 1.6f * kShadowTexelsPerEdge);  // and not much finer (64-texel rounding)
      }
      EXPECT_GE(size, previous);  // more grazing: more texels
      if (tilt == 0) overhead = size;
      if (n == 301 && tilt > 1) EXPECT_GT(size, overhead);
      previous = size;
    }
  }
  // A finer mesh needs a finer map; an explicit size wins.
  const MeshData coarse = grid_mesh(101), fine = grid_mesh(301);
  const LightView over = make_light_view(LightSource::directional({{0, 1, 0}}), origin, 1.5f);
  const int a = light_pass_size(sample_edges(coarse.view(), origin), over, s, 4096);
  const int b = light_pass_size(sample_edges(fine.view(), origin), over, s, 4096);
  EXPECT_GT(b, a);
  s.shadow_map_size = 777;
  EXPECT_EQ(light_pass_size(sample_edges(fine.view(), origin), over, s, 4096), 777);
}

TEST(PassSize, CameraDivisorFollowsTheProjectedEdges) {
  const MeshData m = grid_mesh(201);  // edge 0.01
  const float origin[3] = {0, 0, 0}, eye[3] = {0.2f, 3.0f, 0.3f}, target[3] = {0, 0, 0}, up[3] = {0, 0, -1};
  const EdgeSample edges = sample_edges(m.view(), origin);
  VisibilitySettings s;
  float view[16];
  const auto divisor_at = [&](int width) {
    const Shot shot = test::make_look_at_shot(eye, target, up, 0.9f * float(width), width, width * 3 / 4);
    gl_view_matrix(shot, view);  // origin at 0: world view = origin-relative view
    return camera_pass_divisor(edges, shot, view, s);
  };
  // The plane at distance ~3 with focal 0.9 W: an edge spans ~0.003 W pixels.
  EXPECT_EQ(divisor_at(640), 1);    // ~1.9 px: photo resolution
  EXPECT_EQ(divisor_at(1200), 1);   // ~3.6 px
  EXPECT_EQ(divisor_at(2200), 2);   // ~6.6 px
  EXPECT_EQ(divisor_at(4400), kMaxCameraDivisor);  // ~13 px
  EXPECT_EQ(divisor_at(6000), kMaxCameraDivisor);  // ~18 px: capped
  for (int w : {640, 1200, 2200, 2600, 4400}) {
    const int d = divisor_at(w);
    const double edge_px = 0.01 * 0.9 * w / 3.0;
    if (d > 1) EXPECT_LE(d * kCameraPixelsPerEdge, edge_px * 1.2) << w;  // a map texel <= median edge / k
    EXPECT_GE((w + d - 1) / d, kMinCameraPassSide) << w;
  }
  s.camera_pass_divisor = 3;
  EXPECT_EQ(divisor_at(640), 3);
  s.camera_pass_divisor = -1;
  EXPECT_THROW(divisor_at(640), InputError);
}

TEST(PassSize, DividedShotMapsPhotoPixelsToMapTexels) {
  const float eye[3] = {0.4f, 2.5f, 0.7f}, target[3] = {0.1f, 0, 0}, up[3] = {0, 0, -1};
  const Shot shot = test::make_look_at_shot(eye, target, up, 3000, 4000, 3001, 1990.5f, 1512.25f);
  for (int d : {1, 2, 3}) {
    const Shot small = divided_shot(shot, d);
    EXPECT_EQ(small.Intrinsics.ViewportPx[0], (4000 + d - 1) / d);
    EXPECT_EQ(small.Intrinsics.ViewportPx[1], (3001 + d - 1) / d);
    for (const std::array<float, 3> &p : {std::array<float, 3>{{0, 0, 0}}, std::array<float, 3>{{0.5f, 0.1f, -0.3f}},
                                          std::array<float, 3>{{-0.6f, -0.2f, 0.4f}}}) {
      const vcg::Point2f a = shot.Project(vcg::Point3f(p[0], p[1], p[2]));
      const vcg::Point2f b = small.Project(vcg::Point3f(p[0], p[1], p[2]));
      EXPECT_NEAR(b[0] * d, a[0], 1e-2f * d);  // VCG pixels (y up) divide by d
      EXPECT_NEAR(b[1] * d, a[1], 1e-2f * d);
    }
  }
}

TEST(PassSize, DescribesTheSizesForTheReport) {
  VisibilityBackend::PassSizes s;
  EXPECT_EQ(describe_pass_sizes(s), "");
  s.camera_width = 2000, s.camera_height = 1500, s.camera_divisor = 2, s.divisor_min = 2, s.divisor_max = 2;
  s.shadow_min = 1088, s.shadow_max = 1536;
  EXPECT_EQ(describe_pass_sizes(s), "camera 2000x1500 (photo / 2), shadow maps 1088-1536");
}

} // namespace
} // namespace vbrdf
