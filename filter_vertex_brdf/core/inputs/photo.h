#pragma once
// Photos: decoding to linear RGB and bilinear sampling with saturation detection.
// 8-bit photos are sRGB-encoded (camera JPEG/PNG) and decoded with the sRGB EOTF; 16-bit PNG/TIFF
// are taken as linear. Pixels are kept in their original 8/16-bit form (a 256/65536-entry table
// decodes on sampling) so that hundreds of photos fit in memory.
#include <cstdint>
#include <memory>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace vbrdf {

enum class PhotoEncoding { Auto = 0, SRGB = 1, Linear = 2 };

float srgb_to_linear(float encoded);  // IEC 61966-2-1 EOTF, input in [0,1]
float linear_to_srgb(float linear);   // inverse, clamps to [0,1]

struct Photo {
  std::string path;
  cv::Mat pixels;         // CV_8UC3 or CV_16UC3, RGB channel order, row 0 = top of the image
  bool linear = false;    // true: codes are linear; false: sRGB-encoded
  std::vector<float> lut; // code value -> linear intensity in [0,1]
  int saturation_code = 255; // a channel at or above this code value is clipped
  int width() const { return pixels.cols; }
  int height() const { return pixels.rows; }
};

// Loads a photo. `saturation_level` in (0,1]: a channel >= level * max code counts as clipped.
// Throws InputError naming the file when it is missing/unreadable, not 8/16-bit, or (when
// expected_width/height > 0) its size differs from the raster's viewport.
Photo load_photo(const std::string &path, PhotoEncoding encoding, float saturation_level = 0.99f,
                 int expected_width = 0, int expected_height = 0);

// The photo as linear RGB float (CV_32FC3, its own decoding table: exactly the values its samples
// get) and, when `clipped` is given, a CV_8U mask of its clipped pixels (255 where any channel is
// at or above the saturation code).
cv::Mat photo_linear_rgb(const Photo &photo, cv::Mat *clipped = nullptr);

// Any image (8-bit, 16-bit or float; any channel count) as float in [0, 1] with its channels kept:
// 8-bit decoded as sRGB when `decode_srgb` (else / 255), 16-bit / 65535 (linear), float as is.
// The one decoding of images that are not Photos (colour charts, spheres). Throws InputError for
// another depth; an empty image gives an empty result.
cv::Mat decode_to_linear(const cv::Mat &image, bool decode_srgb);

struct PixelSample {
  float rgb[3] = {0, 0, 0};  // linear
  bool inside = false;       // the bilinear footprint is inside the image
  bool saturated = false;    // any channel of any of the 4 footprint pixels is clipped
};

// Bilinear sample at image-pixel coordinates (top-left origin, y down, centres at +0.5).
// `texels` (visibility.h's footprint mask: bit k = texel (x0 + k % 2, y0 + k / 2)) restricts the
// footprint to some of its 4 texels, their bilinear weights renormalised; when those weights sum
// to almost nothing (the point sits on the far side of the kept texels) the kept texels are
// averaged. Saturation is checked on the kept texels only. texels == 0 gives inside = false.
PixelSample sample_bilinear(const Photo &photo, float x, float y, uint8_t texels = 0xF);

// Keeps decoded photos under a memory budget (least recently used are dropped and reloaded on
// demand). Thread-safe: photos are decoded outside the lock, several at once from several threads;
// a thread asking for a photo that another is decoding waits for it (one decode per photo).
class PhotoCache {
public:
  PhotoCache(PhotoEncoding encoding, float saturation_level, size_t budget_bytes);
  // Returns the photo of `path`, loading it if needed (validating its size when given).
  std::shared_ptr<const Photo> get(const std::string &path, int expected_width = 0, int expected_height = 0);
  size_t loads() const { return loads_; }  // number of decodes performed (for the report)
  // As get, but only when the photo fits beside the cached ones and those being decoded (each
  // counted as large as the largest so far) without evicting any: else nullptr, nothing decoded.
  std::shared_ptr<const Photo> prefetch(const std::string &path, int expected_width = 0, int expected_height = 0);

private:
  std::shared_ptr<const Photo> load(const std::string &path, int expected_width, int expected_height, bool only_if_room);

  PhotoEncoding encoding_;
  float saturation_level_;
  size_t budget_;
  size_t used_ = 0;
  std::atomic<size_t> loads_{0};
  size_t largest_ = 0;
  unsigned long tick_ = 0;
  std::vector<std::string> loading_;  // paths being decoded now
  std::condition_variable loaded_;
  struct Entry { std::shared_ptr<const Photo> photo; size_t bytes; unsigned long last_use; };
  std::vector<std::pair<std::string, Entry>> entries_;
  std::mutex mutex_;
};

} // namespace vbrdf
