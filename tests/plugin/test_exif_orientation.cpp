// EXIF orientation: MeshLab 2020.09 loads a raster's photo with QImage(path)
// (src/common/meshmodel.cpp, Plane::Plane), and Qt 5's QImageReader does not apply the EXIF
// orientation by default (autoTransform() is false), so MeshLab shows and registers the photo as
// its pixels are stored. The fit must read the same pixels: OpenCV's IMREAD_UNCHANGED (load_photo)
// ignores the orientation too. This test checks the two loaders against each other on a JPEG
// tagged "rotate 90" (orientation 6) and against the untagged file.
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <QImage>
#include <QImageReader>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "core/inputs/photo.h"

namespace {

// The JPEG with an EXIF APP1 segment (little-endian TIFF, one IFD entry: Orientation) after SOI.
std::vector<char> with_orientation(const std::vector<char> &jpeg, uint16_t orientation) {
  const unsigned char ifd[] = {'E', 'x', 'i', 'f', 0, 0, 'I', 'I', 42, 0, 8, 0, 0, 0,  // header, IFD at 8
                               1, 0,                                                 // one entry
                               0x12, 0x01, 3, 0, 1, 0, 0, 0,                         // 0x0112 SHORT x1
                               uint8_t(orientation & 0xFF), uint8_t(orientation >> 8), 0, 0,
                               0, 0, 0, 0};                                          // no next IFD
  const uint16_t length = uint16_t(sizeof ifd + 2);
  std::vector<char> out(jpeg.begin(), jpeg.begin() + 2);
  const char marker[] = {char(0xFF), char(0xE1), char(length >> 8), char(length & 0xFF)};
  out.insert(out.end(), marker, marker + 4);
  out.insert(out.end(), reinterpret_cast<const char *>(ifd), reinterpret_cast<const char *>(ifd) + sizeof ifd);
  out.insert(out.end(), jpeg.begin() + 2, jpeg.end());
  return out;
}

std::string scratch(const std::string &name) {
  return std::string(VBRDF_PLUGIN_TEST_SCRATCH) + "/" + name;
}

} // namespace

TEST(ExifOrientation, FitReadsThePixelsMeshLabShows) {
  // A landscape 64x32 photo, left half dark, right half bright: a rotation would show.
  cv::Mat bgr(32, 64, CV_8UC3, cv::Scalar(20, 20, 20));
  bgr(cv::Rect(32, 0, 32, 32)).setTo(cv::Scalar(230, 230, 230));
  const std::string plain = scratch("exif_plain.jpg"), rotated = scratch("exif_rotate90.jpg");
  ASSERT_TRUE(cv::imwrite(plain, bgr));
  std::ifstream in(plain, std::ios::binary);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::vector<char> tagged = with_orientation(bytes, 6);
  std::ofstream(rotated, std::ios::binary).write(tagged.data(), std::streamsize(tagged.size()));

  // The tag is really there: a loader that honours it (OpenCV's IMREAD_COLOR) turns the photo.
  ASSERT_EQ(cv::imread(rotated, cv::IMREAD_COLOR).cols, 32);

  // MeshLab's loader: the stored pixels, as without the tag.
  const QImage shown(QString::fromStdString(rotated));
  ASSERT_FALSE(shown.isNull());
  EXPECT_FALSE(QImageReader(QString::fromStdString(rotated)).autoTransform());
  EXPECT_EQ(shown.width(), 64);
  EXPECT_EQ(shown.height(), 32);

  // The fit's loader agrees with MeshLab's, pixel by pixel (same decoder output, no rotation).
  const vbrdf::Photo photo = vbrdf::load_photo(rotated, vbrdf::PhotoEncoding::Auto);
  ASSERT_EQ(photo.width(), shown.width());
  ASSERT_EQ(photo.height(), shown.height());
  for (int y = 0; y < 32; y += 5)
    for (int x = 0; x < 64; x += 7) {
      const QRgb q = shown.pixel(x, y);
      const cv::Vec3b p(photo.code<uint8_t>(x, y, 0), photo.code<uint8_t>(x, y, 1), photo.code<uint8_t>(x, y, 2));  // RGB
      EXPECT_NEAR(int(p[0]), qRed(q), 2) << x << "," << y;
      EXPECT_NEAR(int(p[2]), qBlue(q), 2) << x << "," << y;
    }
  EXPECT_LT(int(photo.code<uint8_t>(4, 16, 0)), 60);    // left stays dark
  EXPECT_GT(int(photo.code<uint8_t>(60, 16, 0)), 200);  // right stays bright
}
