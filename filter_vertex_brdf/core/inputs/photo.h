#pragma once
// Photos: decoding to linear RGB and bilinear sampling with saturation detection.
// 8-bit photos are sRGB-encoded (camera JPEG/PNG) and decoded with the sRGB EOTF; 16-bit PNG/TIFF
// are taken as linear. Pixels are kept in their original 8/16-bit form and channel layout (a
// 256/65536-entry table decodes on sampling) so that hundreds of photos fit in memory, and so that
// a photo the host application already decoded (MeshLab keeps each raster's photo as a QImage) is
// read in place instead of being decoded and held a second time (HostPixels).
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "base/clip_level.h"

namespace vbrdf {

enum class PhotoEncoding { Auto = 0, SRGB = 1, Linear = 2 };

float srgb_to_linear(float encoded);  // IEC 61966-2-1 EOTF, input in [0,1]
float linear_to_srgb(float linear);   // inverse, clamps to [0,1]

struct Photo {
  std::string path;
  cv::Mat pixels;         // CV_8UC(n) or CV_16UC(n), n = 1..4 codes per pixel, row 0 = top of the image
  std::array<int, 3> rgb{{0, 1, 2}};  // where R, G and B sit within a pixel (grey: all 0)
  std::shared_ptr<const void> owner;  // the host memory `pixels` wraps (photo_from_host), else empty
  bool linear = false;    // true: codes are linear; false: sRGB-encoded
  std::vector<float> lut; // code value -> linear intensity in [0,1]
  int saturation_code = 255; // a channel at or above this code value is clipped
  int width() const { return pixels.cols; }
  int height() const { return pixels.rows; }
  // The code of colour channel c (0 = R) at pixel (x, y); T is uint8_t or uint16_t, as pixels' depth.
  template <typename T> T code(int x, int y, int c) const {
    return pixels.ptr<T>(y)[pixels.channels() * x + rgb[size_t(c)]];
  }
};

// Loads a photo. `saturation_level` in (0,1]: a channel >= level * max code counts as clipped.
// Throws InputError naming the file when it is missing/unreadable, not 8/16-bit, or (when
// expected_width/height > 0) its size differs from the raster's viewport.
Photo load_photo(const std::string &path, PhotoEncoding encoding, float saturation_level = kSaturationLevel,
                 int expected_width = 0, int expected_height = 0);

// A photo the host application has already decoded, e.g. MeshLab's QImage of a raster.
struct HostPixels {
  cv::Mat pixels;                     // CV_8UC(n) or CV_16UC(n) header over the host's memory (not copied)
  std::array<int, 3> rgb{{0, 1, 2}};  // channel index of R, G and B within a pixel (grey: all 0)
  std::shared_ptr<const void> owner;  // keeps that memory alive while a Photo reads it
};
using HostPhotos = std::map<std::string, HostPixels>;  // by photo path (Raster::image_path)

// The host's pixels as a Photo of `path`, decoded as load_photo decodes the same file (the same
// table, saturation code and size check; nothing is copied). Throws InputError naming `path`
// when the size differs from the expected one or the pixels are not 8/16-bit with 1..4 channels.
Photo photo_from_host(const std::string &path, const HostPixels &host, PhotoEncoding encoding,
                      float saturation_level = kSaturationLevel, int expected_width = 0, int expected_height = 0);

// The photo as linear RGB float (CV_32FC3, its own decoding table: exactly the values its samples
// get) and, when `clipped` is given, a CV_8U mask of its clipped pixels (255 where any channel is
// at or above the saturation code).
cv::Mat photo_linear_rgb(const Photo &photo, cv::Mat *clipped = nullptr);

// The photo's own codes as an 8-bit sRGB BGR image (CV_8UC3), what the chart detector reads:
// equal to srgb8_bgr_image(photo_linear_rgb(photo)) (color_chart.h) without the float image in
// between (144 MB for a 12 MP photo). Empty unless the photo is 8-bit and sRGB-encoded.
cv::Mat photo_srgb8_bgr(const Photo &photo);

// Any image (8-bit, 16-bit or float; any channel count) as float in [0, 1] with its channels kept:
// 8-bit decoded as sRGB when `decode_srgb` (else / 255), 16-bit / 65535 (linear), float as is.
// The one decoding of images that are not Photos (colour charts, spheres). Throws InputError for
// another depth; an empty image gives an empty result.
cv::Mat decode_to_linear(const cv::Mat &image, bool decode_srgb);

struct PixelSample {
  float rgb[3] = {0, 0, 0};  // linear
  bool inside = false;       // the point is on the image (footprint texels beyond its border repeat the border pixel)
  bool saturated = false;    // any channel of any of the 4 footprint pixels is clipped
};

// Bilinear sample at image-pixel coordinates (top-left origin, y down, centres at +0.5), for a
// point on the image (x in [0, W), y in [0, H)); beyond the border the footprint repeats the
// border pixel.
// `texels` (visibility.h's footprint mask: bit k = texel (x0 + k % 2, y0 + k / 2)) restricts the
// footprint to some of its 4 texels, their bilinear weights renormalised; when those weights sum
// to almost nothing (the point sits on the far side of the kept texels) the kept texels are
// averaged. Saturation is checked on the kept texels only. texels == 0 gives inside = false.
PixelSample sample_bilinear(const Photo &photo, float x, float y, uint8_t texels = 0xF);

// Keeps decoded photos under a memory budget (least recently used are dropped and reloaded on
// demand). Thread-safe: photos are decoded outside the lock, several at once from several threads;
// a thread asking for a photo that another is decoding waits for it (one decode per photo).
// Photos in `host` (the host application's decoded images, by path) are wrapped instead of
// decoded: no file is read for them and they take none of the budget.
class PhotoCache {
public:
  PhotoCache(PhotoEncoding encoding, float saturation_level, size_t budget_bytes,
             std::shared_ptr<const HostPhotos> host = nullptr);
  // Returns the photo of `path`, loading it if needed (validating its size when given).
  std::shared_ptr<const Photo> get(const std::string &path, int expected_width = 0, int expected_height = 0);
  size_t loads() const { return loads_; }  // number of decodes performed (for the report)
  size_t host_reads() const { return host_reads_; }  // photos read in place from the host's images
  // As get, but only when the photo fits beside the cached ones and those being decoded (each
  // counted as large as the largest so far) without evicting any: else nullptr, nothing decoded.
  std::shared_ptr<const Photo> prefetch(const std::string &path, int expected_width = 0, int expected_height = 0);

private:
  std::shared_ptr<const Photo> load(const std::string &path, int expected_width, int expected_height, bool only_if_room);

  PhotoEncoding encoding_;
  float saturation_level_;
  size_t budget_;
  size_t used_ = 0;
  std::shared_ptr<const HostPhotos> host_;
  std::atomic<size_t> loads_{0};
  std::atomic<size_t> host_reads_{0};
  size_t largest_ = 0;
  unsigned long tick_ = 0;
  std::vector<std::string> loading_;  // paths being decoded now
  std::condition_variable loaded_;
  struct Entry { std::shared_ptr<const Photo> photo; size_t bytes; unsigned long last_use; };
  std::vector<std::pair<std::string, Entry>> entries_;
  std::mutex mutex_;
};

} // namespace vbrdf
