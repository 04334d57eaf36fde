// Sample flags and geometry terms for constructed vertex/camera/light configurations.
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstring>

#include "samples/samples.h"
#include "test_paths.h"
#include "test_scenes.h"
#include "thesis_settings.h"

using namespace vbrdf;

namespace {
struct Fixture {
  Raster raster;
  Photo photo;
  GatherSettings settings = vbrdf::test::thesis_gather_settings();
  Fixture() {
    const float c[3] = {0, 0, 10}, t[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    raster.shot = test::make_look_at_shot(c, t, up, 500, 64, 48);
    raster.label = "r0";
    cv::Mat img(48, 64, CV_8UC3, cv::Scalar(100, 150, 200));
    img.at<cv::Vec3b>(10, 10) = cv::Vec3b(255, 255, 255);
    raster.image_path = test::scratch_dir("samples") + "/img.png";
    cv::imwrite(raster.image_path, img);
    photo = load_photo(raster.image_path, PhotoEncoding::Auto);
  }
  Sample sample(const float p[3], const float n[3], const float l[3], bool cam = true, bool light = true) {
    Sample s;
    make_sample(p, n, raster, 3, LightSource::directional({{l[0], l[1], l[2]}}), photo, cam, light, settings, s);
    return s;
  }
  Sample sample(const float p[3], const float n[3], const LightSource &l, bool cam = true, bool light = true) {
    Sample s;
    make_sample(p, n, raster, 3, l, photo, cam, light, settings, s);
    return s;
  }
};
const float kOrigin[3] = {0, 0, 0};
const float kFacing[3] = {0, 0, 1};

// `count` vertices on the plane z = 0 facing +z, `per_row` to a row from (x0, y0), spacing dx, dy.
MeshData facing_grid(int count, int per_row, float x0, float y0, float dx, float dy) {
  MeshData mesh;
  for (int i = 0; i < count; ++i) {
    mesh.positions.insert(mesh.positions.end(), {x0 + float(i % per_row) * dx, y0 + float(i / per_row) * dy, 0});
    mesh.normals.insert(mesh.normals.end(), {0, 0, 1});
  }
  mesh.indices = {0, 1, uint32_t(per_row)};
  return mesh;
}

// Every vertex seen and lit by every raster, no mixed footprints.
VisibilityMasks all_seen(size_t vertices, size_t rasters) {
  VisibilityMasks masks;
  masks.vertex_count = vertices;
  masks.raster_count = rasters;
  masks.seen.assign(masks.words() * rasters, ~uint64_t(0));
  masks.lit.assign(masks.words() * rasters, ~uint64_t(0));
  masks.mixed.assign(masks.words() * rasters, 0);
  for (auto *v : {&masks.off_image, &masks.back_facing, &masks.occluded}) v->assign(rasters, 0);
  return masks;
}
} // namespace

TEST(Samples, HeadOnLightIsHighlightAndColourIsDecoded) {
  Fixture f;
  const Sample s = f.sample(kOrigin, kFacing, kFacing);
  EXPECT_EQ(s.raster, 3);
  EXPECT_NEAR(s.d, 1, 1e-6);
  EXPECT_NEAR(s.lobe_cos, 1, 1e-6);
  EXPECT_EQ(s.flags, kHighlight);
  EXPECT_NEAR(s.rgb[0], srgb_to_linear(200 / 255.0f), 1e-5);  // BGR on disk
  EXPECT_TRUE(is_specular_sample(s));
  EXPECT_FALSE(is_diffuse_sample(s));
}

TEST(Samples, DiffuseGrazingAndShadowFlags) {
  Fixture f;
  const LightSource side60 = LightSource::directional({{0.8660254f, 0, 0.5f}});  // N.L = 0.5 exactly at the threshold: not grazing
  Sample s = f.sample(kOrigin, kFacing, side60);
  EXPECT_EQ(s.flags, 0) << s.flags;
  EXPECT_NEAR(s.d, 0.5, 1e-6);
  EXPECT_NEAR(s.lobe_cos, 0.5, 1e-2);  // R = (-0.866, 0, 0.5), E ~ (0, 0, 1)
  EXPECT_TRUE(is_diffuse_sample(s));
  const float graze[3] = {0.97f, 0, 0.2431f};
  EXPECT_EQ(f.sample(kOrigin, kFacing, graze).flags, kGrazing);
  const float behind[3] = {0, 0, -1};
  EXPECT_EQ(f.sample(kOrigin, kFacing, behind).flags, kAttachedShadow);
  EXPECT_EQ(f.sample(kOrigin, kFacing, side60, true, false).flags, kCastShadow);
}

// The gatherer stores the diffuse form's factor in Sample::d; the grazing flag stays on plain N.L.
TEST(Samples, DiffuseFactorFollowsTheForm) {
  Fixture f;
  const float low[3] = {-0.5f, 0, 0.8660254f};  // 60 degrees off the camera axis
  const float tilted[3] = {0.6f, 0, 0.8f};        // a normal at N.E = 0.8 (camera on +z): N.L = 0.393
  const Sample lambert = f.sample(kOrigin, tilted, low);
  f.settings.diffuse = DiffuseForms::everywhere(DiffuseForm::Coated);
  const Sample coated = f.sample(kOrigin, tilted, low);
  const float nl = -0.6f * 0.5f + 0.8f * 0.8660254f, ne = 0.8f;
  EXPECT_NEAR(lambert.d, nl, 1e-3);
  EXPECT_NEAR(coated.d, diffuse_factor(DiffuseForm::Coated, nl, ne), 2e-3);
  EXPECT_LT(coated.d, 0.95f * lambert.d);
  EXPECT_EQ(coated.flags, lambert.flags);
  const float graze[3] = {0.97f, 0, 0.2431f};
  EXPECT_EQ(f.sample(kOrigin, kFacing, graze).flags, kGrazing);  // N.L < T_d, coated or not
}

TEST(Samples, NotSeenCases) {
  Fixture f;
  const float away[3] = {0, 0, -1};
  EXPECT_TRUE(f.sample(kOrigin, away, kFacing).flags & kBackFacing);
  EXPECT_TRUE(f.sample(kOrigin, kFacing, kFacing, false).flags & kOccluded);
  const float far_right[3] = {5, 0, 0};
  EXPECT_TRUE(f.sample(far_right, kFacing, kFacing).flags & kOffImage);
  const float behind_cam[3] = {0, 0, 20};
  EXPECT_TRUE(f.sample(behind_cam, kFacing, kFacing).flags & kOffImage);
}

TEST(Samples, SaturatedPixelIsFlagged) {
  Fixture f;
  // Image pixel (10,10) is white. Find the world point projecting onto its centre: x = (10.5-32)/500*10.
  const float p[3] = {(10.5f - 32) / 50.0f, (24 - 10.5f) / 50.0f, 0};
  const LightSource side60 = LightSource::directional({{0.8660254f, 0, 0.5f}});
  const Sample s = f.sample(p, kFacing, side60);
  EXPECT_TRUE(s.flags & kSaturated);
  EXPECT_FALSE(is_diffuse_sample(s));
}

TEST(Samples, GatherStreamsChunksInVertexOrder) {
  // 3000 vertices on a plane facing the camera, 2 photos, forcing ~3 chunks.
  Fixture f;
  const MeshData mesh = facing_grid(3000, 60, -0.5f, -0.4f, 1.0f / 60, 1.0f / 70);
  std::vector<Raster> rasters = {f.raster, f.raster};
  std::vector<std::array<float, 3>> lights = {{{0, 0, 1}}, {{0.8660254f, 0, 0.5f}}};
  VisibilityMasks masks = all_seen(3000, 2);
  masks.lit[masks.words() + 0] = 0;  // raster 1: vertices 0..63 in cast shadow
  masks.seen[masks.words() + 1] = 0;  // raster 1 does not see vertices 64..127
  GatherSettings settings = vbrdf::test::thesis_gather_settings();
  settings.chunk_sample_bytes = 1024 * sizeof(Sample) * 2;
  PhotoCache cache(PhotoEncoding::Auto, 0.99f, 1 << 20);
  uint32_t next = 0;
  size_t total = 0;
  const GatherStats stats = gather_samples(mesh.view(), rasters, directional_lights(lights), masks, settings, cache, [&](const SampleChunk &c) {
    EXPECT_EQ(c.first_vertex, next);
    next += c.vertex_count;
    total += c.samples.size();
    for (uint32_t i = 0; i < c.vertex_count; ++i)
      for (uint32_t k = c.offsets[i]; k < c.offsets[i + 1]; ++k)
        if (c.first_vertex + i < 64 && c.samples[k].raster == 1) EXPECT_TRUE(c.samples[k].flags & kCastShadow);
  });
  EXPECT_EQ(next, 3000u);
  EXPECT_EQ(stats.chunks, 3u);
  EXPECT_EQ(stats.pairs, 6000u);
  EXPECT_EQ(stats.stored, total);
  EXPECT_EQ(stats.stored, 6000u - 64u);
  EXPECT_EQ(stats.flag_counts[4], 64u);  // kCastShadow is bit 4
  EXPECT_EQ(cache.loads(), 1u);          // same photo file: decoded once
}

// The block a chunk is gathered in holds only the vertices some photo sees: vertices no photo
// sees get no samples, every other vertex gets exactly the samples make_sample gives it, in
// raster order, across chunk boundaries that do not fall on a 64-vertex word.
TEST(Samples, GatherSkipsVerticesNoPhotoSees) {
  Fixture f;
  const size_t n = 2500;
  const MeshData mesh = facing_grid(int(n), 50, -0.5f, -0.4f, 1.0f / 50, 1.0f / 60);
  const std::vector<Raster> rasters = {f.raster, f.raster, f.raster};
  const std::vector<LightSource> lights =
      directional_lights({{{0, 0, 1}}, {{0.6f, 0, 0.8f}}, {{0, 0.6f, 0.8f}}});
  VisibilityMasks masks = all_seen(n, 3);
  const size_t words = masks.words();
  const auto clear_bit = [&](size_t r, size_t v) { masks.seen[r * words + v / 64] &= ~(uint64_t(1) << (v % 64)); };
  for (size_t v = 0; v < n; ++v) {
    if (v % 7 == 0 || (v >= 1090 && v < 1120) || v >= 2400)  // no photo sees these
      for (size_t r = 0; r < 3; ++r) clear_bit(r, v);
    if (v % 5 == 0) clear_bit(1, v);  // photo 1 misses some more
  }
  GatherSettings settings = vbrdf::test::thesis_gather_settings();
  settings.chunk_sample_bytes = 1100 * sizeof(Sample) * 3;  // chunks of 1100 vertices
  PhotoCache cache(PhotoEncoding::Auto, 0.99f, 1 << 20);
  size_t chunks = 0, unseen = 0, checked = 0;
  gather_samples(mesh.view(), rasters, lights, masks, settings, cache, [&](const SampleChunk &c) {
    ++chunks;
    for (uint32_t i = 0; i < c.vertex_count; ++i) {
      const size_t v = c.first_vertex + i;
      std::vector<size_t> expected;
      for (size_t r = 0; r < 3; ++r)
        if (masks.is_seen(r, v)) expected.push_back(r);
      ASSERT_EQ(c.offsets[i + 1] - c.offsets[i], expected.size()) << "vertex " << v;
      unseen += expected.empty();
      for (size_t k = 0; k < expected.size(); ++k) {
        const Sample &got = c.samples[c.offsets[i] + k];
        Sample want;
        make_sample(mesh.view().positions + 3 * v, mesh.view().normals + 3 * v, rasters[expected[k]],
                    uint16_t(expected[k]), lights[expected[k]], f.photo, true, true, settings, want);
        ASSERT_EQ(got.raster, want.raster) << "vertex " << v;
        EXPECT_EQ(0, std::memcmp(got.rgb, want.rgb, sizeof want.rgb)) << "vertex " << v;
        EXPECT_EQ(got.d, want.d) << "vertex " << v;
        EXPECT_EQ(got.lobe_cos, want.lobe_cos) << "vertex " << v;
        ++checked;
      }
    }
  });
  EXPECT_EQ(chunks, 3u);
  EXPECT_GT(unseen, 400u);
  EXPECT_GT(checked, 5000u);
}

// The masks may call a pair seen whose footprint make_sample still finds off the photo (the
// masks' frustum test is the vertex's projection, the sample needs its whole footprint): such
// samples are left out and the vertex's others close up behind them, so each vertex keeps exactly
// the samples make_sample stores, in raster order, and the counts add up to them.
TEST(Samples, GatherLeavesOutSamplesOffThePhotoThatTheMasksCallSeen) {
  Fixture f;
  const size_t n = 3000;
  // A grid wider than the photos: each photo's frame cuts it elsewhere.
  const MeshData mesh = facing_grid(int(n), 60, -0.9f, -0.6f, 1.8f / 60, 1.2f / 50);
  std::vector<Raster> rasters(3, f.raster);
  const float up[3] = {0, 1, 0};
  const float c1[3] = {0.4f, 0, 10}, t1[3] = {0.4f, 0, 0}, c2[3] = {-0.2f, 0.3f, 10}, t2[3] = {-0.2f, 0.3f, 0};
  rasters[1].shot = test::make_look_at_shot(c1, t1, up, 500, 64, 48);
  rasters[2].shot = test::make_look_at_shot(c2, t2, up, 500, 64, 48);
  const std::vector<LightSource> lights =
      directional_lights({{{0, 0, 1}}, {{0.6f, 0, 0.8f}}, {{0, 0.6f, 0.8f}}});
  VisibilityMasks masks = all_seen(n, 3);
  for (size_t v = 0; v < n; v += 11) masks.seen[masks.words() + v / 64] &= ~(uint64_t(1) << (v % 64));
  GatherSettings settings = vbrdf::test::thesis_gather_settings();
  settings.chunk_sample_bytes = 1100 * sizeof(Sample) * 3;  // chunks of 1100 vertices
  PhotoCache cache(PhotoEncoding::Auto, 0.99f, 1 << 20);
  size_t stored = 0, dropped = 0, partly = 0;
  uint64_t flag_counts[16] = {};
  std::vector<uint32_t> per_raster(3, 0);
  const GatherStats stats = gather_samples(mesh.view(), rasters, lights, masks, settings, cache, [&](const SampleChunk &c) {
    for (uint32_t i = 0; i < c.vertex_count; ++i) {
      const size_t v = c.first_vertex + i;
      std::vector<Sample> expected;
      for (size_t r = 0; r < 3; ++r) {
        if (!masks.is_seen(r, v)) continue;
        Sample want;
        if (make_sample(mesh.view().positions + 3 * v, mesh.view().normals + 3 * v, rasters[r], uint16_t(r), lights[r],
                        f.photo, true, true, settings, want) & kNotSeen) {
          ++dropped;
          continue;
        }
        expected.push_back(want);
        for (uint16_t fl = want.flags; fl; fl &= uint16_t(fl - 1)) ++flag_counts[__builtin_ctz(fl)];
        ++per_raster[r];
      }
      ASSERT_EQ(c.offsets[i + 1] - c.offsets[i], expected.size()) << "vertex " << v;
      partly += !expected.empty() && expected.size() < 3 - (v % 11 == 0);
      for (size_t k = 0; k < expected.size(); ++k) {
        const Sample &got = c.samples[c.offsets[i] + k];
        ASSERT_EQ(got.raster, expected[k].raster) << "vertex " << v;
        EXPECT_EQ(0, std::memcmp(got.rgb, expected[k].rgb, sizeof got.rgb)) << "vertex " << v;
        EXPECT_EQ(got.d, expected[k].d) << "vertex " << v;
        EXPECT_EQ(got.flags, expected[k].flags) << "vertex " << v;
      }
      stored += expected.size();
    }
  });
  EXPECT_GT(dropped, 500u);  // the test has teeth: many pairs the masks call seen are off a photo
  EXPECT_GT(partly, 200u);   // and many vertices lose some of their samples, not all
  EXPECT_EQ(stats.stored, stored);
  for (int b = 0; b < 16; ++b) EXPECT_EQ(stats.flag_counts[b], flag_counts[b]) << "flag bit " << b;
  EXPECT_EQ(stats.raster_seen_vertices, per_raster);
}

TEST(Samples, MasksTellWhetherARasterSeesAChunk) {
  VisibilityMasks m;
  m.vertex_count = 200;
  m.raster_count = 1;
  m.seen.assign(m.words(), 0);
  m.seen[2] = uint64_t(1) << 5;  // vertex 133
  EXPECT_TRUE(m.sees_any(0, 0, 200));
  EXPECT_TRUE(m.sees_any(0, 133, 1));
  EXPECT_FALSE(m.sees_any(0, 0, 133));
  EXPECT_FALSE(m.sees_any(0, 134, 66));
  EXPECT_TRUE(m.sees_any(0, 100, 34));
  EXPECT_FALSE(m.sees_any(0, 10, 0));
}

namespace vbrdf {
namespace {
// A vertex next to the white pixel: a footprint straddling a depth jump keeps its own-surface
// texels (kRimFootprint, colour from them) or, with none left or for the evaluation's plain
// bilinear, the whole footprint (kMixedPixel).
TEST(Samples, RimFootprintsUseTheirOwnSurfaceTexels) {
  Fixture f;
  // Image point (11.0, 11.0): footprint texels (10,10) white [bit 0], (11,10), (10,11), (11,11).
  const float p[3] = {(11.0f - 32) / 50.0f, (24 - 11.0f) / 50.0f, 0};
  const LightSource side60 = LightSource::directional({{0.8660254f, 0, 0.5f}});
  Sample own{}, plain{}, none{};
  make_sample(p, kFacing, f.raster, 0, side60, f.photo, true, true, f.settings, own, 0xE);  // white texel not own
  EXPECT_EQ(own.flags, kRimFootprint);
  EXPECT_NEAR(own.rgb[0], srgb_to_linear(200 / 255.0f), 1e-5);  // the white texel left out
  EXPECT_TRUE(is_diffuse_sample(own));
  GatherSettings evaluation = f.settings;
  evaluation.own_surface_texels = false;
  make_sample(p, kFacing, f.raster, 0, side60, f.photo, true, true, evaluation, plain, 0xE);
  EXPECT_EQ(plain.flags, kMixedPixel | kSaturated);  // as sampled: the white texel included
  make_sample(p, kFacing, f.raster, 0, side60, f.photo, true, true, f.settings, none, 0x0);
  EXPECT_EQ(none.flags, kMixedPixel | kSaturated);
  EXPECT_FALSE(is_diffuse_sample(none));
}

TEST(Samples, CleanSamplesArePreferredOverRimOnes) {
  SampleChunk c;
  c.first_vertex = 0;
  c.vertex_count = 2;
  auto s = [](uint16_t flags) { Sample x{}; x.d = 0.8f; x.flags = flags; return x; };
  // vertex 0: 2 clean + 1 rim -> the rim sample is left out; vertex 1: 1 clean + 1 rim -> kept.
  c.samples = {s(0), s(0), s(kRimFootprint), s(0), s(kRimFootprint)};
  c.offsets = {0, 3, 5};
  EXPECT_EQ(prefer_clean_samples(c), 1u);
  EXPECT_TRUE(c.samples[2].flags & kMixedPixel);
  EXPECT_FALSE(c.samples[4].flags & kMixedPixel);
  EXPECT_TRUE(is_diffuse_sample(c.samples[4]));
}
} // namespace
} // namespace vbrdf

TEST(Samples, HalfAngleLobeCosine) {
  Fixture f;
  f.settings.lobe = LobeForm::BlinnNH;
  // L at 60 degrees from N in the x-z plane, E ~ (0, 0, 1): R.E = 0.5, the N-H angle is half the
  // R-E angle (30 degrees): N.H = cos 30 = sqrt((1 + 0.5)/2). kHighlight stays on R.E.
  const LightSource side60 = LightSource::directional({{0.8660254f, 0, 0.5f}});
  const Sample s = f.sample(kOrigin, kFacing, side60);
  EXPECT_NEAR(s.lobe_cos, std::cos(30 * 3.14159265 / 180), 2e-3);
  EXPECT_NEAR(s.lobe_cos, lobe_threshold(LobeForm::BlinnNH, 0.5f), 2e-3);
  EXPECT_EQ(s.flags, 0);
  EXPECT_NEAR(f.sample(kOrigin, kFacing, kFacing).lobe_cos, 1, 1e-6);
  EXPECT_EQ(f.sample(kOrigin, kFacing, kFacing).flags, kHighlight);
  // Out of the plane of incidence the two cosines are not tied: N tilted about x, L about y.
  const float n[3] = {0, 0.3f, 0.9539392f}, l[3] = {0.5f, 0, 0.8660254f}, e[3] = {0, 0, 1};
  const float nh = lobe_cosine(LobeForm::BlinnNH, n, l, e), re = lobe_cosine(LobeForm::PhongRE, n, l, e);
  float h[3] = {l[0] + e[0], l[1] + e[1], l[2] + e[2]};
  const float hl = std::sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
  EXPECT_NEAR(nh, (n[0] * h[0] + n[1] * h[1] + n[2] * h[2]) / hl, 1e-6);
  const float nl = n[0] * l[0] + n[1] * l[1] + n[2] * l[2], ne = n[2];
  EXPECT_NEAR(re, 2 * nl * ne - l[2], 1e-6);
  EXPECT_EQ(lobe_cosine(LobeForm::BlinnNH, kFacing, kFacing, kFacing), 1.0f);
  const float opposite[3] = {0, 0, -1};
  EXPECT_EQ(lobe_cosine(LobeForm::BlinnNH, kFacing, opposite, kFacing), 0.0f);  // H undefined
  LobeForm parsed;
  EXPECT_TRUE(parse_lobe_form("nh", parsed) && parsed == LobeForm::BlinnNH);
  EXPECT_TRUE(parse_lobe_form("ggx", parsed) && parsed == LobeForm::GgxNH);
  EXPECT_TRUE(parse_lobe_form(lobe_form_name(LobeForm::GgxNH), parsed) && parsed == LobeForm::GgxNH);
  EXPECT_TRUE(parse_lobe_form(lobe_form_name(LobeForm::PhongRE), parsed) && parsed == LobeForm::PhongRE);
  EXPECT_FALSE(parse_lobe_form("cook_torrance", parsed));
}

TEST(Samples, ResolutionWeightFollowsDistanceAndObliquity) {
  Fixture f;
  const float n[3] = {0, 0, 1};
  const float near_res = photo_resolution(f.raster, kOrigin, n);
  Raster far = f.raster, oblique = f.raster;
  const float c_far[3] = {0, 0, 20}, c_obl[3] = {0, 8.660254f, 5}, t[3] = {0, 0, 0}, up[3] = {0, 1, 0}, up2[3] = {0, 0, 1};
  far.shot = test::make_look_at_shot(c_far, t, up, 500, 64, 48);
  oblique.shot = test::make_look_at_shot(c_obl, t, up2, 500, 64, 48);
  EXPECT_NEAR(photo_resolution(far, kOrigin, n) / near_res, 0.25, 1e-4);      // twice as far
  EXPECT_NEAR(photo_resolution(oblique, kOrigin, n) / near_res, 0.5, 1e-3);  // N.E = 0.5, same distance
  const float back[3] = {0, 0, -1};
  EXPECT_EQ(photo_resolution(f.raster, kOrigin, back), 0.0f);
  EXPECT_EQ(resolution_code(1.0f), 0);
  EXPECT_EQ(resolution_code(0.5f), 8);
  EXPECT_EQ(resolution_code(0.0f), 63);
  EXPECT_EQ(resolution_code(1e-6f), 63);
  Sample s{};
  s.resolution = 8;
  EXPECT_FLOAT_EQ(resolution_weight(s), 0.5f);
}

TEST(Samples, GatherCodesEachSamplesResolutionAgainstTheVertexsBestPhoto) {
  Fixture f;
  const MeshData mesh = facing_grid(100, 10, -0.2f, -0.2f, 1.0f / 25, 1.0f / 25);
  Raster far = f.raster;
  const float c_far[3] = {0, 0, 20}, t[3] = {0, 0, 0}, up[3] = {0, 1, 0};
  far.shot = test::make_look_at_shot(c_far, t, up, 500, 64, 48);
  const std::vector<Raster> rasters = {f.raster, far, f.raster};
  const std::vector<std::array<float, 3>> lights = {{{0, 0, 1}}, {{0, 0, 1}}, {{0.5f, 0, 0.8660254f}}};
  const VisibilityMasks masks = all_seen(100, 3);
  PhotoCache cache(PhotoEncoding::Auto, 0.99f, 1 << 20);
  for (bool weights : {true, false}) {
    GatherSettings settings = vbrdf::test::thesis_gather_settings();
    settings.resolution_weights = weights;
    int checked = 0;
    gather_samples(mesh.view(), rasters, directional_lights(lights), masks, settings, cache, [&](const SampleChunk &c) {
      for (uint32_t k = 0; k < c.samples.size(); ++k, ++checked) {
        const Sample &s = c.samples[k];
        if (!weights || s.raster != 1) EXPECT_EQ(s.resolution, 0) << "raster " << s.raster;
        else EXPECT_NEAR(s.resolution, 16, 1) << "twice as far: a quarter of the pixels";
      }
    });
    EXPECT_EQ(checked, 300);
  }
}

// A coat map (DiffuseForms per vertex): each vertex's samples carry its own form's diffuse factor.
TEST(Samples, GatherTakesEachVertexsDiffuseForm) {
  Fixture f;
  const MeshData mesh = facing_grid(100, 10, -0.2f, -0.2f, 1.0f / 25, 1.0f / 25);
  const std::vector<Raster> rasters = {f.raster};
  const std::vector<std::array<float, 3>> lights = {{{0.8f, 0, 0.6f}}};  // N.L = 0.6
  const VisibilityMasks masks = all_seen(100, 1);
  PhotoCache cache(PhotoEncoding::Auto, 0.99f, 1 << 20);
  auto coated = std::make_shared<std::vector<uint8_t>>(100, 0);
  for (size_t v = 0; v < 100; v += 3) (*coated)[v] = 1;
  GatherSettings settings = vbrdf::test::thesis_gather_settings();
  settings.diffuse = DiffuseForms{DiffuseForm::Lambert, coated};
  int checked = 0;
  gather_samples(mesh.view(), rasters, directional_lights(lights), masks, settings, cache, [&](const SampleChunk &c) {
    for (uint32_t i = 0; i < c.vertex_count; ++i)
      for (uint32_t k = c.offsets[i]; k < c.offsets[i + 1]; ++k, ++checked) {
        const size_t v = c.first_vertex + i;
        const float *p = mesh.positions.data() + 3 * v;
        const float e_len = std::sqrt(p[0] * p[0] + p[1] * p[1] + 100.0f), ne = 10.0f / e_len;  // camera at z = 10
        EXPECT_NEAR(c.samples[k].d, diffuse_factor((*coated)[v] ? DiffuseForm::Coated : DiffuseForm::Lambert, 0.6f, ne),
                    1e-5) << "vertex " << v;
      }
  });
  EXPECT_EQ(checked, 100);
}

// shaders/reflectance_fit.comp reads a sample's last word as raster | flags << 16 | resolution << 26.
TEST(Samples, SampleWordMatchesTheShader) {
  Sample s{};
  s.raster = 0x1234;
  s.flags = kHighlight | kMixedPixel | kRimFootprint;
  s.resolution = 0x2A;
  uint32_t word = 0;
  std::memcpy(&word, reinterpret_cast<const char *>(&s) + 20, 4);
  EXPECT_EQ(word, 0x1234u | uint32_t(kHighlight | kMixedPixel | kRimFootprint) << 16 | 0x2Au << 26);
}

// The GGX lobe (lobe.h lobe_value): 1 at the peak, falling with the angle, the GGX distribution
// D(N.H)/D(1) of roughness a with a^2 = 2 / (alpha + 2), heavier-tailed than (N.H)^alpha of the same
// exponent; its derivative in ln alpha is the fits' Newton step, checked by finite differences.
TEST(Lobe, GgxValueAndDerivative) {
  for (double alpha : {1.0, 20.0, 300.0, 2000.0}) {
    EXPECT_DOUBLE_EQ(lobe_value(LobeForm::GgxNH, 1.0, alpha), 1.0);
    EXPECT_DOUBLE_EQ(lobe_value(LobeForm::GgxNH, 1.5, alpha), 1.0);  // clamped at 1
    EXPECT_EQ(lobe_value(LobeForm::GgxNH, 0.0, alpha), 0.0);
    EXPECT_EQ(lobe_value(LobeForm::GgxNH, -0.3, alpha), 0.0);
    double previous = 1.0;
    for (double s = 0.999; s > 0.05; s -= 0.05) {
      const double g = lobe_value(LobeForm::GgxNH, s, alpha);
      EXPECT_LT(g, previous) << s;
      EXPECT_GT(g, 0.0) << s;
      previous = g;
      const double h = 1e-6, t = std::log(alpha);
      const double fd = (lobe_value(LobeForm::GgxNH, s, std::exp(t + h)) - lobe_value(LobeForm::GgxNH, s, std::exp(t - h))) / (2 * h);
      EXPECT_NEAR(lobe_dvalue_dlog_alpha(LobeForm::GgxNH, s, alpha), fd, 1e-6 + 1e-5 * std::fabs(fd)) << s << " " << alpha;
      const double fd_pow = (lobe_value(LobeForm::BlinnNH, s, std::exp(t + h)) - lobe_value(LobeForm::BlinnNH, s, std::exp(t - h))) / (2 * h);
      EXPECT_NEAR(lobe_dvalue_dlog_alpha(LobeForm::BlinnNH, s, alpha), fd_pow, 1e-6 + 1e-5 * std::fabs(fd_pow));
    }
  }
  // GGX D by its textbook formula: a^2 / (pi ((a^2 - 1) c^2 + 1)^2), over D(1) = 1 / (pi a^2).
  const double alpha = 86.9, a2 = 2 / (alpha + 2), c = 0.97;
  const double d = a2 / ((a2 - 1) * c * c + 1) / ((a2 - 1) * c * c + 1);
  EXPECT_NEAR(lobe_value(LobeForm::GgxNH, c, alpha), d * a2, 1e-12);
  // The tail: 45 degrees off the peak, GGX keeps far more than the power law of the same exponent
  // (which is the broader of the two near the peak: its curvature there is half GGX's).
  const double s45 = std::cos(45 * 3.14159265358979 / 180), s5 = std::cos(5 * 3.14159265358979 / 180);
  EXPECT_GT(lobe_value(LobeForm::GgxNH, s45, alpha), 1e6 * lobe_value(LobeForm::BlinnNH, s45, alpha));
  EXPECT_LT(lobe_value(LobeForm::GgxNH, s5, alpha), lobe_value(LobeForm::BlinnNH, s5, alpha));
}
