// Photo decoding: sRGB EOTF, 8/16-bit handling, bilinear sampling, saturation.
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <fstream>
#include <thread>
#include <vector>

#include "base/errors.h"
#include "inputs/photo.h"
#include "inputs/photo_prefetch.h"
#include "test_paths.h"

using namespace vbrdf;

TEST(Srgb, MatchesStandardAndRoundTrips) {
  EXPECT_FLOAT_EQ(srgb_to_linear(0), 0);
  EXPECT_FLOAT_EQ(srgb_to_linear(1), 1);
  EXPECT_NEAR(srgb_to_linear(0.5f), 0.214041f, 1e-5);     // IEC 61966-2-1
  EXPECT_NEAR(srgb_to_linear(0.04f), 0.04f / 12.92f, 1e-7);  // linear toe
  for (float v = 0; v <= 1; v += 0.01f) EXPECT_NEAR(linear_to_srgb(srgb_to_linear(v)), v, 1e-5);
  EXPECT_EQ(linear_to_srgb(std::nanf("")), 0);
  EXPECT_EQ(linear_to_srgb(7), 1);
}

namespace {
std::string write_png(const cv::Mat &bgr, const std::string &name) {
  const std::string path = test::scratch_dir("photo") + "/" + name;
  cv::imwrite(path, bgr);
  return path;
}
} // namespace

TEST(Photo, EightBitIsSrgbAndSixteenBitIsLinearByDefault) {
  cv::Mat img8(4, 4, CV_8UC3, cv::Scalar(64, 128, 255));  // BGR
  const Photo p8 = load_photo(write_png(img8, "a.png"), PhotoEncoding::Auto);
  PixelSample s = sample_bilinear(p8, 2.0f, 2.0f);
  ASSERT_TRUE(s.inside);
  EXPECT_NEAR(s.rgb[0], 1.0f, 1e-6);  // R = 255
  EXPECT_NEAR(s.rgb[1], srgb_to_linear(128 / 255.0f), 1e-6);
  EXPECT_NEAR(s.rgb[2], srgb_to_linear(64 / 255.0f), 1e-6);
  EXPECT_TRUE(s.saturated);  // R is clipped

  cv::Mat img16(4, 4, CV_16UC3, cv::Scalar(1000, 30000, 65535));
  const Photo p16 = load_photo(write_png(img16, "b.png"), PhotoEncoding::Auto);
  s = sample_bilinear(p16, 2.0f, 2.0f);
  EXPECT_NEAR(s.rgb[1], 30000 / 65535.0f, 1e-6);
  EXPECT_NEAR(s.rgb[2], 1000 / 65535.0f, 1e-6);
  EXPECT_TRUE(s.saturated);
  // Forcing sRGB on an 8-bit photo that is really linear changes the values.
  const Photo lin8 = load_photo(write_png(img8, "c.png"), PhotoEncoding::Linear);
  EXPECT_NEAR(sample_bilinear(lin8, 2, 2).rgb[1], 128 / 255.0f, 1e-6);
}

TEST(Photo, BilinearUsesPixelCentresAndRepeatsBorders) {
  cv::Mat img(2, 3, CV_16UC3, cv::Scalar(0, 0, 0));
  img.at<cv::Vec3w>(0, 0) = cv::Vec3w(0, 0, 10000);  // R of top-left pixel
  img.at<cv::Vec3w>(0, 1) = cv::Vec3w(0, 0, 30000);
  const Photo p = load_photo(write_png(img, "d.png"), PhotoEncoding::Linear);
  // Halfway between the centres of pixels (0,0) and (1,0) on the top row.
  PixelSample s = sample_bilinear(p, 1.0f, 0.5f);
  ASSERT_TRUE(s.inside);
  EXPECT_NEAR(s.rgb[0], 20000 / 65535.0f, 1e-6);
  EXPECT_FALSE(s.saturated);
  // On the image but beyond the border pixels' centres: the border pixel is repeated (an object
  // touching the frame keeps its outermost pixels).
  s = sample_bilinear(p, 0.2f, 0.5f);
  ASSERT_TRUE(s.inside);
  EXPECT_NEAR(s.rgb[0], 10000 / 65535.0f, 1e-6);
  s = sample_bilinear(p, 2.8f, 1.0f);  // right column (black), halfway between the rows
  ASSERT_TRUE(s.inside);
  EXPECT_NEAR(s.rgb[0], 0.0f, 1e-6);
  s = sample_bilinear(p, 1.5f, 0.2f);  // top row, pixel (1,0)'s centre column
  ASSERT_TRUE(s.inside);
  EXPECT_NEAR(s.rgb[0], 30000 / 65535.0f, 1e-6);
  EXPECT_FALSE(sample_bilinear(p, -0.1f, 0.5f).inside);  // off the image
  EXPECT_FALSE(sample_bilinear(p, 3.0f, 1.0f).inside);
  EXPECT_FALSE(sample_bilinear(p, 1.0f, 2.0f).inside);
  EXPECT_FALSE(sample_bilinear(p, std::nanf(""), 1.0f).inside);
}

TEST(Photo, BadFilesGiveClearErrors) {
  try {
    load_photo("/nonexistent/x.png", PhotoEncoding::Auto);
    FAIL();
  } catch (const InputError &e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/x.png"), std::string::npos);
  }
  cv::Mat img(4, 6, CV_8UC3, cv::Scalar(1, 2, 3));
  const std::string path = write_png(img, "size.png");
  try {
    load_photo(path, PhotoEncoding::Auto, 0.99f, 640, 480);
    FAIL();
  } catch (const InputError &e) {
    EXPECT_NE(std::string(e.what()).find("6x4"), std::string::npos) << e.what();
  }
}

TEST(PhotoCache, StaysUnderBudgetAndReloads) {
  cv::Mat img(100, 100, CV_8UC3, cv::Scalar(1, 2, 3));
  const std::string a = write_png(img, "ca.png"), b = write_png(img, "cb.png");
  PhotoCache cache(PhotoEncoding::Auto, 0.99f, 40000);  // room for one 30 kB photo + LUT
  cache.get(a);
  cache.get(a);
  EXPECT_EQ(cache.loads(), 1u);
  cache.get(b);
  cache.get(a);
  EXPECT_EQ(cache.loads(), 3u);
}

// Several threads asking for one photo decode it once, and every one gets it.
TEST(PhotoCache, DecodesAPhotoOnceForConcurrentRequests) {
  cv::Mat img(300, 400, CV_8UC3, cv::Scalar(10, 20, 30));
  const std::string a = write_png(img, "concurrent.png");
  PhotoCache cache(PhotoEncoding::Auto, 0.99f, size_t(64) << 20);
  std::vector<std::shared_ptr<const Photo>> got(6);
  std::vector<std::thread> threads;
  for (size_t i = 0; i < got.size(); ++i) threads.emplace_back([&, i] { got[i] = cache.get(a, 400, 300); });
  for (std::thread &t : threads) t.join();
  EXPECT_EQ(cache.loads(), 1u);
  for (const auto &p : got) EXPECT_EQ(p.get(), got[0].get());
}

// The prefetch decodes every photo of a project once, in the background: the gathering's later
// requests find them (no second decode). A photo that cannot be decoded is reported by finish(),
// naming it, after the good ones were decoded.
TEST(PhotoPrefetch, DecodesEachPhotoOnceAndReportsTheBadOne) {
  cv::Mat img(60, 80, CV_8UC3, cv::Scalar(1, 2, 3));
  std::vector<Raster> rasters(5);
  for (size_t i = 0; i < rasters.size(); ++i) {
    rasters[i].image_path = write_png(img, "prefetch" + std::to_string(i) + ".png");
    rasters[i].shot.Intrinsics.ViewportPx = vcg::Point2i(80, 60);
  }
  {
    PhotoCache cache(PhotoEncoding::Auto, 0.99f, size_t(64) << 20);
    auto prefetch = start_photo_prefetch(cache, rasters);
    prefetch->finish();
    EXPECT_EQ(cache.loads(), rasters.size());
    for (const Raster &r : rasters) cache.get(r.image_path, 80, 60);
    EXPECT_EQ(cache.loads(), rasters.size());
  }
  const std::string broken = test::scratch_dir("photo") + "/prefetch_broken.png";
  std::ofstream(broken) << "not a png";
  rasters[3].image_path = broken;
  PhotoCache cache(PhotoEncoding::Auto, 0.99f, size_t(64) << 20);
  auto prefetch = start_photo_prefetch(cache, rasters);
  try {
    prefetch->finish();
    ADD_FAILURE() << "the broken photo was not reported";
  } catch (const InputError &e) {
    EXPECT_NE(std::string(e.what()).find("prefetch_broken.png"), std::string::npos) << e.what();
  }
  EXPECT_EQ(cache.loads(), rasters.size() - 1);
}

// Prefetching never decodes more than the cache's budget holds (a photo decoded and evicted before
// use would be decoded twice); the rest decode on demand.
TEST(PhotoPrefetch, StopsAtTheCacheBudget) {
  cv::Mat img(100, 100, CV_8UC3, cv::Scalar(1, 2, 3));  // 30 kB decoded (+ LUT)
  std::vector<Raster> rasters(8);
  for (size_t i = 0; i < rasters.size(); ++i) {
    rasters[i].image_path = write_png(img, "budget" + std::to_string(i) + ".png");
    rasters[i].shot.Intrinsics.ViewportPx = vcg::Point2i(100, 100);
  }
  PhotoCache cache(PhotoEncoding::Auto, 0.99f, 100000);  // room for three
  start_photo_prefetch(cache, rasters)->finish();
  EXPECT_GE(cache.loads(), 1u);
  EXPECT_LE(cache.loads(), 3u);
}

namespace vbrdf {
namespace {
// A footprint mask keeps only some texels (the vertex's own surface at a silhouette): the sample
// is their renormalised bilinear mix; saturation elsewhere in the footprint does not count.
TEST(Photo, MaskedBilinearUsesOnlyTheKeptTexels) {
  cv::Mat img(2, 2, CV_16UC3, cv::Scalar(0, 0, 0));
  img.at<cv::Vec3w>(0, 0) = cv::Vec3w(0, 0, 10000);  // R: texel bit 0 (top-left)
  img.at<cv::Vec3w>(0, 1) = cv::Vec3w(0, 0, 30000);  // bit 1 (top-right)
  img.at<cv::Vec3w>(1, 0) = cv::Vec3w(0, 0, 50000);  // bit 2 (bottom-left)
  img.at<cv::Vec3w>(1, 1) = cv::Vec3w(65535, 65535, 65535);  // bit 3: clipped
  const std::string path = (std::string(::testing::TempDir()) + "masked.png");
  ASSERT_TRUE(cv::imwrite(path, img));
  const Photo p = load_photo(path, PhotoEncoding::Linear);
  // At (0.75, 0.75) the bilinear weights are 0.5625, 0.1875, 0.1875, 0.0625.
  PixelSample all = sample_bilinear(p, 0.75f, 0.75f);
  EXPECT_TRUE(all.saturated);
  PixelSample top = sample_bilinear(p, 0.75f, 0.75f, 0x3);  // texels 0 and 1: weights 0.75 : 0.25
  ASSERT_TRUE(top.inside);
  EXPECT_FALSE(top.saturated);
  EXPECT_NEAR(top.rgb[0], (0.75f * 10000 + 0.25f * 30000) / 65535.0f, 1e-5);
  PixelSample left = sample_bilinear(p, 0.75f, 0.75f, 0x5);  // texels 0 and 2
  EXPECT_NEAR(left.rgb[0], (0.75f * 10000 + 0.25f * 50000) / 65535.0f, 1e-5);
  // A kept texel with (almost) no bilinear weight: the kept texels are averaged instead.
  PixelSample far = sample_bilinear(p, 0.5f, 0.5f, 0x2);  // exactly on texel 0's centre
  EXPECT_NEAR(far.rgb[0], 30000 / 65535.0f, 1e-5);
  EXPECT_FALSE(sample_bilinear(p, 0.75f, 0.75f, 0).inside);  // nothing kept: no sample
}
} // namespace
} // namespace vbrdf
