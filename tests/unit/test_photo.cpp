// Photo decoding: sRGB EOTF, 8/16-bit handling, bilinear sampling, saturation.
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "base/errors.h"
#include "inputs/photo.h"
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

TEST(Photo, BilinearUsesPixelCentresAndDetectsBorders) {
  cv::Mat img(2, 3, CV_16UC3, cv::Scalar(0, 0, 0));
  img.at<cv::Vec3w>(0, 0) = cv::Vec3w(0, 0, 10000);  // R of top-left pixel
  img.at<cv::Vec3w>(0, 1) = cv::Vec3w(0, 0, 30000);
  const Photo p = load_photo(write_png(img, "d.png"), PhotoEncoding::Linear);
  // Halfway between the centres of pixels (0,0) and (1,0) on the top row.
  PixelSample s = sample_bilinear(p, 1.0f, 0.5f);
  ASSERT_TRUE(s.inside);
  EXPECT_NEAR(s.rgb[0], 20000 / 65535.0f, 1e-6);
  EXPECT_FALSE(s.saturated);
  EXPECT_FALSE(sample_bilinear(p, 0.2f, 0.5f).inside);   // footprint leaves the image
  EXPECT_FALSE(sample_bilinear(p, 2.8f, 1.0f).inside);
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
