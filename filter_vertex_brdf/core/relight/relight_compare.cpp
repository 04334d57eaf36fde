// Render-against-photo comparison (contract in relight_compare.h).
#include "relight/relight_compare.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/color_difference.h"
#include "base/errors.h"
#include "base/file_util.h"
#include "base/vec3.h"

namespace vbrdf {

// ---------------------------------------------------------------------------------------------
// Comparison

namespace {

// True when every 8-neighbour of (x, y) is surface whose depth continues the pixel's surface.
bool interior_pixel(const RelitImage &r, int x, int y, float focal_px) {
  if (x < 1 || y < 1 || x >= r.width - 1 || y >= r.height - 1) return false;
  const size_t i = size_t(y) * size_t(r.width) + size_t(x);
  const float depth = r.depth[i];
  // Up to a 79-degree view angle (tan 5) over one pixel, as the visibility pass's footprint test.
  const float allowed = depth / std::max(focal_px, 1e-6f) * 5.0f + 1e-4f * depth;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const size_t j = size_t(y + dy) * size_t(r.width) + size_t(x + dx);
      if (r.pixel_class[j] == kRelitBackground || std::fabs(r.depth[j] - depth) > allowed) return false;
    }
  return true;
}

// Median and 95th percentile from the histogram (bin centres).
void histogram_stats(PixelComparison &c) {
  if (c.pixels == 0) return;
  const size_t median_rank = (c.pixels - 1) / 2, p95_rank = size_t(0.95 * double(c.pixels - 1) + 0.5);
  size_t seen = 0;
  bool median_done = false;
  for (size_t b = 0; b < c.histogram.size(); ++b) {
    seen += c.histogram[b];
    const double centre = (double(b) + 0.5) * kDeHistogramBin;
    if (!median_done && seen > median_rank) c.median_de2000 = centre, median_done = true;
    if (seen > p95_rank) {
      c.p95_de2000 = centre;
      break;
    }
  }
}

void finish_stats(PixelComparison &c, double de_sum) {
  if (c.pixels == 0) return;
  c.mean_de2000 = de_sum / double(c.pixels);
  histogram_stats(c);
  const double mse = c.squared_error / (3.0 * double(c.pixels));
  c.psnr_db = mse > 0 ? 10 * std::log10(1.0 / mse) : 99.0;
}

} // namespace

namespace {
// Compares the pixels `use` accepts; pixels of a triangle without a fit are predicted black.
template <class Use>
PixelComparison compare_pixels(const RelitImage &render, const cv::Mat &photo_linear, const cv::Mat &photo_clipped,
                               const Use &use) {
  if (photo_linear.cols != render.width || photo_linear.rows != render.height || photo_linear.type() != CV_32FC3 ||
      photo_clipped.size() != photo_linear.size())
    throw InputError("Relighting: the photo is " + std::to_string(photo_linear.cols) + "x" +
                     std::to_string(photo_linear.rows) + " but the camera's viewport is " +
                     std::to_string(render.width) + "x" + std::to_string(render.height) + ".");
  PixelComparison c;
  c.width = render.width;
  c.height = render.height;
  c.de2000.assign(size_t(render.width) * size_t(render.height), -1.0f);
  c.histogram.assign(kDeHistogramBins, 0);
  double de_sum = 0;
  for (int y = 0; y < render.height; ++y) {
    const float *photo = photo_linear.ptr<float>(y);
    const uint8_t *clip = photo_clipped.ptr<uint8_t>(y);
    for (int x = 0; x < render.width; ++x) {
      const size_t i = size_t(y) * size_t(render.width) + size_t(x);
      if (clip[x] || !use(x, y, i)) continue;
      float predicted[3] = {0, 0, 0};
      if (render.pixel_class[i] != kRelitNoFit)
        for (int k = 0; k < 3; ++k) predicted[k] = std::min(1.0f, std::max(0.0f, render.rgb[3 * i + size_t(k)]));
      const double de = delta_e2000_linear_srgb(predicted, photo + 3 * x);
      c.de2000[i] = float(de);
      de_sum += de;
      ++c.histogram[std::min(kDeHistogramBins - 1, size_t(de / kDeHistogramBin))];
      for (int k = 0; k < 3; ++k) {
        const double e = double(predicted[k]) - double(photo[3 * x + k]);
        c.squared_error += e * e;
      }
      ++c.pixels;
    }
  }
  finish_stats(c, de_sum);
  return c;
}
} // namespace

PixelComparison compare_with_photo(const RelitImage &render, const cv::Mat &photo_linear, const cv::Mat &photo_clipped,
                                   float focal_px) {
  return compare_pixels(render, photo_linear, photo_clipped, [&](int x, int y, size_t i) {
    return render.pixel_class[i] == kRelitLit && interior_pixel(render, x, y, focal_px);
  });
}

PixelComparison compare_whole_surface(const RelitImage &render, const cv::Mat &photo_linear,
                                      const cv::Mat &photo_clipped) {
  return compare_pixels(render, photo_linear, photo_clipped, [&](int, int, size_t i) {
    return render.pixel_class[i] == kRelitLit || render.pixel_class[i] == kRelitNoFit;
  });
}

PixelComparison pool_comparisons(const std::vector<const PixelComparison *> &parts) {
  PixelComparison c;
  c.histogram.assign(kDeHistogramBins, 0);
  double de_sum = 0;
  for (const PixelComparison *p : parts) {
    c.pixels += p->pixels;
    c.squared_error += p->squared_error;
    de_sum += p->mean_de2000 * double(p->pixels);
    for (size_t b = 0; b < std::min(p->histogram.size(), c.histogram.size()); ++b) c.histogram[b] += p->histogram[b];
  }
  finish_stats(c, de_sum);
  return c;
}

} // namespace vbrdf
