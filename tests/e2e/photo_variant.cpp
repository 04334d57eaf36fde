// vbrdf_photo_variant MODE IN OUT [IN OUT ...]: writes a variant of each photo IN (8-bit sRGB RGB
// PNG) for the bad-input corpus (run_e2e.py bad): the formats and contents real captures produce.
//   grey8 grey16   one channel, 8-bit sRGB / 16-bit linear PNG
//   rgba           8-bit with an opaque alpha channel (PNG)
//   jpeg           8-bit JPEG (quality 95)
//   cmyk_jpeg      Adobe CMYK JPEG (inverted CMYK, as Photoshop writes it) through libjpeg
//   tiff16         16-bit linear RGB TIFF
//   half           half the width and height (a photo of the wrong size)
//   big            5x the width and height (larger than a small photo memory)
//   black white    the same size, every pixel 0 / 255
#include <cmath>
#include <cstdio>
#include <jpeglib.h>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace {

cv::Mat to_linear16(const cv::Mat &srgb8) {
  cv::Mat out(srgb8.size(), CV_MAKETYPE(CV_16U, srgb8.channels()));
  const uint8_t *in = srgb8.ptr<uint8_t>();
  uint16_t *o = out.ptr<uint16_t>();
  for (size_t i = 0; i < srgb8.total() * size_t(srgb8.channels()); ++i) {
    const double c = in[i] / 255.0;
    const double lin = c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
    o[i] = uint16_t(std::lround(lin * 65535.0));
  }
  return out;
}

bool write_cmyk_jpeg(const cv::Mat &bgr, const std::string &path) {
  std::FILE *f = std::fopen(path.c_str(), "wb");
  if (!f) return false;
  jpeg_compress_struct c;
  jpeg_error_mgr err;
  c.err = jpeg_std_error(&err);
  jpeg_create_compress(&c);
  jpeg_stdio_dest(&c, f);
  c.image_width = JDIMENSION(bgr.cols);
  c.image_height = JDIMENSION(bgr.rows);
  c.input_components = 4;
  c.in_color_space = JCS_CMYK;
  jpeg_set_defaults(&c);
  jpeg_set_quality(&c, 95, TRUE);
  jpeg_start_compress(&c, TRUE);
  std::vector<JSAMPLE> row(size_t(bgr.cols) * 4);
  while (c.next_scanline < c.image_height) {
    const uint8_t *px = bgr.ptr<uint8_t>(int(c.next_scanline));
    for (int x = 0; x < bgr.cols; ++x) {
      const int b = px[3 * x], g = px[3 * x + 1], r = px[3 * x + 2];
      const int k = 255 - std::max(r, std::max(g, b));
      const int cc = k == 255 ? 0 : (255 - r - k) * 255 / (255 - k);
      const int m = k == 255 ? 0 : (255 - g - k) * 255 / (255 - k);
      const int y = k == 255 ? 0 : (255 - b - k) * 255 / (255 - k);
      // Adobe files store inverted CMYK.
      row[4 * size_t(x)] = JSAMPLE(255 - cc), row[4 * size_t(x) + 1] = JSAMPLE(255 - m);
      row[4 * size_t(x) + 2] = JSAMPLE(255 - y), row[4 * size_t(x) + 3] = JSAMPLE(255 - k);
    }
    JSAMPROW rows[1] = {row.data()};
    jpeg_write_scanlines(&c, rows, 1);
  }
  jpeg_finish_compress(&c);
  jpeg_destroy_compress(&c);
  return std::fclose(f) == 0;
}

} // namespace

namespace {
int convert(const std::string &mode, const std::string &in, const std::string &out) {
  const cv::Mat bgr = cv::imread(in, cv::IMREAD_COLOR);
  if (bgr.empty()) {
    std::fprintf(stderr, "cannot read %s\n", in.c_str());
    return 1;
  }
  cv::Mat img;
  std::vector<int> opts;
  if (mode == "grey8") cv::cvtColor(bgr, img, cv::COLOR_BGR2GRAY);
  else if (mode == "grey16") { cv::Mat g; cv::cvtColor(bgr, g, cv::COLOR_BGR2GRAY); img = to_linear16(g); }
  else if (mode == "rgba") cv::cvtColor(bgr, img, cv::COLOR_BGR2BGRA);
  else if (mode == "jpeg") img = bgr, opts = {cv::IMWRITE_JPEG_QUALITY, 95};
  else if (mode == "cmyk_jpeg") return write_cmyk_jpeg(bgr, out) ? 0 : 1;
  else if (mode == "tiff16") img = to_linear16(bgr);
  else if (mode == "half") cv::resize(bgr, img, cv::Size(bgr.cols / 2, bgr.rows / 2), 0, 0, cv::INTER_AREA);
  else if (mode == "big") cv::resize(bgr, img, cv::Size(bgr.cols * 5, bgr.rows * 5), 0, 0, cv::INTER_LINEAR);
  else if (mode == "black") img = cv::Mat::zeros(bgr.size(), bgr.type());
  else if (mode == "white") img = cv::Mat(bgr.size(), bgr.type(), cv::Scalar::all(255));
  else {
    std::fprintf(stderr, "unknown mode %s\n", mode.c_str());
    return 2;
  }
  return cv::imwrite(out, img, opts) ? 0 : 1;
}
} // namespace

int main(int argc, char **argv) {
  if (argc < 4 || argc % 2 != 0) {
    std::fprintf(stderr, "usage: %s MODE IN OUT [IN OUT ...]\n", argv[0]);
    return 2;
  }
  for (int i = 2; i + 1 < argc; i += 2)
    if (const int rc = convert(argv[1], argv[i], argv[i + 1])) return rc;
  return 0;
}
