#pragma once
// Comparison of a relit render (relight_render.h) with a photo of the same camera, pixel by
// pixel: CIEDE2000 and PSNR over the lit visible pixels and, labelled, over the whole surface
// (the rules are at the top of relight_render.h).
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "relight/relight_render.h"

namespace vbrdf {

// Per-pixel comparison of a render with a photo of the same camera.
struct PixelComparison {
  int width = 0, height = 0;
  std::vector<float> de2000;      // per pixel; negative where not compared
  size_t pixels = 0;              // compared pixels
  double mean_de2000 = 0, median_de2000 = 0, p95_de2000 = 0;
  double psnr_db = 0;             // linear RGB in [0, 1]; 99 when identical
  double squared_error = 0;       // sum over compared pixels and channels (for pooling)
  std::vector<uint32_t> histogram;  // de2000 in bins of kDeHistogramBin (last bin: everything above)
};
constexpr double kDeHistogramBin = 0.01;
constexpr size_t kDeHistogramBins = 20000;  // up to CIEDE2000 200

// Compares `render` with the photo (linear, same size; see photo_linear_rgb, photo.h) over the lit visible
// pixels (see the top of this file). `focal_px` (the shot's focal length in pixels) scales the
// allowed depth change between neighbours. Throws InputError when the sizes differ.
PixelComparison compare_with_photo(const RelitImage &render, const cv::Mat &photo_linear, const cv::Mat &photo_clipped,
                                   float focal_px);

// Whole-surface comparison (the RTI protocol), reported beside the one above: every rendered surface
// pixel that is lit (kRelitLit) or belongs to a triangle without a fit (kRelitNoFit, predicted
// black: what relighting the PLY shows), silhouettes and depth jumps included; only pixels with a
// clipped photo channel are left out. Throws InputError when the sizes differ.
PixelComparison compare_whole_surface(const RelitImage &render, const cv::Mat &photo_linear,
                                      const cv::Mat &photo_clipped);

// Pools several comparisons (pixel-weighted mean, percentiles from the merged histograms,
// PSNR of the pooled squared error).
PixelComparison pool_comparisons(const std::vector<const PixelComparison *> &parts);

} // namespace vbrdf
