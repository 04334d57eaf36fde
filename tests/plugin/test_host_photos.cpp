// Photos read in place from MeshLab's decoded images, so that each photo is decoded once. For every
// layout Qt gives the photo formats the fit accepts (8-bit RGB/RGBA/grey PNG, JPEG, 16-bit RGB and
// grey PNG), the wrapped QImage must decode to exactly what the fit's own decoder (OpenCV) makes of
// the same file: the same samples, the same linear image, the same content fingerprint. And a
// cache given the images must not read the files at all.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include <QImage>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "core/base/errors.h"
#include "core/inputs/photo.h"
#include "core/inputs/photo_content.h"
#include "host_photos.h"

namespace {

std::string scratch(const std::string &name) { return std::string(VBRDF_PLUGIN_TEST_SCRATCH) + "/" + name; }

// A test image with distinct R, G and B everywhere (a swapped channel shows), some clipped pixels.
cv::Mat pattern(int depth, int channels) {
  const double max = depth == CV_16U ? 65535.0 : 255.0;
  cv::Mat m(37, 53, CV_MAKETYPE(depth, channels));
  for (int y = 0; y < m.rows; ++y)
    for (int x = 0; x < m.cols; ++x)
      for (int c = 0; c < channels; ++c) {
        const double v = c == 3 ? 1.0 : std::fmod(0.13 * (c + 1) + 0.011 * x * (c + 2) + 0.017 * y * (3 - c), 1.0);
        const double code = (x == 7 && y == 9) ? max : v * max;
        if (depth == CV_16U) m.ptr<uint16_t>(y)[channels * x + c] = uint16_t(code);
        else m.ptr<uint8_t>(y)[channels * x + c] = uint8_t(code);
      }
  return m;
}

struct Case {
  const char *name;
  int depth, channels;
  const char *ext;
};

// Largest difference between the two photos' samples over a grid of sub-pixel positions.
float largest_sample_difference(const vbrdf::Photo &a, const vbrdf::Photo &b) {
  float worst = 0;
  for (float y = 0.6f; y < float(a.height()) - 0.6f; y += 0.77f)
    for (float x = 0.6f; x < float(a.width()) - 0.6f; x += 0.93f) {
      const vbrdf::PixelSample sa = vbrdf::sample_bilinear(a, x, y), sb = vbrdf::sample_bilinear(b, x, y);
      EXPECT_EQ(sa.saturated, sb.saturated) << x << "," << y;
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(sa.rgb[c] - sb.rgb[c]));
    }
  return worst;
}

} // namespace

TEST(HostPhotos, MeshLabsImagesDecodeAsTheFitsOwnDecoder) {
  const Case cases[] = {{"rgb8", CV_8U, 3, ".png"}, {"rgba8", CV_8U, 4, ".png"}, {"grey8", CV_8U, 1, ".png"},
                        {"jpeg", CV_8U, 3, ".jpg"}, {"rgb16", CV_16U, 3, ".png"}, {"grey16", CV_16U, 1, ".png"}};
  for (const Case &k : cases) {
    SCOPED_TRACE(k.name);
    const std::string path = scratch(std::string("host_") + k.name + k.ext);
    ASSERT_TRUE(cv::imwrite(path, pattern(k.depth, k.channels)));
    const QImage image(QString::fromStdString(path));  // as MeshLab loads a raster's photo
    ASSERT_FALSE(image.isNull());
    vbrdf::HostPixels host;
    ASSERT_TRUE(vbrdf_plugin::host_pixels_of(image, host)) << "QImage format " << int(image.format());
    EXPECT_EQ(host.pixels.data, image.constBits());  // read in place, not copied

    for (vbrdf::PhotoEncoding encoding : {vbrdf::PhotoEncoding::Auto, vbrdf::PhotoEncoding::Linear}) {
      const vbrdf::Photo own = vbrdf::load_photo(path, encoding, 0.99f, 53, 37);
      const vbrdf::Photo wrapped = vbrdf::photo_from_host(path, host, encoding, 0.99f, 53, 37);
      EXPECT_EQ(wrapped.linear, own.linear);
      EXPECT_EQ(largest_sample_difference(own, wrapped), 0.0f);
      cv::Mat clip_own, clip_wrapped;
      const cv::Mat lin_own = vbrdf::photo_linear_rgb(own, &clip_own);
      const cv::Mat lin_wrapped = vbrdf::photo_linear_rgb(wrapped, &clip_wrapped);
      EXPECT_EQ(cv::norm(lin_own, lin_wrapped, cv::NORM_INF), 0.0);
      EXPECT_EQ(cv::countNonZero(clip_own != clip_wrapped), 0);
      EXPECT_GT(cv::countNonZero(clip_own), 0);  // the clipped pixel is seen by both
      EXPECT_EQ(vbrdf::analyse_photo(own).fingerprint, vbrdf::analyse_photo(wrapped).fingerprint);
    }
    if (k.channels >= 3) {  // control: the same pixels read with R and B swapped must differ
      vbrdf::HostPixels swapped = host;
      std::swap(swapped.rgb[0], swapped.rgb[2]);
      const vbrdf::Photo own = vbrdf::load_photo(path, vbrdf::PhotoEncoding::Auto);
      EXPECT_GT(largest_sample_difference(own, vbrdf::photo_from_host(path, swapped, vbrdf::PhotoEncoding::Auto)), 0.05f);
    }
  }
}

TEST(HostPhotos, OnlyFormatsQtDecodesAtTheirOwnDepthAreTaken) {
  // PNG (Qt >= 5.12 keeps 16-bit) and JPEG (8-bit only) by their signature, whatever the name;
  // TIFF and the rest are decoded by the core (a Qt plugin might reduce 16-bit TIFFs to 8 bits).
  const std::string png = scratch("sig.tif"), jpeg = scratch("sig_jpeg.png"), tiff = scratch("sig.tiff");
  ASSERT_TRUE(cv::imwrite(scratch("sig_tmp.png"), pattern(CV_16U, 3)));
  ASSERT_EQ(std::rename(scratch("sig_tmp.png").c_str(), png.c_str()), 0);  // a PNG named .tif
  ASSERT_TRUE(cv::imwrite(scratch("sig_tmp.jpg"), pattern(CV_8U, 3)));
  ASSERT_EQ(std::rename(scratch("sig_tmp.jpg").c_str(), jpeg.c_str()), 0);
  ASSERT_TRUE(cv::imwrite(tiff, pattern(CV_16U, 3)));
  EXPECT_TRUE(vbrdf_plugin::qt_keeps_the_photos_depth(png));
  EXPECT_TRUE(vbrdf_plugin::qt_keeps_the_photos_depth(jpeg));
  EXPECT_FALSE(vbrdf_plugin::qt_keeps_the_photos_depth(tiff));
  EXPECT_FALSE(vbrdf_plugin::qt_keeps_the_photos_depth(scratch("missing.png")));
}

TEST(HostPhotos, ACacheGivenTheImagesReadsNoFile) {
  const std::string path = scratch("host_cache.png");
  ASSERT_TRUE(cv::imwrite(path, pattern(CV_8U, 3)));
  auto photos = std::make_shared<vbrdf::HostPhotos>();
  {
    const QImage image(QString::fromStdString(path));
    ASSERT_TRUE(vbrdf_plugin::host_pixels_of(image, (*photos)[path]));
  }  // the QImage goes out of scope here: the wrapper keeps its pixels alive
  const vbrdf::Photo own = vbrdf::load_photo(path, vbrdf::PhotoEncoding::Auto);
  ASSERT_EQ(std::remove(path.c_str()), 0);  // no file to decode any more

  vbrdf::PhotoCache cache(vbrdf::PhotoEncoding::Auto, 0.99f, 1 << 20, photos);
  const auto first = cache.get(path, 53, 37);
  const auto again = cache.get(path, 53, 37);
  EXPECT_EQ(first, again);
  EXPECT_EQ(cache.loads(), 0u);
  EXPECT_EQ(cache.host_reads(), 1u);
  EXPECT_EQ(largest_sample_difference(own, *first), 0.0f);
  // A size that does not match the raster's camera is refused as for a decoded file.
  vbrdf::PhotoCache strict(vbrdf::PhotoEncoding::Auto, 0.99f, 1 << 20, photos);
  EXPECT_THROW(strict.get(path, 64, 48), vbrdf::InputError);
  // A path the host did not decode is read from its file (missing here: the usual message).
  EXPECT_THROW(cache.get(scratch("not_in_host.png")), vbrdf::InputError);
}
