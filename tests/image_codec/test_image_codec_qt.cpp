// image_codec_qt.cpp decodes as cv::imread(path, IMREAD_UNCHANGED) does: the fit reads the same
// codes in the PyMeshLab build as in the 2020.09 build.
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "inputs/image_codec.h"

namespace {

std::string scratch(const std::string &name) { return std::string(VBRDF_CODEC_TEST_SCRATCH) + "/" + name; }

// A test pattern of the given depth and channels with distinct codes in every channel.
cv::Mat pattern(int depth, int channels) {
  cv::Mat image(37, 53, CV_MAKETYPE(depth, channels));
  const double top = depth == CV_16U ? 65535.0 : 255.0;
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x)
      for (int c = 0; c < channels; ++c) {
        const double v = std::fmod(0.013 * (x * 7 + y * 11 + c * 101) * top, top);
        if (depth == CV_16U) image.ptr<uint16_t>(y)[x * channels + c] = uint16_t(v);
        else image.ptr<uint8_t>(y)[x * channels + c] = uint8_t(v);
      }
  return image;
}

void expect_same(const cv::Mat &a, const cv::Mat &b) {
  ASSERT_EQ(a.type(), b.type());
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
}

struct Case { const char *name; int depth; int channels; };

class ImageCodecQt : public ::testing::TestWithParam<Case> {};

TEST_P(ImageCodecQt, DecodesAsOpenCvDoes) {
  const Case c = GetParam();
  const std::string path = scratch(std::string(c.name) + ".png");
  ASSERT_TRUE(cv::imwrite(path, pattern(c.depth, c.channels)));
  expect_same(vbrdf::read_image_unchanged(path), cv::imread(path, cv::IMREAD_UNCHANGED));
}

INSTANTIATE_TEST_SUITE_P(Png, ImageCodecQt,
                         ::testing::Values(Case{"rgb8", CV_8U, 3}, Case{"rgba8", CV_8U, 4}, Case{"grey8", CV_8U, 1},
                                           Case{"rgb16", CV_16U, 3}, Case{"rgba16", CV_16U, 4},
                                           Case{"grey16", CV_16U, 1}),
                         [](const ::testing::TestParamInfo<Case> &info) { return std::string(info.param.name); });

TEST(ImageCodecQtMissing, AnUnreadableFileGivesAnEmptyImage) {
  EXPECT_TRUE(vbrdf::read_image_unchanged(scratch("no_such_file.png")).empty());
}

TEST(ImageCodecQtPng, EncodedPngDecodesToTheSamePixels) {
  for (int channels : {1, 3, 4}) {
    const cv::Mat image = pattern(CV_8U, channels);
    std::vector<uint8_t> bytes;
    ASSERT_TRUE(vbrdf::encode_png(image, bytes));
    const cv::Mat decoded = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);  // RGBA
    cv::Mat expected;
    if (channels == 1) cv::cvtColor(image, expected, cv::COLOR_GRAY2BGRA);
    else if (channels == 3) cv::cvtColor(image, expected, cv::COLOR_BGR2BGRA);
    else expected = image;
    expect_same(decoded, expected);
  }
}

} // namespace
