#include "host_photos.h"

#include <algorithm>
#include <fstream>

#include <QtGlobal>

#include "meshlab_bridge.h"  // utf8

namespace vbrdf_plugin {

bool host_pixels_of(const QImage &image, vbrdf::HostPixels &out) {
  if (image.isNull()) return false;
  // Qt stores 32-bit ARGB/RGB formats as one native-endian word 0xAARRGGBB: B, G, R, A in memory
  // on a little-endian machine. The byte-ordered formats (RGBA8888, RGB888, RGBA64) are R, G, B(, A).
  const bool little = Q_BYTE_ORDER == Q_LITTLE_ENDIAN;
  const std::array<int, 3> word_order = little ? std::array<int, 3>{{2, 1, 0}} : std::array<int, 3>{{1, 2, 3}};
  int depth = CV_8U, channels = 0;
  std::array<int, 3> rgb{{0, 1, 2}};
  switch (image.format()) {
  case QImage::Format_RGB32:
  case QImage::Format_ARGB32: channels = 4, rgb = word_order; break;  // non-premultiplied: colour as stored
  case QImage::Format_RGBX8888:
  case QImage::Format_RGBA8888: channels = 4; break;
  case QImage::Format_RGB888: channels = 3; break;
  case QImage::Format_Grayscale8: channels = 1, rgb = {{0, 0, 0}}; break;
#if QT_VERSION >= QT_VERSION_CHECK(5, 13, 0)
  case QImage::Format_Grayscale16: depth = CV_16U, channels = 1, rgb = {{0, 0, 0}}; break;
#endif
#if QT_VERSION >= QT_VERSION_CHECK(5, 14, 0)
  case QImage::Format_BGR888: channels = 3, rgb = {{2, 1, 0}}; break;
#endif
  case QImage::Format_RGBX64:
  case QImage::Format_RGBA64: depth = CV_16U, channels = 4; break;  // 16-bit codes, R, G, B, A in memory
  default: return false;
  }
  auto keep = std::make_shared<const QImage>(image);  // shares the pixels (implicit sharing), no copy
  out.pixels = cv::Mat(keep->height(), keep->width(), CV_MAKETYPE(depth, channels),
                       const_cast<uchar *>(keep->constBits()), size_t(keep->bytesPerLine()));
  out.rgb = rgb;
  out.owner = keep;
  return true;
}

bool qt_keeps_the_photos_depth(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char head[8] = {0};
  if (!in.read(reinterpret_cast<char *>(head), sizeof head)) return false;
  const unsigned char png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  const bool is_png = std::equal(head, head + 8, png);
  const bool is_jpeg = head[0] == 0xFF && head[1] == 0xD8 && head[2] == 0xFF;
  return is_png || is_jpeg;
}

std::shared_ptr<const vbrdf::HostPhotos> host_photos(const MeshDocument &document) {
  auto photos = std::make_shared<vbrdf::HostPhotos>();
  for (const RasterModel *rm : host::rasters(document)) {
    if (rm == nullptr || rm->planeList.empty() || rm->planeList.first() == nullptr) continue;
    const host::RasterPlane &plane = *rm->planeList.first();
    const std::string path = utf8(plane.fullPathFileName);
    vbrdf::HostPixels pixels;
    if (qt_keeps_the_photos_depth(path) && host_pixels_of(plane.image, pixels)) (*photos)[path] = pixels;
  }
  return photos;
}

} // namespace vbrdf_plugin
