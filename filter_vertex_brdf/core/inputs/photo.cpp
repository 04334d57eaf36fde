#include "inputs/photo.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "base/errors.h"
#include "base/file_util.h"
#include "inputs/image_codec.h"

namespace vbrdf {

float srgb_to_linear(float c) {
  c = std::min(std::max(c, 0.0f), 1.0f);
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

float linear_to_srgb(float c) {
  if (!(c > 0)) return 0;  // also maps NaN to 0
  if (c >= 1) return 1;
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

namespace {

// Where R, G and B sit in a pixel of `channels` codes as OpenCV and Qt store them; channels
// beyond the colour ones (alpha) are ignored.
bool rgb_layout(int channels, bool bgr_order, std::array<int, 3> &rgb) {
  if (channels == 1 || channels == 2) rgb = {{0, 0, 0}};
  else if (channels == 3 || channels == 4) rgb = bgr_order ? std::array<int, 3>{{2, 1, 0}} : std::array<int, 3>{{0, 1, 2}};
  else return false;
  return true;
}

void check_size(const Photo &photo, int expected_width, int expected_height) {
  if (expected_width > 0 && (photo.width() != expected_width || photo.height() != expected_height))
    throw InputError("Photo '" + photo.path + "' is " + std::to_string(photo.width()) + "x" +
                     std::to_string(photo.height()) + " but its raster's camera expects " +
                     std::to_string(expected_width) + "x" + std::to_string(expected_height) +
                     ": use the photo the camera was registered with.");
}

// The decoding table and saturation code of a photo whose codes are `pixels`' depth.
void set_decoding(Photo &photo, PhotoEncoding encoding, float saturation_level) {
  const bool sixteen = photo.pixels.depth() == CV_16U;
  const int max_code = sixteen ? 65535 : 255;
  photo.linear = encoding == PhotoEncoding::Linear || (encoding == PhotoEncoding::Auto && sixteen);
  photo.lut.resize(size_t(max_code) + 1);
  for (int c = 0; c <= max_code; ++c) {
    const float v = float(c) / float(max_code);
    photo.lut[size_t(c)] = photo.linear ? v : srgb_to_linear(v);
  }
  photo.saturation_code = std::max(1, int(std::ceil(saturation_level * max_code - 1e-3f)));
}

} // namespace

Photo load_photo(const std::string &path, PhotoEncoding encoding, float saturation_level, int expected_width,
                 int expected_height) {
  if (!file_exists(path))
    throw InputError("Photo '" + path + "' is missing: restore it or fix the raster's path in the project.");
  Photo photo;
  photo.path = path;
  // Kept as decoded (BGR order): no conversion pass and no second copy of the photo.
  photo.pixels = read_image_unchanged(path);
  if (photo.pixels.empty()) throw InputError("Photo '" + path + "' cannot be decoded (unsupported or damaged file).");
  if (photo.pixels.depth() != CV_8U && photo.pixels.depth() != CV_16U)
    throw InputError("Photo '" + path + "' is neither 8- nor 16-bit per channel: convert it to 8-bit sRGB or "
                     "16-bit linear PNG/TIFF.");
  if (!rgb_layout(photo.pixels.channels(), true, photo.rgb))
    throw InputError("Photo '" + path + "' has " + std::to_string(photo.pixels.channels()) +
                     " channels; expected RGB.");
  check_size(photo, expected_width, expected_height);
  set_decoding(photo, encoding, saturation_level);
  return photo;
}

Photo photo_from_host(const std::string &path, const HostPixels &host, PhotoEncoding encoding, float saturation_level,
                      int expected_width, int expected_height) {
  Photo photo;
  photo.path = path;
  photo.pixels = host.pixels;
  photo.rgb = host.rgb;
  photo.owner = host.owner;
  const int n = photo.pixels.channels();
  const bool rgb_inside = std::all_of(host.rgb.begin(), host.rgb.end(), [n](int c) { return c >= 0 && c < n; });
  if (photo.pixels.empty() || (photo.pixels.depth() != CV_8U && photo.pixels.depth() != CV_16U) || n > 4 || !rgb_inside)
    throw InputError("Photo '" + path + "': the host application's decoded image is not 8/16-bit RGB or grey; "
                     "convert the photo to 8-bit sRGB or 16-bit linear PNG/TIFF.");
  check_size(photo, expected_width, expected_height);
  set_decoding(photo, encoding, saturation_level);
  return photo;
}

namespace {
template <typename T>
PixelSample bilinear(const Photo &photo, float x, float y, uint8_t texels) {
  PixelSample out;
  // A point on the image (x in [0, W), y in [0, H)) is sampled even in the outer half of a border
  // pixel: the footprint's texels beyond the border repeat the border pixel (OpenCV's
  // BORDER_REPLICATE), so an object that touches the frame keeps its outermost pixels.
  const int width = photo.width(), height = photo.height();
  if (!(x >= 0 && y >= 0 && x < float(width) && y < float(height)) || (texels & 0xF) == 0) return out;
  // Pixel centres are at +0.5: shift to centre-based coordinates.
  const float fx = x - 0.5f, fy = y - 0.5f;
  const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  const int xs[2] = {std::max(x0, 0), std::min(x0 + 1, width - 1)}, ys[2] = {std::max(y0, 0), std::min(y0 + 1, height - 1)};
  out.inside = true;
  const float ax = fx - float(x0), ay = fy - float(y0);
  float w[4] = {(1 - ax) * (1 - ay), ax * (1 - ay), (1 - ax) * ay, ax * ay};
  float total = 0;
  for (int k = 0; k < 4; ++k) total += (texels >> k & 1u) ? w[k] : (w[k] = 0);
  if (total < 1e-3f)  // kept texels carry (almost) no bilinear weight: average them instead
    for (int k = 0; k < 4; ++k) w[k] = (texels >> k & 1u) ? 1.0f : 0.0f;
  total = 0;
  for (float wk : w) total += wk;
  const T *rows[2] = {photo.pixels.ptr<T>(ys[0]), photo.pixels.ptr<T>(ys[1])};
  const int n = photo.pixels.channels();
  for (int k = 0; k < 4; ++k) {
    if (w[k] == 0 && texels != 0xF) continue;
    const T *px = rows[k / 2] + n * xs[k % 2];
    for (int c = 0; c < 3; ++c) {
      const T code = px[photo.rgb[size_t(c)]];
      if (int(code) >= photo.saturation_code) out.saturated = true;
      out.rgb[c] += w[k] / total * photo.lut[code];
    }
  }
  return out;
}
} // namespace

cv::Mat photo_linear_rgb(const Photo &photo, cv::Mat *clipped) {
  const int w = photo.width(), h = photo.height();
  cv::Mat linear(h, w, CV_32FC3);
  if (clipped) clipped->create(h, w, CV_8U);
  const bool wide = photo.pixels.depth() == CV_16U;
  const int n = photo.pixels.channels();
#pragma omp parallel for schedule(static)
  for (int y = 0; y < h; ++y) {
    float *out = linear.ptr<float>(y);
    uint8_t *clip = clipped ? clipped->ptr<uint8_t>(y) : nullptr;
    for (int x = 0; x < w; ++x) {
      bool any = false;
      for (int c = 0; c < 3; ++c) {
        const int i = n * x + photo.rgb[size_t(c)];
        const int code = wide ? photo.pixels.ptr<uint16_t>(y)[i] : photo.pixels.ptr<uint8_t>(y)[i];
        out[3 * x + c] = photo.lut[size_t(code)];
        any = any || code >= photo.saturation_code;
      }
      if (clip) clip[x] = any ? 255 : 0;
    }
  }
  return linear;
}

cv::Mat photo_srgb8_bgr(const Photo &photo) {
  if (photo.linear || photo.pixels.depth() != CV_8U || photo.pixels.empty()) return cv::Mat();
  cv::Mat bgr(photo.height(), photo.width(), CV_8UC3);
  const int from_to[6] = {photo.rgb[2], 0, photo.rgb[1], 1, photo.rgb[0], 2};  // B, G, R wherever they sit
  cv::mixChannels(&photo.pixels, 1, &bgr, 1, from_to, 3);
  return bgr;
}

cv::Mat decode_to_linear(const cv::Mat &image, bool decode_srgb) {
  if (image.empty()) return cv::Mat();
  cv::Mat f;
  if (image.depth() == CV_8U && decode_srgb) {
    cv::Mat lut(1, 256, CV_32F);
    for (int i = 0; i < 256; ++i) lut.at<float>(i) = srgb_to_linear(float(i) / 255.0f);
    std::vector<cv::Mat> planes, decoded;
    cv::split(image, planes);
    for (const cv::Mat &p : planes) {
      cv::Mat d;
      cv::LUT(p, lut, d);
      decoded.push_back(d);
    }
    cv::merge(decoded, f);
  } else if (image.depth() == CV_8U) {
    image.convertTo(f, CV_MAKETYPE(CV_32F, image.channels()), 1.0 / 255);
  } else if (image.depth() == CV_16U) {
    image.convertTo(f, CV_MAKETYPE(CV_32F, image.channels()), 1.0 / 65535);
  } else if (image.depth() == CV_32F || image.depth() == CV_64F) {
    image.convertTo(f, CV_MAKETYPE(CV_32F, image.channels()));
  } else {
    throw InputError("Unsupported image depth: expected 8-bit, 16-bit or float.");
  }
  return f;
}

PixelSample sample_bilinear(const Photo &photo, float x, float y, uint8_t texels) {
  if (!std::isfinite(x) || !std::isfinite(y)) return PixelSample();
  return photo.pixels.depth() == CV_16U ? bilinear<uint16_t>(photo, x, y, texels)
                                        : bilinear<uint8_t>(photo, x, y, texels);
}

PhotoCache::PhotoCache(PhotoEncoding encoding, float saturation_level, size_t budget_bytes,
                       std::shared_ptr<const HostPhotos> host)
    : encoding_(encoding), saturation_level_(saturation_level), budget_(budget_bytes), host_(std::move(host)) {}

std::shared_ptr<const Photo> PhotoCache::get(const std::string &path, int expected_width, int expected_height) {
  return load(path, expected_width, expected_height, false);
}

std::shared_ptr<const Photo> PhotoCache::prefetch(const std::string &path, int expected_width, int expected_height) {
  return load(path, expected_width, expected_height, true);
}

std::shared_ptr<const Photo> PhotoCache::load(const std::string &path, int expected_width, int expected_height,
                                              bool only_if_room) {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    ++tick_;
    for (auto &e : entries_)
      if (e.first == path) {
        e.second.last_use = tick_;
        return e.second.photo;
      }
    if (std::find(loading_.begin(), loading_.end(), path) == loading_.end()) break;
    loaded_.wait(lock);  // another thread decodes it
  }
  const auto host = host_ ? host_->find(path) : HostPhotos::const_iterator();
  if (host_ && host != host_->end()) {
    // Read in place: only its decoding table counts against the budget.
    auto photo = std::make_shared<const Photo>(
        photo_from_host(path, host->second, encoding_, saturation_level_, expected_width, expected_height));
    ++host_reads_;
    entries_.push_back({path, Entry{photo, photo->lut.size() * sizeof(float), ++tick_}});
    used_ += entries_.back().second.bytes;
    return photo;
  }
  // Room for it and for the photos being decoded, each as large as the largest so far (checked
  // with the decode registered under one lock, so that prefetching threads never overshoot).
  const bool busy = !entries_.empty() || !loading_.empty();
  if (only_if_room && busy && used_ + largest_ * (loading_.size() + 1) > budget_) return nullptr;
  loading_.push_back(path);
  lock.unlock();
  std::shared_ptr<const Photo> photo;
  try {
    photo = std::make_shared<const Photo>(load_photo(path, encoding_, saturation_level_, expected_width, expected_height));
  } catch (...) {
    lock.lock();
    loading_.erase(std::find(loading_.begin(), loading_.end(), path));
    loaded_.notify_all();
    throw;
  }
  lock.lock();
  loading_.erase(std::find(loading_.begin(), loading_.end(), path));
  ++loads_;
  const size_t bytes = photo->pixels.total() * photo->pixels.elemSize() + photo->lut.size() * sizeof(float);
  largest_ = std::max(largest_, bytes);
  // Evict least recently used photos until the new one fits (a photo in use elsewhere stays
  // alive through its shared_ptr even when evicted).
  while (!entries_.empty() && used_ + bytes > budget_) {
    auto oldest = std::min_element(entries_.begin(), entries_.end(), [](const auto &a, const auto &b) {
      return a.second.last_use < b.second.last_use;
    });
    used_ -= oldest->second.bytes;
    entries_.erase(oldest);
  }
  entries_.push_back({path, Entry{photo, bytes, ++tick_}});
  used_ += bytes;
  loaded_.notify_all();
  return photo;
}


} // namespace vbrdf
