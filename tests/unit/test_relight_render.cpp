// Image-space relighting (relight_render.h): renders against analytic answers (per-pixel Phong,
// cast shadows, unfitted vertices), the photo comparison, the written images and table, and the
// novel-view camera. GL through OSMesa; skipped when no context can be created.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "base/color_difference.h"
#include "base/errors.h"
#include "base/file_util.h"
#include "osmesa_context.h"
#include "relight/orbit_camera.h"
#include "relight/relight_render.h"
#include "relight/relight_report.h"
#include "test_paths.h"
#include "test_scenes.h"
#include "thesis_settings.h"

namespace vbrdf {
namespace {

constexpr int kW = 160, kH = 120;

std::unique_ptr<test::OsMesaContext> context_or_skip(std::string &why) {
  return test::OsMesaContext::try_create(&why);
}
#define REQUIRE_GL(ctx)                                   \
  std::string why_;                                       \
  auto ctx = context_or_skip(why_);                       \
  if (!ctx) GTEST_SKIP() << "no OSMesa context: " << why_

VertexFit reflectance_fit(const float rho[3], float ks, float shininess) {
  VertexFit f{};
  f.kd = std::max(rho[0], std::max(rho[1], rho[2]));
  for (int c = 0; c < 3; ++c) f.color[c] = f.kd > 0 ? rho[c] / f.kd : 0;
  f.ks = ks;
  f.shininess = shininess;
  f.status = ks > 0 ? kFitFull : kFitDiffuseOnly;
  return f;
}

// A camera above the plane y = 0 looking down (slightly tilted so that the view is generic).
Shot top_camera() {
  const float eye[3] = {0.2f, 3.0f, 0.6f}, target[3] = {0, 0, 0}, up[3] = {0, 0, -1};
  return test::make_look_at_shot(eye, target, up, 150, kW, kH);
}

// Ray through the centre of image pixel (x, y) intersected with the plane y = 0.
vcg::Point3f plane_point(const Shot &shot, int x, int y) {
  const vcg::Point2f vcg_px(x + 0.5f, float(shot.Intrinsics.ViewportPx[1]) - (y + 0.5f));
  const vcg::Point3f far_point = shot.UnProject(vcg_px, 1.0f), c = shot.GetViewPoint();
  const vcg::Point3f dir = far_point - c;
  return c + dir * (-c[1] / dir[1]);
}

size_t count_class(const RelitImage &r, uint8_t cls) {
  size_t n = 0;
  for (uint8_t c : r.pixel_class) n += c == cls;
  return n;
}

const float *pixel(const RelitImage &r, int x, int y) { return &r.rgb[3 * (size_t(y) * size_t(r.width) + size_t(x))]; }
uint8_t pixel_class(const RelitImage &r, int x, int y) { return r.pixel_class[size_t(y) * size_t(r.width) + size_t(x)]; }

// Renders the lit plane y = 0 (uniform reflectance fit) from top_camera() under `light` and compares
// every third pixel with the model evaluated at the pixel's plane point: the light's direction and
// irradiance there (light_source.h, as the CPU computes them).
struct PlaneCheck {
  size_t checked = 0, shadowed = 0, unfitted = 0;
  double worst = 0, brightest = 0, darkest = 1e9;
};
// A coat map (settings.diffuse varying) is given as coated on the vertices with x < 0; pixels over
// the column of triangles between x = -0.5 and 0 (grid spacing 0.5), which blend both forms, are
// not checked.
PlaneCheck render_plane(test::OsMesaContext &ctx, const LightSource &light,
                        RelightRenderSettings settings = vbrdf::test::thesis_render_settings(), bool coat_map = false) {
  const MeshData mesh = test::make_grid(8, 2.0f, 0.0f);
  if (coat_map) {
    auto coated = std::make_shared<std::vector<uint8_t>>(mesh.positions.size() / 3, 0);
    for (size_t v = 0; v < coated->size(); ++v) (*coated)[v] = mesh.positions[3 * v] < 0 ? 1 : 0;
    settings.diffuse = DiffuseForms{DiffuseForm::Lambert, coated};
  }
  const float rho[3] = {0.5f, 0.3f, 0.1f};
  const std::vector<VertexFit> fits(mesh.positions.size() / 3, reflectance_fit(rho, 0.4f, 30.0f));
  RelightRenderer renderer(mesh.view(), fits, ctx.get_proc_address(), settings);
  const Shot shot = top_camera();
  const RelitImage r = renderer.render(shot, light);
  EXPECT_EQ(r.width, kW);
  EXPECT_EQ(r.height, kH);
  PlaneCheck c;
  c.shadowed = count_class(r, kRelitShadowed);
  c.unfitted = count_class(r, kRelitNoFit);
  for (int y = 2; y < kH - 2; y += 3)
    for (int x = 2; x < kW - 2; x += 3) {
      if (pixel_class(r, x, y) != kRelitLit) continue;
      const vcg::Point3f p = plane_point(shot, x, y), e = (shot.GetViewPoint() - p).Normalize();
      const float pf[3] = {p[0], p[1], p[2]};
      float l[3];
      light_direction_at(light, pf, l);
      const vcg::Point3f n(0, 1, 0), lv(l[0], l[1], l[2]);
      const float d = n * lv;
      const vcg::Point3f refl = n * (2 * d) - lv;
      float expected[3];
      if (coat_map && p[0] > -0.55f && p[0] < 0.05f) continue;
      const DiffuseForm form = coat_map ? (p[0] < 0 ? DiffuseForm::Coated : DiffuseForm::Lambert) : settings.diffuse.uniform;
      const float nf[3] = {n[0], n[1], n[2]}, lf[3] = {lv[0], lv[1], lv[2]}, ef[3] = {e[0], e[1], e[2]};
      const float cosine = settings.lobe == LobeForm::PhongRE ? refl * e : lobe_cosine(settings.lobe, nf, lf, ef);
      evaluate_reflectance(fits[0], diffuse_factor(form, d, n * e), cosine, settings.lobe, expected);
      const float irradiance = light_irradiance_at(light, pf);
      for (int k = 0; k < 3; ++k)
        c.worst = std::max(c.worst, double(std::fabs(pixel(r, x, y)[k] - expected[k] * irradiance)));
      c.brightest = std::max(c.brightest, double(pixel(r, x, y)[0]));
      c.darkest = std::min(c.darkest, double(pixel(r, x, y)[0]));
      ++c.checked;
    }
  return c;
}

TEST(RelightRender, PerPixelPhongMatchesTheModelEverywhere) {
  REQUIRE_GL(ctx);
  const PlaneCheck c = render_plane(*ctx, LightSource::directional({{0.3f, 1.0f, 0.4f}}));
  EXPECT_EQ(c.shadowed, 0u);
  EXPECT_EQ(c.unfitted, 0u);
  EXPECT_GT(c.checked, 500u);  // the plane fills the view
  EXPECT_LT(c.worst, 2e-3);
}

// The coated diffuse form (diffuse_form.h): the shader's copy agrees with the CPU's, and it is in
// effect (a low light dims the coated render against the Lambertian one).
TEST(RelightRender, CoatedDiffuseMatchesTheModelEverywhere) {
  REQUIRE_GL(ctx);
  const LightSource low = LightSource::directional({{1.0f, 0.3f, 0.2f}});  // N.L about 0.28
  RelightRenderSettings coated = vbrdf::test::thesis_render_settings();
  coated.diffuse = DiffuseForms::everywhere(DiffuseForm::Coated);
  const PlaneCheck c = render_plane(*ctx, low, coated);
  EXPECT_GT(c.checked, 500u);
  EXPECT_LT(c.worst, 2e-3);
  const PlaneCheck lambert = render_plane(*ctx, low);
  EXPECT_LT(lambert.worst, 2e-3);
  EXPECT_LT(c.brightest, 0.9 * lambert.brightest);  // T(0.28)/T(1) is about 0.78
  const PlaneCheck map = render_plane(*ctx, low, vbrdf::test::thesis_render_settings(), true);  // per vertex
  EXPECT_GT(map.checked, 300u);
  EXPECT_LT(map.worst, 2e-3);
}

// The GGX lobe (lobe.h lobe_value): the shader's copy agrees with the CPU's over the plane, whose
// pixels span the highlight and its tail; it is in effect (Blinn-Phong of the same exponent renders
// other values).
TEST(RelightRender, GgxLobeMatchesTheModelEverywhere) {
  REQUIRE_GL(ctx);
  const LightSource light = LightSource::directional({{0.3f, 1.0f, 0.4f}});
  RelightRenderSettings ggx = vbrdf::test::thesis_render_settings();
  ggx.lobe = LobeForm::GgxNH;
  const PlaneCheck c = render_plane(*ctx, light, ggx);
  EXPECT_GT(c.checked, 500u);
  EXPECT_LT(c.worst, 2e-3);
  RelightRenderSettings blinn = vbrdf::test::thesis_render_settings();
  blinn.lobe = LobeForm::BlinnNH;
  EXPECT_LT(render_plane(*ctx, light, blinn).worst, 2e-3);
  EXPECT_GT(std::fabs(c.brightest - render_plane(*ctx, light, blinn).brightest) + std::fabs(c.darkest - render_plane(*ctx, light, blinn).darkest), 1e-3);
}

// A point light close over the plane: per pixel its own direction and the inverse-square fall-off.
TEST(RelightRender, PointLightHasPerPixelDirectionAndFallOff) {
  REQUIRE_GL(ctx);
  LightSource light;
  light.positional = true;
  light.position = {{0.6f, 3.2f, -0.3f}};  // 3.2 above a plate of half-width 2: directions vary by ~60 degrees
  light.reference_distance = 3.2f;
  light.intensity = 0.8f;
  const PlaneCheck c = render_plane(*ctx, light);
  EXPECT_GT(c.checked, 500u);
  EXPECT_LT(c.worst, 3e-3);
  EXPECT_GT(c.brightest, 1.5 * c.darkest);  // the fall-off and the changing N.L are really there
  // The fall-off itself: inverse square of the distance, 1 x intensity at the reference distance.
  const float at_ref[3] = {0.6f, 0.0f, -0.3f}, twice[3] = {0.6f, -3.2f, -0.3f};
  EXPECT_NEAR(light_irradiance_at(light, at_ref), 0.8f, 1e-6f);
  EXPECT_NEAR(light_irradiance_at(light, twice), 0.2f, 1e-6f);
  EXPECT_TRUE(std::isfinite(light_irradiance_at(light, light.position.data())));
}

TEST(RelightRender, CastShadowsAndUnfittedVertices) {
  REQUIRE_GL(ctx);
  // Ground plane plus a small plate at height 1 over the origin; light from +x, 45 degrees up:
  // the plate's shadow falls around x = -1 on the ground.
  MeshData mesh = test::make_grid(40, 2.0f, 0.0f);
  test::append_mesh(mesh, test::make_grid(4, 0.3f, 1.0f));
  const size_t n = mesh.positions.size() / 3;
  const float grey[3] = {0.5f, 0.5f, 0.5f};
  std::vector<VertexFit> fits(n, reflectance_fit(grey, 0, 0));
  // The ground's far corner (x, z > 1.5) has no fit.
  for (size_t v = 0; v < 41 * 41; ++v)
    if (mesh.positions[3 * v] > 1.5f && mesh.positions[3 * v + 2] > 1.5f) fits[v] = VertexFit{};
  const float eye[3] = {0.0f, 6.0f, 0.01f}, target[3] = {0, 0, 0}, up[3] = {0, 0, -1};
  const Shot shot = test::make_look_at_shot(eye, target, up, 200, 320, 240);
  RelightRenderer renderer(mesh.view(), fits, ctx->get_proc_address(), vbrdf::test::thesis_render_settings());
  const float s = std::sqrt(0.5f), light[3] = {s, s, 0};
  const RelitImage r = renderer.render(shot, LightSource::directional({{light[0], light[1], light[2]}}));
  auto class_at = [&](float x, float z) {
    const float w[3] = {x, 0.0f, z};
    const ImagePoint p = project_to_image(shot, w);
    return pixel_class(r, int(p.x), int(p.y));
  };
  EXPECT_EQ(class_at(-1.0f, 0.0f), kRelitShadowed);  // under the plate's shadow
  EXPECT_EQ(class_at(1.0f, 0.0f), kRelitLit);        // the mirror position is lit
  EXPECT_EQ(class_at(-1.0f, 1.0f), kRelitLit);       // beside the shadow
  EXPECT_EQ(class_at(1.8f, 1.8f), kRelitNoFit);
  const ImagePoint q = project_to_image(shot, std::array<float, 3>{{1.0f, 0.0f, 0.0f}}.data());
  EXPECT_NEAR(pixel(r, int(q.x), int(q.y))[0], 0.5f * s, 1e-3f);  // rho N.L
  // Light from below: everything faces away.
  const float below[3] = {0, -1, 0};
  const RelitImage dark = renderer.render(shot, LightSource::directional({{below[0], below[1], below[2]}}));
  EXPECT_EQ(count_class(dark, kRelitLit), 0u);
  EXPECT_EQ(count_class(dark, kRelitShadowed) + count_class(dark, kRelitNoFit),
            size_t(320 * 240) - count_class(dark, kRelitBackground));
  EXPECT_GT(count_class(dark, kRelitShadowed), size_t(320 * 240 / 10));
}

TEST(RelightRender, RejectsMismatchedFitsAndBadLights) {
  REQUIRE_GL(ctx);
  const MeshData mesh = test::make_grid(2, 1.0f, 0.0f);
  EXPECT_THROW(RelightRenderer(mesh.view(), std::vector<VertexFit>(3), ctx->get_proc_address(), vbrdf::test::thesis_render_settings()), InputError);
  RelightRenderer renderer(mesh.view(), std::vector<VertexFit>(9), ctx->get_proc_address(), vbrdf::test::thesis_render_settings());
  const float zero[3] = {0, 0, 0};
  EXPECT_THROW(renderer.render(top_camera(), LightSource::directional({{zero[0], zero[1], zero[2]}})), InputError);
  EXPECT_THROW(renderer.render(Shot(), LightSource::directional({{0, 1, 0}})), InputError);
}

// A flat plane lit head on: its photo is rho everywhere on the plane (16-bit linear PNG).
struct FlatScene {
  MeshData mesh = test::make_grid(10, 1.0f, 0.0f);
  Raster raster;
  std::array<float, 3> light{{0, 1, 0}};
  std::string dir = test::scratch_dir("relight_render");
  FlatScene(const float photo_rho[3], const float model_rho[3], std::vector<VertexFit> &fits) {
    const float eye[3] = {0, 4, 0.01f}, target[3] = {0, 0, 0}, up[3] = {0, 0, -1};
    raster.shot = test::make_look_at_shot(eye, target, up, 120, kW, kH);
    raster.label = "held out, 1";
    raster.image_path = dir + "/held_out.png";
    cv::Mat img(kH, kW, CV_16UC3, cv::Scalar(0, 0, 0));
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const vcg::Point3f p = plane_point(raster.shot, x, y);
        if (std::fabs(p[0]) < 0.98f && std::fabs(p[2]) < 0.98f)
          img.at<cv::Vec3w>(y, x) = cv::Vec3w(uint16_t(photo_rho[2] * 65535), uint16_t(photo_rho[1] * 65535),
                                               uint16_t(photo_rho[0] * 65535));
      }
    cv::imwrite(raster.image_path, img);
    fits.assign(mesh.positions.size() / 3, reflectance_fit(model_rho, 0, 0));
  }
};

TEST(RelightRender, ComparesLitVisiblePixelsWithThePhoto) {
  REQUIRE_GL(ctx);
  const float rho[3] = {0.6f, 0.4f, 0.2f}, wrong[3] = {0.3f, 0.4f, 0.2f};
  std::vector<VertexFit> fits;
  FlatScene scene(rho, rho, fits);
  RelightRenderer renderer(scene.mesh.view(), fits, ctx->get_proc_address(), vbrdf::test::thesis_render_settings());
  const RelightReport good = relight_rasters(renderer, {scene.raster}, {LightSource::directional(scene.light)}, RelightOutputOptions());
  ASSERT_EQ(good.rows.size(), 1u);
  const PixelComparison &c = good.rows[0].comparison;
  EXPECT_GT(c.pixels, 2000u);
  EXPECT_LT(c.mean_de2000, 0.05);
  EXPECT_LT(c.p95_de2000, 0.1);
  EXPECT_GT(c.psnr_db, 60.0);
  EXPECT_TRUE(good.files.empty());  // no folder: nothing written
  ASSERT_FALSE(good.color_log.empty());  // no chart in this photo: compared as decoded, and said so
  EXPECT_NE(good.color_log.back().find("colours uncorrected"), std::string::npos) << good.color_log.back();
  RelightOutputOptions required;
  required.color_correction = ColorCorrectionChoice::Required;
  EXPECT_THROW(relight_rasters(renderer, {scene.raster}, {LightSource::directional(scene.light)}, required), InputError);
  RelightOutputOptions corners;
  corners.chart_corners = {1, 2, 3};
  EXPECT_THROW(relight_rasters(renderer, {scene.raster}, {LightSource::directional(scene.light)}, corners), InputError);
  RelightOutputOptions off;
  off.color_correction = ColorCorrectionChoice::Off;
  EXPECT_TRUE(relight_rasters(renderer, {scene.raster}, {LightSource::directional(scene.light)}, off).color_log.empty());
  // Silhouette pixels are never compared: fewer pixels than the plane covers.
  const RelitImage r = renderer.render(scene.raster.shot, LightSource::directional(scene.light));
  EXPECT_LT(c.pixels, count_class(r, kRelitLit));

  std::vector<VertexFit> wrong_fits;
  FlatScene other(rho, wrong, wrong_fits);
  RelightRenderer wrong_renderer(other.mesh.view(), wrong_fits, ctx->get_proc_address(), vbrdf::test::thesis_render_settings());
  const RelightReport bad = relight_rasters(wrong_renderer, {other.raster}, {LightSource::directional(other.light)}, RelightOutputOptions());
  const double expected = delta_e2000_linear_srgb(wrong, rho);
  EXPECT_NEAR(bad.rows[0].comparison.mean_de2000, expected, 0.05);
  EXPECT_NEAR(bad.rows[0].comparison.p95_de2000, expected, 0.05);
  EXPECT_NEAR(bad.overall.comparison.mean_de2000, expected, 0.05);
  EXPECT_LT(bad.rows[0].comparison.psnr_db, 25.0);
}

// Whole surface (no GL needed): every lit or unfitted surface pixel, silhouettes included,
// unfitted predicted black, clipped photo pixels left out; the interior measure drops the rim.
TEST(RelightRender, WholeSurfaceComparisonCountsRimAndUnfittedPixels) {
  const int w = 12, h = 10;
  RelitImage r;
  r.width = w;
  r.height = h;
  r.rgb.assign(size_t(3 * w * h), 0.4f);
  r.pixel_class.assign(size_t(w * h), kRelitBackground);
  r.depth.assign(size_t(w * h), 0.0f);
  for (int y = 1; y < h - 1; ++y)
    for (int x = 1; x < w - 1; ++x) {
      const size_t i = size_t(y * w + x);
      r.pixel_class[i] = x >= 8 ? kRelitNoFit : (y == 5 && x == 3) ? kRelitShadowed : kRelitLit;
      r.depth[i] = 2.0f;
    }
  cv::Mat photo(h, w, CV_32FC3, cv::Scalar(0.4f, 0.4f, 0.4f));
  cv::Mat clipped(h, w, CV_8U, cv::Scalar(0));
  clipped.at<uint8_t>(2, 2) = 255;
  const size_t surface = size_t((w - 2) * (h - 2));
  const size_t nofit = size_t(3 * (h - 2));  // columns 8, 9, 10
  const PixelComparison whole = compare_whole_surface(r, photo, clipped);
  EXPECT_EQ(whole.pixels, surface - 1 /* shadowed */ - 1 /* clipped */);
  const float black[3] = {0, 0, 0}, grey[3] = {0.4f, 0.4f, 0.4f};
  const double de_black = delta_e2000_linear_srgb(black, grey);
  EXPECT_NEAR(whole.mean_de2000, de_black * double(nofit) / double(whole.pixels), 1e-3);
  EXPECT_GT(whole.p95_de2000, de_black - 0.02);  // 24 of 78 pixels are black
  const PixelComparison interior = compare_with_photo(r, photo, clipped, 100.0f);
  EXPECT_GT(interior.pixels, 0u);
  EXPECT_LT(interior.pixels, whole.pixels - nofit);  // the rim next to the background is left out
  EXPECT_LT(interior.mean_de2000, 1e-3);
  EXPECT_THROW(compare_whole_surface(r, cv::Mat(h, w + 1, CV_32FC3), clipped), InputError);
}

TEST(RelightRender, WritesImagesContactSheetAndTable) {
  REQUIRE_GL(ctx);
  const float rho[3] = {0.6f, 0.4f, 0.2f}, model[3] = {0.5f, 0.4f, 0.25f};
  std::vector<VertexFit> fits;
  FlatScene scene(rho, model, fits);
  RelightRenderer renderer(scene.mesh.view(), fits, ctx->get_proc_address(), vbrdf::test::thesis_render_settings());
  RelightOutputOptions options;
  options.folder = scene.dir + "/out/nested";
  Raster second = scene.raster;
  second.label = "second";
  const RelightReport report = relight_rasters(renderer, {scene.raster, second}, {LightSource::directional(scene.light), LightSource::directional(scene.light)}, options);
  ASSERT_EQ(report.files.size(), 4u);
  for (const std::string &f : report.files) EXPECT_TRUE(file_exists(f)) << f;
  EXPECT_EQ(file_name_of(report.files[0]), "relight_000_held_out__1.png");
  const cv::Mat panel = cv::imread(report.files[0]);
  EXPECT_EQ(panel.cols, 3 * kW);
  EXPECT_GT(panel.rows, kH);
  EXPECT_FALSE(cv::imread(options.folder + "/contact_sheet.png").empty());
  std::ifstream csv(options.folder + "/relight_table.csv");
  std::string header, row1, row2, all;
  std::getline(csv, header);
  std::getline(csv, row1);
  std::getline(csv, row2);
  std::getline(csv, all);
  EXPECT_EQ(header, "raster,photo,pixels,mean_de2000,median_de2000,p95_de2000,psnr_db,whole_surface_pixels,"
                    "whole_surface_mean_de2000,whole_surface_median_de2000,whole_surface_p95_de2000,"
                    "whole_surface_psnr_db");
  EXPECT_EQ(row1.rfind("\"held out, 1\",", 0), 0u) << row1;  // labels with commas are quoted
  EXPECT_EQ(all.rfind("all,,", 0), 0u) << all;
  EXPECT_NEAR(report.overall.comparison.mean_de2000, report.rows[0].comparison.mean_de2000, 1e-9);
  EXPECT_EQ(report.overall.comparison.pixels, 2 * report.rows[0].comparison.pixels);
  // The whole-surface figure stands beside it: more pixels (the rim), pooled the same way.
  EXPECT_GT(report.rows[0].whole_surface.pixels, report.rows[0].comparison.pixels);
  EXPECT_EQ(report.overall.whole_surface.pixels, 2 * report.rows[0].whole_surface.pixels);
  EXPECT_EQ(std::count(all.begin(), all.end(), ','), 11) << all;

  // Never over a photo; a missing photo is named with its raster.
  RelightOutputOptions over = options;
  over.folder = scene.dir;
  Raster clash = scene.raster;
  clash.image_path = scene.dir + "/contact_sheet.png";
  EXPECT_THROW(relight_rasters(renderer, {clash}, {LightSource::directional(scene.light)}, over), InputError);
  Raster missing = scene.raster;
  missing.image_path = scene.dir + "/nope.png";
  try {
    relight_rasters(renderer, {missing}, {LightSource::directional(scene.light)}, RelightOutputOptions());
    FAIL();
  } catch (const InputError &e) {
    EXPECT_NE(std::string(e.what()).find("held out, 1"), std::string::npos) << e.what();
  }
}

TEST(RelightRender, OrbitShotKeepsThePivotInViewAndMovesTheCamera) {
  const float eye[3] = {0, 1, 5}, target[3] = {0, 1, 0}, up[3] = {0, 1, 0};
  const Shot base = test::make_look_at_shot(eye, target, up, 500, 640, 480);
  const Shot same = orbit_shot(base, target, 0, 0, 1);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(same.GetViewPoint()[k], base.GetViewPoint()[k], 1e-5);
  const Shot right = orbit_shot(base, target, 90, 0, 2);
  EXPECT_NEAR(right.GetViewPoint()[0], 10.0, 1e-4);  // moved to the camera's right (+x), twice as far
  EXPECT_NEAR(right.GetViewPoint()[1], 1.0, 1e-4);
  EXPECT_NEAR(right.GetViewPoint()[2], 0.0, 1e-4);
  const Shot above = orbit_shot(base, target, 0, 30, 1);
  EXPECT_GT(above.GetViewPoint()[1], 1.0f + 2.4f);
  for (const Shot *s : {&right, &above}) {
    const ImagePoint p = project_to_image(*s, target);
    EXPECT_NEAR(p.x, 320.0, 1e-2);
    EXPECT_NEAR(p.y, 240.0, 1e-2);
    EXPECT_TRUE(shot_is_valid(*s));
  }
  EXPECT_THROW(orbit_shot(base, target, 0, 0, 0), InputError);
}

TEST(RelightRender, PoolsComparisonsAndMakesSafeNames) {
  PixelComparison a, b;
  a.pixels = 3, a.mean_de2000 = 1, a.squared_error = 0.03;
  b.pixels = 1, b.mean_de2000 = 5, b.squared_error = 0.01;
  a.histogram.assign(kDeHistogramBins, 0);
  b.histogram.assign(kDeHistogramBins, 0);
  a.histogram[100] = 3;
  b.histogram[500] = 1;
  const PixelComparison p = pool_comparisons({&a, &b});
  EXPECT_EQ(p.pixels, 4u);
  EXPECT_DOUBLE_EQ(p.mean_de2000, 2.0);
  EXPECT_NEAR(p.median_de2000, 1.005, 1e-9);
  EXPECT_NEAR(p.p95_de2000, 5.005, 1e-9);
  EXPECT_NEAR(p.psnr_db, 10 * std::log10(1.0 / (0.04 / 12)), 1e-9);
  EXPECT_EQ(file_safe_label("a b/c.png"), "a_b_c.png");
  EXPECT_EQ(file_safe_label(""), "raster");
}

} // namespace
} // namespace vbrdf
