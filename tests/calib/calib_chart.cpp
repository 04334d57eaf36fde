#include "calib_chart.h"

#include <cmath>
#include <cstdio>
#include <dirent.h>
#include <random>

#include <opencv2/imgcodecs.hpp>

#include "calib_data.h"
#include "calibration/color_chart.h"
#include "base/color_difference.h"
#include "base/errors.h"
#include "inputs/light_file.h"

namespace vbrdf {
namespace calib {

namespace {

cv::Mat load_linear(const std::string &path) { return linear_rgb_image(read_image(path), true); }

std::string base_name(const std::string &p) {
  const size_t s = p.find_last_of('/');
  return s == std::string::npos ? p : p.substr(s + 1);
}

void write_correction(const std::string &path, const ColorCalibration &c, const std::vector<std::string> &images) {
  cv::FileStorage fs(path, cv::FileStorage::WRITE);
  if (!fs.isOpened()) throw ProcessingError("Cannot write '" + path + "'");
  fs << "model" << correction_model_name(c.correction.model);
  fs << "matrix" << cv::Mat(3, 3, CV_64F, const_cast<double *>(&c.correction.matrix[0][0]));
  fs << "polynomial" << cv::Mat(3, 4, CV_64F, const_cast<double *>(&c.correction.poly[0][0]));
  fs << "tone_curve" << cv::Mat(1, 3, CV_64F, const_cast<double *>(c.correction.curve));
  fs << "tone_curve_range" << cv::Vec2d(c.correction.curve_lo, c.correction.curve_hi);
  fs << "photos" << "[";
  for (size_t i = 0; i < images.size(); ++i) fs << "{" << "image" << images[i] << "divisor" << c.divisor[i] << "}";
  fs << "]";
}

// Light directions for the photos from an .lp (zero vector where the .lp has none).
std::vector<std::array<double, 3>> lights_for(const std::string &lp, const std::vector<std::string> &images) {
  const std::vector<LightEntry> entries = read_light_file(lp);
  std::vector<std::array<double, 3>> out;
  for (const auto &img : images) {
    const int k = find_light_for_image(entries, img);
    if (k < 0) out.push_back({{0, 0, 0}});
    else out.push_back({{entries[k].dir_cam[0], entries[k].dir_cam[1], entries[k].dir_cam[2]}});
  }
  return out;
}

std::vector<std::string> files_in(const std::string &dir) {
  std::vector<std::string> out;
  if (DIR *d = opendir(dir.c_str())) {
    while (dirent *e = readdir(d)) {
      const std::string n = e->d_name;
      const size_t dot = n.find_last_of('.');
      const std::string ext = dot == std::string::npos ? "" : n.substr(dot);
      if (ext == ".jpg" || ext == ".jpeg" || ext == ".png" || ext == ".JPG") out.push_back(dir + "/" + n);
    }
    closedir(d);
  }
  std::sort(out.begin(), out.end());
  return out;
}

double best_heldout(const CorrectionFit &f) {
  return std::min({f.heldout_matrix, f.heldout_curve_matrix, f.heldout_polynomial});
}

// Mean CIEDE2000 between object pixels of a corrected cast photo and the cast-free linear render
// (divided by the render's exposure): the correction's effect beyond the chart.
double object_pixels_de(const ColorCalibration &c, size_t photo, const std::string &cast_path,
                        const std::string &linear_path, double exposure) {
  const cv::Mat cast = load_linear(cast_path), lin = load_linear(linear_path);
  if (cast.size() != lin.size()) return -1;
  std::mt19937 rng(7);
  double sum = 0;
  int n = 0;
  for (int tries = 0; tries < 200000 && n < 3000; ++tries) {
    const int x = int(rng() % unsigned(cast.cols)), y = int(rng() % unsigned(cast.rows));
    const cv::Vec3f t = lin.at<cv::Vec3f>(y, x) / float(exposure), v = cast.at<cv::Vec3f>(y, x);
    const double lum = 0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2];
    if (lum < 0.05 || v[0] >= 0.99f || v[1] >= 0.99f || v[2] >= 0.99f) continue;  // 8-bit noise, clipping
    float rgb[3] = {v[0], v[1], v[2]};
    apply_color_calibration(c, photo, rgb);
    const float truth[3] = {t[0], t[1], t[2]};
    sum += delta_e2000_linear_srgb(rgb, truth);
    ++n;
  }
  return n ? sum / n : -1;
}

} // namespace

int run_chart(const std::vector<std::string> &images, const std::vector<float> &corners, const std::string &lights,
              bool require, const std::string &exposure, const std::string &out) {
  if (images.empty()) throw InputError("chart: no photos (--images)");
  ColorSettings s;
  s.require_chart = require;
  if (corners.size() == 8) {
    s.manual = true;
    std::copy(corners.begin(), corners.end(), s.corners);
  }
  s.exposure = exposure == "on" ? ExposureMode::On : exposure == "off" ? ExposureMode::Off : ExposureMode::Auto;
  std::vector<std::string> names;
  for (const auto &p : images) names.push_back(base_name(p));
  std::vector<std::array<double, 3>> dirs;
  if (!lights.empty()) dirs = lights_for(lights, images);
  const ColorCalibration c = calibrate_colors(
      images.size(), [&](size_t i) { return load_linear(images[i]); }, s, lights.empty() ? nullptr : &dirs, names);
  for (const auto &line : c.log) std::printf("%s\n", line.c_str());
  if (c.corrected) {
    for (size_t i = 0; i < images.size(); ++i) std::printf("%s divisor %.5f\n", names[i].c_str(), c.divisor[i]);
    if (!out.empty()) {
      write_correction(out, c, names);
      std::printf("Wrote %s.\n", out.c_str());
    }
  }
  return c.corrected || !require ? 0 : 1;
}

void report_colour(const std::string &shared, bool &ok) {
  std::printf("\n### Colour correction: real ColorChecker photos (one photo each, published ColorChecker "
              "reference)\n\n");
  std::printf("| photo | chart | patches | dE2000 before | after (fit) | best held-out | chosen model |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  const std::string root = shared + "/real/colorchecker";
  for (const char *sub : {"mindvision_luimoli", "plantcv", "wikimedia_pd_via_optrace", "spydercheckr24_phone_crystaldust"}) {
    for (const std::string &path : files_in(root + "/" + sub)) {
      const std::string name = std::string(sub) + "/" + base_name(path);
      const bool spyder = std::string(sub).find("spyder") == 0;
      const ColorCalibration c = calibrate_colors(1, [&](size_t) { return load_linear(path); }, ColorSettings{});
      if (!c.corrected) {
        std::printf("| %s | not found | - | - | - | - | - |\n", name.c_str());
        continue;
      }
      std::printf("| %s | %s | %d | %.2f | %.2f | %.2f | %s |\n", name.c_str(),
                  spyder ? "SpyderCheckr 24 (other layout: not comparable)" : "found", c.fit.patches, c.fit.before,
                  c.fit.after, best_heldout(c.fit), correction_model_name(c.correction.model));
    }
  }

  std::printf("\n### Colour correction: Mitsuba scenes (images/ carry a known cast; reference = the scene's "
              "chart)\n\n");
  std::printf("| scene | patches | dE2000 before | after (fit) | held-out: matrix / curve+matrix / polynomial | "
              "chosen | exposure | object pixels vs linear/ |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const std::string &name : scene_names(shared)) {
    const SceneSet sc = load_scene(shared, name);
    PatchColors ref;
    for (int k = 0; k < kChartPatches; ++k) ref[k] = sc.patch_reference[k];
    ColorSettings s;
    s.reference = &ref;
    const ColorCalibration c =
        calibrate_colors(sc.images.size(), [&](size_t i) { return load_linear(sc.images[i]); }, s, &sc.lights_cam);
    if (!c.corrected) {
      std::printf("| %s | chart not found | | | | | | |\n", name.c_str());
      ok = false;
      continue;
    }
    std::string lin = sc.images[0];
    lin.replace(lin.find("/images/"), 8, "/linear/");
    const double obj = object_pixels_de(c, 0, sc.images[0], lin, sc.exposure);
    std::printf("| %s | %d | %.2f | %.2f | %.2f / %.2f / %.2f | %s | %s | %.2f |\n", name.c_str(), c.fit.patches,
                c.fit.before, c.fit.after, c.fit.heldout_matrix, c.fit.heldout_curve_matrix,
                c.fit.heldout_polynomial, correction_model_name(c.correction.model),
                c.exposure_normalised ? "normalised per photo" : "one for all photos", obj);
    if (!(c.fit.after < 2.0)) {
      ok = false;
      std::printf("  MISSED: %s: patch dE2000 after correction %.2f (target < 2)\n", name.c_str(), c.fit.after);
    }
  }
}

} // namespace calib
} // namespace vbrdf
