// Relighting evaluation and the result PLY round trip.
#include <cmath>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "errors.h"
#include "output_ply.h"
#include "relight.h"
#include "result_ply.h"
#include "test_paths.h"
#include "test_scenes.h"
#include "visibility.h"

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
  const RelightStats s = evaluate_relighting(scene.mesh.view(), good, {scene.raster}, {scene.light}, *visibility,
                                             GatherSettings());
  ASSERT_GT(s.samples, 50u);
  EXPECT_LT(s.mean_de2000, 0.05);
  EXPECT_GT(s.psnr_db, 60.0);
  const float wrong_rho[3] = {0.3f, 0.4f, 0.2f};
  std::vector<VertexFit> wrong(n, diffuse_fit(wrong_rho));
  const RelightStats w = evaluate_relighting(scene.mesh.view(), wrong, {scene.raster}, {scene.light}, *visibility,
                                             GatherSettings());
  EXPECT_GT(w.mean_de2000, 5.0);
  EXPECT_LT(w.psnr_db, 25.0);
  EXPECT_EQ(w.per_raster_samples[0], w.samples);
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
