#include "calibration/color_plan.h"

#include <algorithm>

#include "base/errors.h"
#include "inputs/viewpoints.h"

namespace vbrdf {

namespace {
// Chart settings of viewpoint `v`: detection, or its corners (8 numbers shared by all viewpoints,
// or 8 per viewpoint).
ColorSettings chart_settings_for(const ColorCorrectionSettings &settings, size_t v, size_t viewpoints) {
  const std::vector<float> &corners = settings.chart_corners;
  if (!corners.empty() && corners.size() != 8 && corners.size() != 8 * viewpoints)
    throw InputError("Parameter 'chartCorners' has " + std::to_string(corners.size()) + " numbers; give 8 (x y of "
                     "the dark skin, bluish green, black and white patch centres) for all viewpoints, or 8 per "
                     "viewpoint (the project has " + std::to_string(viewpoints) + "), or leave it empty to detect "
                     "the chart.");
  ColorSettings s;
  s.require_chart = settings.choice == ColorCorrectionChoice::Required;
  s.exposure = settings.exposure;
  s.manual = !corners.empty();
  const size_t first = corners.size() == 8 ? 0 : 8 * v;
  if (s.manual) std::copy(corners.begin() + long(first), corners.begin() + long(first + 8), s.corners);
  return s;
}

std::string viewpoint_name(const std::vector<Raster> &rasters, const std::vector<size_t> &group, size_t v,
                           size_t count) {
  return "Viewpoint " + std::to_string(v + 1) + " of " + std::to_string(count) + " (" + std::to_string(group.size()) +
         " photo(s), first raster '" + rasters[group.front()].label + "')";
}
} // namespace

bool ColorPlan::any_corrected() const {
  return std::any_of(viewpoints.begin(), viewpoints.end(), [](const ColorCalibration &c) { return c.corrected; });
}

const ColorCalibration *ColorPlan::of_raster(size_t r) const {
  if (r >= viewpoint_of.size() || viewpoint_of[r] >= viewpoints.size()) return nullptr;
  const ColorCalibration &c = viewpoints[viewpoint_of[r]];
  return c.corrected ? &c : nullptr;
}

ColorPlan plan_color_correction(const std::vector<Raster> &rasters,
                                const std::vector<std::array<float, 3>> &lights_world,
                                const ColorCorrectionSettings &settings, const std::function<cv::Mat(size_t)> &load,
                                const LogFn &log, const std::function<cv::Mat(size_t)> &detector_image,
                                const RgbRegionLoader &load_region) {
  ColorPlan plan;
  if (settings.choice == ColorCorrectionChoice::Off) return plan;
  const std::vector<std::vector<size_t>> groups = rasters_by_viewpoint(rasters);
  plan.viewpoint_of.resize(rasters.size());
  plan.photo_of.resize(rasters.size());
  for (size_t v = 0; v < groups.size(); ++v) {
    const std::vector<size_t> &group = groups[v];
    const std::string where = viewpoint_name(rasters, group, v, groups.size());
    std::vector<std::string> names;
    std::vector<std::array<double, 3>> lights_cam;  // calibrate_colors tells varying intensity from the chart's angle
    for (size_t r : group) {
      names.push_back(rasters[r].label);  // the core quotes it
      float cam[3];
      world_to_camera_direction(rasters[r].shot, lights_world[r].data(), cam);
      lights_cam.push_back({{cam[0], cam[1], cam[2]}});
    }
    const RgbLoader load_photo = [&](size_t i) { return load(group[i]); };
    RgbLoader detector_photo;
    if (detector_image) detector_photo = [&](size_t i) { return detector_image(group[i]); };
    RgbRegionLoader region_of_photo;
    if (load_region) region_of_photo = [&](size_t i, const cv::Rect &r) { return load_region(group[i], r); };
    try {
      plan.viewpoints.push_back(calibrate_colors(group.size(), load_photo, chart_settings_for(settings, v, groups.size()),
                                                 &lights_cam, names, detector_photo, region_of_photo));
    } catch (const InputError &e) {
      throw InputError("Colour correction is required (colorCorrection = Required) but failed. " + where + ": " +
                       e.what() + " Set 'chartCorners', or set 'colorCorrection' to Auto to go on without correction.");
    }
    const ColorCalibration &cal = plan.viewpoints.back();
    for (size_t i = 0; i < group.size(); ++i) {
      plan.viewpoint_of[group[i]] = uint32_t(v);
      plan.photo_of[group[i]] = uint32_t(i);
    }
    for (const std::string &line : cal.log) log(where + ": " + line);
    if (!cal.corrected)
      log(where + ": colour correction: " + (cal.patches.empty() ? "no chart found" : "chart not usable") +
          ": colours uncorrected.");
  }
  return plan;
}

} // namespace vbrdf
