#pragma once
// Colour-correction planning, one for the fit and the relight comparison: every viewpoint's photos
// are calibrated from the ColorChecker in them (color_chart.h) and each raster finds its
// viewpoint's correction here. The fit corrects its samples with it (samples/sample_colors.h), the relight
// filter its photos (apply_color_calibration), so both compare the same corrected colours.
#include <array>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "base/callbacks.h"
#include "inputs/camera.h"
#include "calibration/color_chart.h"

namespace vbrdf {

// The colorCorrection parameter of every filter.
enum class ColorCorrectionChoice { Off = 0, Auto = 1, Required = 2 };

struct ColorCorrectionSettings {
  ColorCorrectionChoice choice = ColorCorrectionChoice::Auto;
  ExposureMode exposure = ExposureMode::Auto;
  // Centres of the chart's corner patches: empty = detect; 8 numbers = the same for every
  // viewpoint; 8 per viewpoint = one group each, viewpoints in order of their first raster.
  std::vector<float> chart_corners;
};

struct ColorPlan {
  std::vector<ColorCalibration> viewpoints;       // in rasters_by_viewpoint order; empty when Off
  std::vector<uint32_t> viewpoint_of, photo_of;  // per raster: its viewpoint, its index there
  bool any_corrected() const;
  // The correction of raster r, or null (Off, or no usable chart in its viewpoint).
  const ColorCalibration *of_raster(size_t r) const;
};

// Calibrates every viewpoint of `rasters`. `load(r)` returns raster r's photo as linear RGB float
// (decoded as its samples are); lights_world[r] is the direction towards raster r's light (the
// chart's shading tells varying intensity). Each viewpoint's log lines go to `log`, prefixed with
// "Viewpoint i of n (k photo(s), first raster '...')". Throws InputError when the correction is
// Required and a viewpoint has no usable chart, or when chart_corners has a wrong count (naming
// 'chartCorners'). `detector_image` and `load_region` (optional, by raster): calibrate_colors'
// cheaper ways to the detector's 8-bit image and to the chart's part of a photo.
ColorPlan plan_color_correction(const std::vector<Raster> &rasters,
                                const std::vector<std::array<float, 3>> &lights_world,
                                const ColorCorrectionSettings &settings, const std::function<cv::Mat(size_t)> &load,
                                const LogFn &log, const std::function<cv::Mat(size_t)> &detector_image = {},
                                const RgbRegionLoader &load_region = {});

} // namespace vbrdf
