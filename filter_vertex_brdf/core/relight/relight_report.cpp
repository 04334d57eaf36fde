// The relight filter's per-raster loop, table and files (relight_report.h).
#include "relight/relight_report.h"

#include <QDir>

#include "relight/orbit_camera.h"

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
#include "base/output_file.h"
#include "base/vec3.h"

namespace vbrdf {

// ---------------------------------------------------------------------------------------------
// Tables and the per-raster loop

namespace {

std::string csv_field(const std::string &s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}


struct RasterImages {
  cv::Mat render, photo, heat;
};

void ensure_folder(const std::string &folder) {
  if (!QDir().mkpath(QString::fromStdString(folder)))
    throw ProcessingError("Cannot create the output folder '" + folder + "': check the path and permissions.");
}

// Output paths of every file relight_rasters writes, checked against the inputs.
std::vector<std::string> output_paths(const std::vector<Raster> &rasters, const std::string &folder) {
  std::vector<std::string> paths;
  for (size_t r = 0; r < rasters.size(); ++r) {
    char prefix[32];
    std::snprintf(prefix, sizeof prefix, "relight_%03zu_", r);
    std::string label = rasters[r].label;  // "light_007.png" -> relight_007_light_007.png
    const size_t dot = label.find_last_of('.');
    if (dot != std::string::npos && dot > 0 && label.size() - dot <= 5) label.erase(dot);
    paths.push_back(join_path(folder, prefix + file_safe_label(label) + ".png"));
  }
  paths.push_back(join_path(folder, "contact_sheet.png"));
  paths.push_back(join_path(folder, "relight_table.csv"));
  for (const std::string &p : paths)
    for (const Raster &r : rasters)
      if (p == r.image_path)
        throw InputError("The relighting output '" + p + "' would overwrite the photo of raster '" + r.label +
                         "': choose another output folder.");
  return paths;
}

// The raster's photo as linear RGB and its clipped pixels; InputError names the raster.
void load_linear(const Raster &raster, const RelightOutputOptions &options, cv::Mat &linear, cv::Mat &clipped) {
  Photo photo;
  try {
    photo = load_photo(raster.image_path, options.encoding, options.saturation_level, raster.width(), raster.height());
  } catch (const InputError &e) {
    throw InputError("Raster '" + raster.label + "': " + e.what());
  }
  linear = photo_linear_rgb(photo, &clipped);
}

// Calibrates each viewpoint from the chart in its photos, as the fit does (color_plan.h).
ColorPlan plan_colors(const std::vector<Raster> &rasters, const std::vector<std::array<float, 3>> &lights_world,
                      const RelightOutputOptions &options, std::vector<std::string> &log) {
  ColorCorrectionSettings cs;
  cs.choice = options.color_correction;
  cs.exposure = options.exposure;
  cs.chart_corners = options.chart_corners;
  const auto load = [&](size_t r) {
    cv::Mat linear, clipped;
    load_linear(rasters[r], options, linear, clipped);
    return linear;
  };
  return plan_color_correction(rasters, lights_world, cs, load, [&](const std::string &line) { log.push_back(line); });
}

PixelComparison relight_one(RelightRenderer &renderer, const Raster &raster, const LightSource &light,
                            const RelightOutputOptions &options, const ColorCalibration *color, size_t color_photo,
                            RasterImages *images, PixelComparison *whole_surface) {
  if (!shot_is_valid(raster.shot))
    throw InputError("Raster '" + raster.label + "' has no valid camera: check its <VCGCamera> in the project.");
  cv::Mat linear, clipped;
  load_linear(raster, options, linear, clipped);
  if (color) {  // as the fit corrects its samples: corrected = M(rgb / exposure), no negative light
    linear = apply_color_calibration(*color, color_photo, linear);
    cv::max(linear, 0.0, linear);
  }
  const RelitImage render = renderer.render(raster.shot, light);
  const float focal_px = raster.shot.Intrinsics.FocalMm / raster.shot.Intrinsics.PixelSizeMm[0];
  PixelComparison c = compare_with_photo(render, linear, clipped, focal_px);
  if (whole_surface) {
    *whole_surface = compare_whole_surface(render, linear, clipped);
    whole_surface->de2000.clear();
    whole_surface->de2000.shrink_to_fit();
  }
  if (images) {
    images->render = display_image(render);
    images->photo = display_image(linear);
    images->heat = heat_map_image(c, render, options.heat_map_max_de);
  }
  return c;
}

std::string title_of(const RelightRow &row) {
  const PixelComparison &c = row.comparison;
  if (c.pixels == 0) return row.label + ": no lit visible pixel to compare";
  return row.label + ": CIEDE2000 mean " + fixed(c.mean_de2000, 2) + ", p95 " + fixed(c.p95_de2000, 2) + ", PSNR " +
         fixed(c.psnr_db, 1) + " dB over " + std::to_string(c.pixels) + " lit pixels";
}

} // namespace

std::string relight_table_csv(const std::vector<RelightRow> &rows) {
  std::ostringstream out;
  out << "raster,photo,pixels,mean_de2000,median_de2000,p95_de2000,psnr_db,"
         "whole_surface_pixels,whole_surface_mean_de2000,whole_surface_median_de2000,whole_surface_p95_de2000,"
         "whole_surface_psnr_db\n";
  for (const RelightRow &r : rows) {
    const PixelComparison &c = r.comparison, &w = r.whole_surface;
    out << csv_field(r.label) << ',' << csv_field(r.photo) << ',' << c.pixels << ',' << fixed(c.mean_de2000, 4) << ','
        << fixed(c.median_de2000, 4) << ',' << fixed(c.p95_de2000, 4) << ',' << fixed(c.psnr_db, 3) << ','
        << w.pixels << ',' << fixed(w.mean_de2000, 4) << ',' << fixed(w.median_de2000, 4) << ','
        << fixed(w.p95_de2000, 4) << ',' << fixed(w.psnr_db, 3) << '\n';
  }
  return out.str();
}

RelightReport relight_rasters(RelightRenderer &renderer, const std::vector<Raster> &rasters,
                              const std::vector<LightSource> &lights,
                              const RelightOutputOptions &options, const ProgressFn &progress) {
  if (lights.size() != rasters.size())
    throw ProcessingError("internal: " + std::to_string(lights.size()) + " lights for " +
                          std::to_string(rasters.size()) + " rasters");
  const bool write = !options.folder.empty();
  std::vector<std::string> paths;
  if (write) {
    paths = output_paths(rasters, options.folder);
    ensure_folder(options.folder);
  }
  RelightReport report;
  for (const std::string &p : paths)
    report.replaced += check_output_path(p, options.overwrite, "Output folder") != "new file";
  const ColorPlan colors = plan_colors(rasters, light_directions(lights), options, report.color_log);
  std::vector<cv::Mat> panels;
  for (size_t r = 0; r < rasters.size(); ++r) {
    if (progress && !progress(float(r) / float(std::max<size_t>(1, rasters.size())), "relighting"))
      throw ProcessingError("cancelled");
    RasterImages images;
    RelightRow row;
    row.label = rasters[r].label;
    row.photo = rasters[r].image_path;
    const size_t color_photo = colors.photo_of.empty() ? 0 : colors.photo_of[r];  // empty when Off
    row.comparison = relight_one(renderer, rasters[r], lights[r], options, colors.of_raster(r), color_photo,
                                 write ? &images : nullptr, &row.whole_surface);
    if (write) {
      panels.push_back(side_by_side(images.render, images.photo, images.heat, title_of(row), options.heat_map_max_de));
      write_png_atomically(paths[r], panels.back());
      report.files.push_back(paths[r]);
    }
    row.comparison.de2000.clear();  // the per-pixel map is only needed for the image
    row.comparison.de2000.shrink_to_fit();
    report.rows.push_back(std::move(row));
  }
  std::vector<const PixelComparison *> parts;
  for (const RelightRow &row : report.rows) parts.push_back(&row.comparison);
  report.overall.label = "all";
  report.overall.comparison = pool_comparisons(parts);
  std::vector<const PixelComparison *> whole_parts;
  for (const RelightRow &row : report.rows) whole_parts.push_back(&row.whole_surface);
  report.overall.whole_surface = pool_comparisons(whole_parts);
  if (write) {
    write_png_atomically(paths[rasters.size()],
                         contact_sheet(panels, options.sheet_columns, options.sheet_panel_width));
    std::vector<RelightRow> table = report.rows;
    table.push_back(report.overall);
    write_text_file_atomically(paths[rasters.size() + 1], relight_table_csv(table));
    report.files.push_back(paths[rasters.size()]);
    report.files.push_back(paths[rasters.size() + 1]);
  }
  if (progress) progress(1.0f, "relighting");
  return report;
}

} // namespace vbrdf
