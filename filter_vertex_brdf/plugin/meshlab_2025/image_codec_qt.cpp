// core/inputs/image_codec.h through Qt's QImageReader / QImageWriter, for the PyMeshLab build: the
// host process already holds Qt (the wheel's), while OpenCV's imgcodecs would load GDAL -> libcurl
// against the wheel's older libnghttp2 (docs/pymeshlab.md#image-decoding). The pixels come out as
// cv::imread(path, IMREAD_UNCHANGED) gives them: codes as stored (8 or 16 bit), B, G, R(, A) order,
// no EXIF rotation (QImageReader::autoTransform is off by default, as OpenCV's IMREAD_UNCHANGED).
#include "inputs/image_codec.h"

#include <QBuffer>
#include <QByteArray>
#include <QImage>
#include <QImageReader>
#include <QImageWriter>
#include <QString>

#include <opencv2/imgproc.hpp>

namespace vbrdf {

namespace {

// A copy of `image` (already in `format`) as a cv::Mat of `type`, channels reordered to BGR(A).
cv::Mat to_mat(const QImage &image, int type, int to_bgr_code) {
  const cv::Mat view(image.height(), image.width(), type, const_cast<uchar *>(image.constBits()),
                     size_t(image.bytesPerLine()));
  cv::Mat out;
  if (to_bgr_code < 0) view.copyTo(out);
  else cv::cvtColor(view, out, to_bgr_code);
  return out;
}

bool is_sixteen_bit(QImage::Format format) {
  return format == QImage::Format_Grayscale16 || format == QImage::Format_RGBX64 || format == QImage::Format_RGBA64 ||
         format == QImage::Format_RGBA64_Premultiplied;
}

} // namespace

cv::Mat read_image_unchanged(const std::string &path) {
  QImageReader reader(QString::fromStdString(path));
  reader.setAutoTransform(false);
  QImage image;
  if (!reader.read(&image) || image.isNull()) return cv::Mat();
  const bool alpha = image.hasAlphaChannel();
  if (is_sixteen_bit(image.format())) {
    if (image.isGrayscale() && !alpha) return to_mat(image.convertToFormat(QImage::Format_Grayscale16), CV_16UC1, -1);
    const QImage rgba = image.convertToFormat(QImage::Format_RGBA64);  // R, G, B, A in memory
    return alpha ? to_mat(rgba, CV_16UC4, cv::COLOR_RGBA2BGRA) : to_mat(rgba, CV_16UC4, cv::COLOR_RGBA2BGR);
  }
  if (image.isGrayscale() && !alpha) return to_mat(image.convertToFormat(QImage::Format_Grayscale8), CV_8UC1, -1);
  if (alpha) return to_mat(image.convertToFormat(QImage::Format_RGBA8888), CV_8UC4, cv::COLOR_RGBA2BGRA);
  return to_mat(image.convertToFormat(QImage::Format_RGB888), CV_8UC3, cv::COLOR_RGB2BGR);
}

bool encode_png(const cv::Mat &image, std::vector<uint8_t> &bytes) {
  if (image.empty() || image.depth() != CV_8U) return false;
  cv::Mat rgba;
  switch (image.channels()) {
  case 1: cv::cvtColor(image, rgba, cv::COLOR_GRAY2RGBA); break;
  case 3: cv::cvtColor(image, rgba, cv::COLOR_BGR2RGBA); break;
  case 4: cv::cvtColor(image, rgba, cv::COLOR_BGRA2RGBA); break;
  default: return false;
  }
  const QImage qimage(rgba.data, rgba.cols, rgba.rows, int(rgba.step), QImage::Format_RGBA8888);
  QByteArray encoded;
  QBuffer buffer(&encoded);
  buffer.open(QIODevice::WriteOnly);
  if (!QImageWriter(&buffer, "png").write(qimage)) return false;
  bytes.assign(encoded.begin(), encoded.end());
  return true;
}

} // namespace vbrdf
