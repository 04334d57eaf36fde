// The photo's pixel footprint (samples/footprint.h) and the GGX lobe seen through it (lobe.h).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "fit/reflectance_fit.h"
#include "samples/footprint.h"
#include "model/lobe.h"
#include "test_scenes.h"
#include "thesis_settings.h"

using namespace vbrdf;

namespace {
constexpr double kPi = 3.14159265358979323846;

// The lobe's energy: the integral of g(N.H) (N.H) over the hemisphere of half vectors (a GGX
// distribution D integrates to 1 that way, so g = D / D(1) integrates to 1 / D(1) = pi a^2).
double lobe_energy(double alpha, double v) {
  const int n = 200000;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double th = (i + 0.5) / n * (kPi / 2), s = std::cos(th);
    sum += lobe_value(LobeForm::GgxNH, s, alpha, v) * s * std::sin(th);
  }
  return sum * (kPi / 2 / n) * 2 * kPi;
}
} // namespace

// Through a footprint the GGX lobe is lower at its peak (a^2 / (a^2 + v)) and broader, with the same
// energy; v = 0 is the lobe at the vertex; the power forms ignore v; v is clamped at 0.18.
TEST(Lobe, FootprintLowersAndBroadensTheGgxLobeAtTheSameEnergy) {
  for (double alpha : {50.0, 300.0, 2000.0}) {
    const double a2 = ggx_a2(alpha);
    for (double s : {1.0, 0.999, 0.99, 0.9, 0.5})
      EXPECT_EQ(lobe_value(LobeForm::GgxNH, s, alpha, 0.0), lobe_value(LobeForm::GgxNH, s, alpha));
    for (double v : {1e-4, 1e-3, 1e-2}) {
      EXPECT_NEAR(lobe_value(LobeForm::GgxNH, 1.0, alpha, v), a2 / (a2 + v), 1e-12);
      // Broader: far enough from the peak the footprint's lobe is the higher one.
      const double far = std::cos(4 * std::sqrt(a2 + v));
      EXPECT_GT(lobe_value(LobeForm::GgxNH, far, alpha, v), lobe_value(LobeForm::GgxNH, far, alpha)) << alpha << " " << v;
      EXPECT_NEAR(lobe_energy(alpha, v), lobe_energy(alpha, 0), 2e-3 * lobe_energy(alpha, 0)) << alpha << " " << v;
      EXPECT_EQ(lobe_value(LobeForm::BlinnNH, 0.99, alpha, v), lobe_value(LobeForm::BlinnNH, 0.99, alpha));
    }
    EXPECT_EQ(lobe_value(LobeForm::GgxNH, 0.9, alpha, 5.0), lobe_value(LobeForm::GgxNH, 0.9, alpha, kMaxFootprintVariance));
  }
}

// The fits' Newton step through a footprint, by finite differences, the peak (s = 1) included: there
// the height a^2 / (a^2 + v) still depends on alpha.
TEST(Lobe, FootprintDerivativeMatchesFiniteDifferences) {
  for (double alpha : {5.0, 80.0, 600.0})
    for (double v : {1e-4, 3e-3, 0.05, 1.0})
      for (double s : {1.0, 0.9999, 0.999, 0.99, 0.95, 0.7}) {
        const double h = 1e-6, t = std::log(alpha);
        const double fd = (lobe_value(LobeForm::GgxNH, s, std::exp(t + h), v) -
                           lobe_value(LobeForm::GgxNH, s, std::exp(t - h), v)) / (2 * h);
        EXPECT_NEAR(lobe_dvalue_dlog_alpha(LobeForm::GgxNH, s, alpha, v), fd, 1e-7 + 1e-5 * std::fabs(fd))
            << alpha << " " << v << " " << s;
      }
}

// A plane has no footprint whatever the camera; a sphere of radius R seen head-on has v =
// 0.25 * 2 * (depth / (f R))^2 (the normal turns by 1/R per unit length, one pixel spans depth / f),
// growing towards its rim, where a pixel spans a long strip along the tilt.
TEST(Footprint, PlaneHasNoneAndASphereHasItsCurvature) {
  const float eye[3] = {5, 0, 0}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
  Raster raster;
  raster.shot = test::make_look_at_shot(eye, target, up, 800, 640, 480);

  // The grid lies in y = 0 (normals +y): seen from above-right so that it faces the camera.
  Raster above;
  const float eye_above[3] = {3, 4, 1};
  above.shot = test::make_look_at_shot(eye_above, target, up, 800, 640, 480);
  const MeshData grid = test::make_grid(20, 1.0f, 0.0f);
  const std::vector<float> g_grid = normal_gradients(grid.view());
  for (size_t v = 0; v < grid.positions.size() / 3; v += 7)
    EXPECT_EQ(footprint_variance(above, &grid.positions[3 * v], &grid.normals[3 * v], &g_grid[9 * v]), 0.0f);

  const float centre[3] = {0, 0, 0};
  const MeshData sphere = test::make_sphere(centre, 1.0f, 96, 192);
  const std::vector<float> g = normal_gradients(sphere.view());
  size_t front = 0;
  for (size_t v = 1; v < sphere.positions.size() / 3; ++v)
    if (sphere.normals[3 * v] > sphere.normals[3 * front]) front = v;
  const float *p = &sphere.positions[3 * front];
  const double depth = 5 - p[0], expected = 0.25 * 2 * std::pow(depth / 800.0, 2);
  const float head_on = footprint_variance(raster, p, &sphere.normals[3 * front], &g[9 * front]);
  EXPECT_NEAR(head_on, expected, 0.05 * expected);
  // Towards the rim (N.E falling) the footprint grows; at the clamp it stops.
  float previous = head_on;
  for (double angle_deg : {40.0, 60.0, 72.0}) {  // the limb seen from 5 radii: 78.5 degrees
    size_t best = 0;
    double best_err = 1e9;
    for (size_t v = 0; v < sphere.positions.size() / 3; ++v) {
      const double err = std::fabs(sphere.normals[3 * v] - std::cos(angle_deg * kPi / 180)) + std::fabs(sphere.normals[3 * v + 1]);
      if (err < best_err) best_err = err, best = v;
    }
    const float fv = footprint_variance(raster, &sphere.positions[3 * best], &sphere.normals[3 * best], &g[9 * best]);
    EXPECT_GT(fv, previous) << angle_deg;
    EXPECT_LE(fv, float(kMaxFootprintVariance));
    previous = fv;
  }
  // Back-facing: none.
  size_t back = 0;
  for (size_t v = 1; v < sphere.positions.size() / 3; ++v)
    if (sphere.normals[3 * v] < sphere.normals[3 * back]) back = v;
  EXPECT_EQ(footprint_variance(raster, &sphere.positions[3 * back], &sphere.normals[3 * back], &g[9 * back]), 0.0f);
}

// A vertex whose photos show its sharp lobe (alpha 600) through a footprint (v = 0.003, as a
// curved vertex of bunny_two_materials_dir32 shows): fitted with the footprint, the surface's own
// exponent and k_s come back; without it the fit reports the broader, lower lobe the photos show
// (for one camera the same values at the vertex: a^2 + v and k_s a^2 / (a^2 + v)).
TEST(ReflectanceFit, RecoversTheSurfaceLobeThroughAFootprint) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0, 1);
  const double alpha = 600, v = 0.003, ks = 0.8;
  const float rho[3] = {0.3f, 0.2f, 0.1f};
  std::vector<Sample> with, without;
  for (int i = 0; i < 300; ++i) {
    Sample s{};
    s.d = 0.55f + 0.45f * u(rng);
    // Half the samples within the broadened highlight, the rest anywhere.
    const double angle = (i % 2 ? 3.0 * std::sqrt(ggx_a2(alpha) + v) : 1.2) * u(rng);
    s.lobe_cos = float(std::cos(angle));
    s.footprint = float(v);
    const double g = lobe_value(LobeForm::GgxNH, s.lobe_cos, alpha, v);
    for (int c = 0; c < 3; ++c) s.rgb[c] = float(rho[c] * s.d + ks * g);
    s.flags = angle < 0.2 ? kHighlight : 0;
    with.push_back(s);
    s.footprint = 0;
    without.push_back(s);
  }
  ReflectanceFitOptions o = vbrdf::test::thesis_fit_options();
  o.lobe = LobeForm::GgxNH;
  o.alpha_max = 5000;
  VertexFit f_with, f_without;
  fit_vertex_cpu(with.data(), with.size(), o, f_with);
  fit_vertex_cpu(without.data(), without.size(), o, f_without);
  ASSERT_EQ(f_with.status, kFitFull);
  EXPECT_NEAR(f_with.shininess, alpha, 0.05 * alpha);
  EXPECT_NEAR(f_with.ks, ks, 0.05 * ks);
  const double a2f = ggx_a2(alpha) + v;
  EXPECT_NEAR(f_without.shininess, 2 / a2f - 2, 0.05 * (2 / a2f - 2));  // the photos' broader lobe
  EXPECT_NEAR(f_without.ks, ks * ggx_a2(alpha) / a2f, 0.05 * ks * ggx_a2(alpha) / a2f);
}
