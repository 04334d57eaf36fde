// Live relighting (live_relight.h), the render path of MeshLab's "Vertex BRDF: relight" plugin,
// against the relight renderer (relight_render.h) for the same light and view: both evaluate
// shaders/reflectance_model.glsl, so on every lit interior pixel of a convex object (no cast shadows,
// the one stated difference) they must agree within kTolerance. Controls with the other lobe form
// and with every vertex's diffuse form swapped show that the comparison can fail. GL through
// OSMesa; skipped when no context can be created.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "base/errors.h"
#include "osmesa_context.h"
#include "relight/live_legend.h"
#include "relight/live_relight.h"
#include "relight/relight_render.h"
#include "test_scenes.h"
#include "thesis_settings.h"

namespace vbrdf {
namespace {

constexpr int kW = 160, kH = 120;
// Linear units (1 = a white Lambertian surface lit head-on; an 8-bit level is 1/255): float rounding of the two programs'
// inputs (eye from an inverted matrix vs the shot's centre, light rotated to eye space and back).
constexpr float kAbsTolerance = 5e-4f, kRelTolerance = 5e-4f;  // measured here: 2e-6

#define REQUIRE_GL(ctx)                                                       \
  std::string why_;                                                           \
  auto ctx = test::OsMesaContext::try_create(&why_);                          \
  if (!ctx) GTEST_SKIP() << "no OSMesa context: " << why_

struct Scene {
  MeshData mesh;
  std::vector<VertexFit> fits;
  Shot shot;
  std::array<float, 3> light{{0.5f, 0.8f, 0.6f}};  // world, towards the light
};

// A sphere whose fits vary over the surface (colour with position, k_s = 0 on one side: the median
// shininess rule) seen in perspective.
Scene make_scene() {
  Scene s;
  const float centre[3] = {0.1f, -0.2f, 0.3f};
  s.mesh = test::make_sphere(centre, 1.0f, 40, 60);
  const size_t n = s.mesh.positions.size() / 3;
  s.fits.resize(n);
  for (size_t v = 0; v < n; ++v) {
    const float *p = &s.mesh.positions[3 * v];
    VertexFit &f = s.fits[v];
    f = VertexFit{};
    f.color[0] = 1.0f;
    f.color[1] = 0.5f + 0.4f * std::sin(3 * p[0]);
    f.color[2] = 0.3f + 0.2f * std::cos(2 * p[1]);
    f.kd = 0.6f;
    f.ks = p[0] > centre[0] + 0.5f ? 0.0f : 0.25f + 0.1f * p[2];
    f.shininess = f.ks > 0 ? 12.0f + 6.0f * p[1] : 0.0f;
    f.status = f.ks > 0 ? kFitFull : kFitDiffuseOnly;
    f.dq = 1.5f;
    f.sq = 0.5f;
  }
  const float eye[3] = {0.8f, 1.0f, 4.0f}, up[3] = {0, 1, 0};
  s.shot = test::make_look_at_shot(eye, centre, up, 120, kW, kH);
  return s;
}

// The live view of the shot: GL matrices from the same camera, the light rotated into eye space
// (what MeshLab's GL_LIGHT0 holds).
LiveView live_view(const Scene &s, LiveDisplay display, float exposure, bool srgb) {
  LiveView v;
  float mv[16], proj[16];
  gl_view_matrix(s.shot, mv);
  gl_projection_matrix(s.shot, 0.5f, 20.0f, proj);
  for (int i = 0; i < 16; ++i) v.modelview[i] = mv[i], v.projection[i] = proj[i];
  float len = 0;
  for (float c : s.light) len += c * c;
  len = std::sqrt(len);
  for (int r = 0; r < 3; ++r) {
    double e = 0;
    for (int k = 0; k < 3; ++k) e += double(mv[k * 4 + r]) * s.light[size_t(k)] / len;
    v.light_eye[r] = float(e);
  }
  v.light_eye[3] = 0;
  v.display = display;
  v.exposure = exposure;
  v.encode_srgb = srgb;
  return v;
}

struct Agreement {
  size_t compared = 0;
  double worst = 0;      // largest |live - reference| - tolerance (<= 0: all within)
  double max_abs = 0;
};

// Pixels lit in the reference with all 8 neighbours lit too (no silhouette or terminator pixels,
// where one rasterisation may cover a pixel the other does not).
Agreement compare(const RelitImage &ref, const std::vector<float> &live, float exposure, bool srgb) {
  Agreement a;
  auto lit = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < ref.width && y < ref.height &&
           ref.pixel_class[size_t(y) * size_t(ref.width) + size_t(x)] == kRelitLit;
  };
  auto encode = [](float c) {
    c = std::min(std::max(c, 0.0f), 1.0f);
    return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  };
  for (int y = 0; y < ref.height; ++y)
    for (int x = 0; x < ref.width; ++x) {
      bool interior = true;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) interior = interior && lit(x + dx, y + dy);
      if (!interior) continue;
      const size_t i = size_t(y) * size_t(ref.width) + size_t(x);
      EXPECT_EQ(live[4 * i + 3], 1.0f) << "live view has no surface at (" << x << ", " << y << ")";
      for (int c = 0; c < 3; ++c) {
        const float expected = srgb ? encode(exposure * ref.rgb[3 * i + size_t(c)]) : exposure * ref.rgb[3 * i + size_t(c)];
        const double diff = std::fabs(double(live[4 * i + size_t(c)]) - expected);
        a.max_abs = std::max(a.max_abs, diff);
        a.worst = std::max(a.worst, diff - (kAbsTolerance + kRelTolerance * std::fabs(expected)));
      }
      ++a.compared;
    }
  return a;
}

void check_forms(LobeForm lobe, const DiffuseForms &diffuse) {
  REQUIRE_GL(ctx);
  const Scene s = make_scene();
  RelightRenderSettings settings = vbrdf::test::thesis_render_settings();
  settings.lobe = lobe;
  settings.diffuse = diffuse;
  RelightRenderer reference(s.mesh.view(), s.fits, ctx->get_proc_address(), settings);
  const RelitImage ref = reference.render(s.shot, LightSource::directional(s.light));
  LiveRelight live(s.mesh.view(), s.fits, ctx->get_proc_address(), lobe, diffuse);

  const Agreement linear = compare(ref, live.render_offscreen(live_view(s, LiveDisplay::Full, 1.0f, false), kW, kH), 1.0f, false);
  EXPECT_GT(linear.compared, size_t(kW * kH / 8)) << "too few lit interior pixels to compare";
  EXPECT_LE(linear.worst, 0.0) << "live view and relight renderer disagree by up to " << linear.max_abs
                               << " (linear) over " << linear.compared << " pixels";
  // The screen path: exposure, clipping at 1 and sRGB encoding.
  const Agreement screen = compare(ref, live.render_offscreen(live_view(s, LiveDisplay::Full, 1.8f, true), kW, kH), 1.8f, true);
  EXPECT_LE(screen.worst, 0.0) << "sRGB output disagrees by up to " << screen.max_abs;

  // Control: the other lobe form must fail the same comparison (the test can fail).
  const LobeForm other = lobe == LobeForm::PhongRE ? LobeForm::BlinnNH : LobeForm::PhongRE;
  LiveRelight wrong(s.mesh.view(), s.fits, ctx->get_proc_address(), other, diffuse);
  const Agreement control = compare(ref, wrong.render_offscreen(live_view(s, LiveDisplay::Full, 1.0f, false), kW, kH), 1.0f, false);
  EXPECT_GT(control.worst, 0.0) << "the comparison does not see a different lobe form";
  // Control: every vertex's diffuse form swapped (coated <-> Lambert) must fail it too.
  auto flipped = std::make_shared<std::vector<uint8_t>>(s.fits.size());
  for (size_t v = 0; v < s.fits.size(); ++v) (*flipped)[v] = diffuse.at(v) == DiffuseForm::Coated ? 0 : 1;
  LiveRelight swapped(s.mesh.view(), s.fits, ctx->get_proc_address(), lobe, DiffuseForms{DiffuseForm::Lambert, flipped});
  const Agreement control_d =
      compare(ref, swapped.render_offscreen(live_view(s, LiveDisplay::Full, 1.0f, false), kW, kH), 1.0f, false);
  EXPECT_GT(control_d.worst, 0.0) << "the comparison does not see the vertices' diffuse forms";
  std::cout << lobe_form_label(lobe) << "/" << describe_diffuse_forms(diffuse) << ": " << linear.compared
            << " pixels, largest difference " << linear.max_abs << " linear, " << screen.max_abs
            << " sRGB; other lobe form: " << control.max_abs << ", diffuse forms swapped: " << control_d.max_abs << "\n";
}

TEST(LiveRelight, MatchesRelightRendererPhongLambert) {
  check_forms(LobeForm::PhongRE, DiffuseForms::everywhere(DiffuseForm::Lambert));
}
TEST(LiveRelight, MatchesRelightRendererBlinnCoated) {
  check_forms(LobeForm::BlinnNH, DiffuseForms::everywhere(DiffuseForm::Coated));
}
TEST(LiveRelight, MatchesRelightRendererGgxCoated) {
  check_forms(LobeForm::GgxNH, DiffuseForms::everywhere(DiffuseForm::Coated));
}
// A coat map: every other vertex coated (both renderers blend the forms across triangles alike).
TEST(LiveRelight, MatchesRelightRendererWithACoatMap) {
  const size_t n = make_scene().mesh.positions.size() / 3;
  auto coated = std::make_shared<std::vector<uint8_t>>(n, 0);
  for (size_t v = 0; v < n; v += 2) (*coated)[v] = 1;
  check_forms(LobeForm::BlinnNH, DiffuseForms{DiffuseForm::Lambert, coated});
}

// Diffuse only + specular only = full model (linear output), everywhere on the surface.
TEST(LiveRelight, TermsAddUpToTheModel) {
  REQUIRE_GL(ctx);
  const Scene s = make_scene();
  LiveRelight live(s.mesh.view(), s.fits, ctx->get_proc_address(), LobeForm::PhongRE,
                   DiffuseForms::everywhere(DiffuseForm::Lambert));
  const auto full = live.render_offscreen(live_view(s, LiveDisplay::Full, 1.0f, false), kW, kH);
  const auto diffuse = live.render_offscreen(live_view(s, LiveDisplay::Diffuse, 1.0f, false), kW, kH);
  const auto specular = live.render_offscreen(live_view(s, LiveDisplay::Specular, 1.0f, false), kW, kH);
  size_t surface = 0, specular_pixels = 0;
  for (size_t i = 0; i < size_t(kW * kH); ++i) {
    if (full[4 * i + 3] != 1.0f) continue;
    ++surface;
    specular_pixels += specular[4 * i] > 1e-3f;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(full[4 * i + size_t(c)], diffuse[4 * i + size_t(c)] + specular[4 * i + size_t(c)], 1e-5f);
    EXPECT_FLOAT_EQ(specular[4 * i], specular[4 * i + 2]);  // grey
  }
  EXPECT_GT(surface, size_t(1000));
  EXPECT_GT(specular_pixels, size_t(50)) << "no highlight in view: the scene does not test the specular term";
}

// False colours: the legend's colour of each vertex's code or value, shaded (hue kept).
TEST(LiveRelight, FalseColoursFollowTheLegend) {
  REQUIRE_GL(ctx);
  const Scene s = make_scene();
  LiveRelight live(s.mesh.view(), s.fits, ctx->get_proc_address(), LobeForm::PhongRE,
                   DiffuseForms::everywhere(DiffuseForm::Lambert));
  const struct {
    LiveDisplay display;
    std::array<float, 3> expected;  // uniform dq = 1.5, sq = 0.5 in make_scene
  } cases[] = {{LiveDisplay::DiffuseQuality, quality_color(1.5f)}, {LiveDisplay::SpecularQuality, quality_color(0.5f)}};
  for (const auto &c : cases) {
    const auto img = live.render_offscreen(live_view(s, c.display, 1.0f, false), kW, kH);
    const size_t centre = size_t(kH / 2) * kW + kW / 2;
    ASSERT_EQ(img[4 * centre + 3], 1.0f);
    const float scale = img[4 * centre] / c.expected[0];
    EXPECT_GE(scale, 0.35f - 1e-4f);
    EXPECT_LE(scale, 1.0f + 1e-4f);
    for (int k = 1; k < 3; ++k) EXPECT_NEAR(img[4 * centre + size_t(k)], scale * c.expected[size_t(k)], 1e-4f);
  }
  EXPECT_EQ(fit_status_legend().size(), size_t(5));  // one entry per FitStatus code
}

TEST(LiveRelight, RejectsMismatchedFitsAndSingularViews) {
  REQUIRE_GL(ctx);
  const Scene s = make_scene();
  std::vector<VertexFit> short_fits(s.fits.begin(), s.fits.end() - 1);
  EXPECT_THROW(LiveRelight(s.mesh.view(), short_fits, ctx->get_proc_address(), LobeForm::PhongRE,
                   DiffuseForms::everywhere(DiffuseForm::Lambert)),
               InputError);
  LiveRelight live(s.mesh.view(), s.fits, ctx->get_proc_address(), LobeForm::PhongRE,
                   DiffuseForms::everywhere(DiffuseForm::Lambert));
  LiveView v = live_view(s, LiveDisplay::Full, 1.0f, false);
  LiveView zero_light = v;
  for (float &c : zero_light.light_eye) c = 0;
  EXPECT_THROW(live.render_offscreen(zero_light, 8, 8), InputError);
  LiveView singular = v;
  for (double &m : singular.modelview) m = 0;
  EXPECT_THROW(live.render_offscreen(singular, 8, 8), InputError);
}

} // namespace
} // namespace vbrdf
