// Relighting evaluation and the result PLY round trip.
#include <cmath>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "base/errors.h"
#include "io/output_ply.h"
#include "tools/relight.h"
#include "io/result_ply.h"
#include "test_paths.h"
#include "test_scenes.h"
#include "visibility/visibility.h"
#include "thesis_settings.h"

using namespace vbrdf;

namespace {
// A grid facing a camera on +y, photographed under a light from +y: every pixel of the plane has
// the colour of a Lambertian reflectance `rho` lit head on (N.L = 1), encoded in 16-bit linear.
struct Scene {
  MeshData mesh = test::make_grid(10, 1.0f, 0.0f);
  Raster raster;
  std::array<float, 3> light{{0, 1, 0}};
  Scene(const float rho[3]) {
    const float eye[3] = {0, 4, 0.01f}, target[3] = {0, 0, 0}, up[3] = {0, 0, -1};
    raster.shot = test::make_look_at_shot(eye, target, up, 300, 320, 240);
    raster.label = "held_out";
    cv::Mat img(240, 320, CV_16UC3, cv::Scalar(rho[2] * 65535, rho[1] * 65535, rho[0] * 65535));
    raster.image_path = test::scratch_dir("relight") + "/held_out.png";
    cv::imwrite(raster.image_path, img);
  }
};

VertexFit diffuse_fit(const float rho[3]) {
  VertexFit f{};
  f.kd = std::max(rho[0], std::max(rho[1], rho[2]));
  for (int c = 0; c < 3; ++c) f.color[c] = rho[c] / f.kd;
  f.status = kFitDiffuseOnly;
  return f;
}
} // namespace

TEST(Relight, PerfectModelScoresZeroAndWrongModelDoesNot) {
  const float rho[3] = {0.6f, 0.4f, 0.2f};
  Scene scene(rho);
  auto visibility = make_cpu_visibility(scene.mesh.view(), VisibilitySettings());
  const size_t n = scene.mesh.positions.size() / 3;
  std::vector<VertexFit> good(n, diffuse_fit(rho));
  const RelightStats s = evaluate_relighting(scene.mesh.view(), good, {scene.raster}, {LightSource::directional(scene.light)}, *visibility);
  ASSERT_GT(s.samples, 50u);
  EXPECT_LT(s.mean_de2000, 0.05);
  EXPECT_GT(s.psnr_db, 60.0);
  const float wrong_rho[3] = {0.3f, 0.4f, 0.2f};
  std::vector<VertexFit> wrong(n, diffuse_fit(wrong_rho));
  const RelightStats w = evaluate_relighting(scene.mesh.view(), wrong, {scene.raster}, {LightSource::directional(scene.light)}, *visibility);
  EXPECT_GT(w.mean_de2000, 5.0);
  EXPECT_LT(w.psnr_db, 25.0);
  EXPECT_EQ(w.per_raster_samples[0], w.samples);
  // All modelled: the clean measure only leaves out the plane's rim (mixed footprints).
  EXPECT_LT(w.clean_modelled.samples, w.samples);
  EXPECT_GT(w.clean_modelled.samples, w.samples / 2);
  EXPECT_EQ(w.unmodelled_samples, 0u);
  EXPECT_FALSE(w.has_baselines);
}

// Whole surface: vertices without a model are scored as black (what relighting the PLY shows);
// the labelled clean measure leaves them out; a vertex filter restricts both.
TEST(Relight, UnmodelledVerticesCountAsBlackAndFilterRestricts) {
  const float rho[3] = {0.6f, 0.4f, 0.2f};
  Scene scene(rho);
  auto visibility = make_cpu_visibility(scene.mesh.view(), VisibilitySettings());
  const size_t n = scene.mesh.positions.size() / 3;
  std::vector<VertexFit> fits(n, diffuse_fit(rho));
  std::vector<uint8_t> modelled(n, 1);
  for (size_t v = 0; v < n; v += 3) {
    fits[v] = VertexFit{};
    fits[v].status = kFitNone;
    modelled[v] = 0;
  }
  fits[1].status = 4;  // any status other than kFitNone counts as modelled
  const RelightStats s = evaluate_relighting(scene.mesh.view(), fits, {scene.raster}, {LightSource::directional(scene.light)}, *visibility);
  ASSERT_GT(s.samples, 50u);
  EXPECT_GT(s.unmodelled_samples, s.samples / 4);
  EXPECT_LT(s.unmodelled_samples, s.samples / 2);
  EXPECT_NEAR(s.unmodelled_share, double(s.unmodelled_samples) / double(s.samples), 1e-12);
  EXPECT_LE(s.clean_modelled.samples + s.unmodelled_samples, s.samples);  // + modelled rim samples
  EXPECT_LT(s.clean_modelled.mean, 0.05);
  EXPECT_GT(s.mean_de2000, 10.0);  // black against a mid-grey-ish colour on a third of the samples
  EXPECT_GT(s.p95_de2000, 30.0);
  EXPECT_EQ(s.seen_unmodelled_vertices, s.unmodelled_samples);  // one photo: one sample per vertex
  EXPECT_GE(s.seen_vertices, s.samples);

  RelightOptions only_modelled = vbrdf::test::thesis_relight_options();
  only_modelled.vertex_filter = &modelled;
  const RelightStats f = evaluate_relighting(scene.mesh.view(), fits, {scene.raster}, {LightSource::directional(scene.light)}, *visibility,
                                             only_modelled);
  EXPECT_EQ(f.samples, s.samples - s.unmodelled_samples);
  EXPECT_LT(f.mean_de2000, 0.05);
  EXPECT_EQ(f.seen_unmodelled_vertices, 0u);
  std::vector<uint8_t> wrong_size(n - 1, 1);
  only_modelled.vertex_filter = &wrong_size;
  EXPECT_THROW(evaluate_relighting(scene.mesh.view(), fits, {scene.raster}, {LightSource::directional(scene.light)}, *visibility, only_modelled),
               InputError);
}

// Baselines: PTM and RBF fitted per vertex on training photos of the same camera, scored on the
// same held-out samples as the product. The plane is Lambertian: the photo under light l has the
// colour rho * N.L everywhere.
TEST(Relight, BaselinesScoreTheSameSamples) {
  const float rho[3] = {0.6f, 0.4f, 0.2f};
  Scene scene(rho);  // held-out photo: light head on (N.L = 1)
  const std::string dir = test::scratch_dir("relight_baselines");
  std::vector<Raster> training;
  std::vector<std::array<float, 3>> training_lights;
  for (int ring = 0; ring < 2; ++ring)
    for (int k = 0; k < 8; ++k) {
      const float elev = ring == 0 ? 0.6f : 1.0f, az = 0.785398f * (float(k) + 0.5f * float(ring));
      const std::array<float, 3> l{{std::cos(elev) * std::cos(az), std::sin(elev), std::cos(elev) * std::sin(az)}};
      const float nl = l[1];  // normal +y
      Raster r = scene.raster;
      r.label = "train_" + std::to_string(training.size());
      r.image_path = dir + "/" + r.label + ".png";
      cv::imwrite(r.image_path, cv::Mat(240, 320, CV_16UC3,
                                        cv::Scalar(rho[2] * nl * 65535, rho[1] * nl * 65535, rho[0] * nl * 65535)));
      training.push_back(r);
      training_lights.push_back(l);
    }
  // A training photo from another camera is not used for this viewpoint.
  Raster other = training.front();
  const float eye[3] = {1, 4, 0.01f}, target[3] = {0, 0, 0}, up[3] = {0, 0, -1};
  other.shot = test::make_look_at_shot(eye, target, up, 300, 320, 240);
  training.push_back(other);
  training_lights.push_back({{0, 1, 0}});

  auto visibility = make_cpu_visibility(scene.mesh.view(), VisibilitySettings());
  const size_t n = scene.mesh.positions.size() / 3;
  std::vector<VertexFit> fits(n, diffuse_fit(rho));
  fits[0] = VertexFit{};  // one vertex without a model
  RelightOptions options = vbrdf::test::thesis_relight_options();
  options.training_rasters = &training;
  const std::vector<LightSource> training_sources = directional_lights(training_lights);
  options.training_lights = &training_sources;
  const RelightStats s = evaluate_relighting(scene.mesh.view(), fits, {scene.raster}, {LightSource::directional(scene.light)}, *visibility, options);
  ASSERT_TRUE(s.has_baselines);
  ASSERT_GT(s.samples, 50u);
  EXPECT_EQ(s.baseline_excluded, 0u);
  EXPECT_EQ(s.product_on_baseline_set.samples, s.samples);
  EXPECT_EQ(s.ptm.samples, s.samples);
  EXPECT_EQ(s.rbf.samples, s.samples);
  EXPECT_NEAR(s.product_on_baseline_set.mean, s.mean_de2000, 1e-9);
  // PTM extrapolates rho * sqrt(1 - lu^2 - lv^2) from the two rings (elevations 0.6, 1.0 rad) to
  // the zenith about 5 % too bright; the RBF stays finite and in range.
  EXPECT_LT(s.ptm.median, 3.0);
  EXPECT_GT(s.ptm.median, 0.1);
  EXPECT_LT(s.rbf.median, 40.0);
  ASSERT_EQ(s.rbf_sigma_per_raster.size(), 1u);
  EXPECT_GT(s.rbf_sigma_per_raster[0], 0.3f);  // nearest-neighbour angles of this dome: 0.4 - 0.5 rad
  EXPECT_LT(s.rbf_sigma_per_raster[0], 0.6f);
  // Without any training photo of the held-out viewpoint, every sample is excluded, none scored.
  std::vector<Raster> only_other{other};
  std::vector<std::array<float, 3>> only_other_light{{{0, 1, 0}}};
  options.training_rasters = &only_other;
  const std::vector<LightSource> only_other_source = directional_lights(only_other_light);
  options.training_lights = &only_other_source;
  const RelightStats e = evaluate_relighting(scene.mesh.view(), fits, {scene.raster}, {LightSource::directional(scene.light)}, *visibility, options);
  EXPECT_EQ(e.baseline_excluded, e.samples);
  EXPECT_EQ(e.ptm.samples, 0u);
  EXPECT_EQ(e.samples, s.samples);
}

TEST(ResultPly, RoundTripsFitsAndRejectsMissingProperties) {
  const MeshData mesh = test::make_grid(3, 1.0f, 0.0f);
  const size_t n = mesh.positions.size() / 3;
  std::vector<VertexAttribute> attrs;
  const char *names[] = {"kd", "ks", "shininess", "color_r", "color_g", "color_b", "dq", "sq", "fit_rmse", "fit_status"};
  for (size_t k = 0; k < 10; ++k) {
    attrs.push_back({names[k], std::vector<float>(n)});
    for (size_t v = 0; v < n; ++v) attrs.back().values[v] = float(k) + 0.01f * float(v);
  }
  const std::string dir = test::scratch_dir("result_ply");
  write_result_ply(dir + "/r.ply", mesh.view(), std::vector<uint8_t>(4 * n, 77), attrs);
  const ResultPly r = read_result_ply(dir + "/r.ply");
  ASSERT_EQ(r.mesh.positions, mesh.positions);
  ASSERT_EQ(r.mesh.indices, mesh.indices);
  ASSERT_EQ(r.mesh.colors.size(), 4 * n);
  EXPECT_EQ(r.mesh.colors[5], 77);
  const std::vector<VertexFit> fits = fits_from_result(r, dir + "/r.ply");
  ASSERT_EQ(fits.size(), n);
  EXPECT_FLOAT_EQ(fits[3].kd, 0.03f);
  EXPECT_FLOAT_EQ(fits[3].shininess, 2.03f);
  EXPECT_FLOAT_EQ(fits[3].color[2], 5.03f);
  EXPECT_EQ(fits[2].status, 9);
  // A diffuse-only result (no kd property) is refused with the property named.
  write_result_ply(dir + "/d.ply", mesh.view(), std::vector<uint8_t>(4 * n, 0), {{"diffuse_r", std::vector<float>(n)}});
  try {
    fits_from_result(read_result_ply(dir + "/d.ply"), dir + "/d.ply");
    FAIL();
  } catch (const InputError &e) {
    EXPECT_NE(std::string(e.what()).find("'kd'"), std::string::npos);
  }
  EXPECT_THROW(read_result_ply(dir + "/missing.ply"), InputError);
}
