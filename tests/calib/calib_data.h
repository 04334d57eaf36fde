#pragma once
// Loaders for the calibration test data in ../shared (real photographs with reference light
// directions, the Mitsuba scenes' ground truth) and the small statistics the reports print.
// Used by the unit tests and by vbrdf_calibrate's report.
#include <array>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calibration/sphere_lights.h"

namespace vbrdf {
namespace calib {

// Uncompressed true-colour TGA (type 2, 24/32 bit) as BGR(A), top row first. OpenCV 4.6 has no
// TGA codec. Throws InputError on anything else.
cv::Mat read_tga(const std::string &path);

// Any photo: TGA through read_tga, everything else through cv::imread(IMREAD_UNCHANGED).
// Throws InputError when it cannot be read.
cv::Mat read_image(const std::string &path);

// A real set: photos of one sphere with reference light directions (camera frame, x right,
// y up, z towards the viewer) and the circle the set's own calibration used (image pixels).
struct RealLightSet {
  std::string name;
  std::vector<std::string> images;
  std::vector<std::array<double, 3>> reference;
  SphereCircle circle;
  std::string circle_source;
};

// psm_uw_seitz/chrome: 12 photos; circle from the centroid and area of chrome.mask.tga.
RealLightSet load_psm_chrome(const std::string &shared_dir);
// harvard_psdata/<object>/LightProbe-<probe>: 20 photos; circle from circle_data.txt (bottom-left
// origin, MATLAB 1-based pixel indices, converted here).
RealLightSet load_harvard_probe(const std::string &shared_dir, const std::string &object, int probe);

// A Mitsuba scene of ../shared/scenes: photos, camera of the first raster, ground truth.
struct SceneSet {
  std::string name, dir;
  std::vector<std::string> images;                   // absolute paths, lights.lp order
  std::vector<std::string> lp_names;                 // names as written in lights.lp
  SphereCamera camera;                               // from project.mlp (first raster)
  Shot shot;
  std::vector<std::array<double, 3>> lights_cam;     // lights.lp
  bool point_lights = false;
  std::vector<std::array<double, 3>> light_pos_cam;  // point lights: positions, camera frame
  SphereCircle sphere;                               // ground-truth outline (ellipse centre, radius_px)
  double sphere_radius_world = 0;
  std::array<double, 3> sphere_centre_cam{{0, 0, 0}};
  std::vector<std::array<double, 2>> highlight_px;   // ground-truth mirror points
  // Chart.
  std::vector<std::array<double, 2>> patch_centres;  // 24, image pixels
  std::vector<std::array<float, 3>> patch_reference; // 24, linear sRGB reflectance
  double cast[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // camera response matrix A (linear)
  double exposure = 1;
};

// Loads ../shared/scenes/<name>. Throws InputError when a file is missing.
SceneSet load_scene(const std::string &shared_dir, const std::string &name);

// Names of the Mitsuba scenes present in ../shared/scenes.
std::vector<std::string> scene_names(const std::string &shared_dir);

struct Stats {
  size_t n = 0;
  double median = 0, max = 0, mean = 0;
};
Stats stats_of(std::vector<double> values);

} // namespace calib
} // namespace vbrdf
