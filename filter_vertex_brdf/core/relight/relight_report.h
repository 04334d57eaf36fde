#pragma once
// The relight filter's work on a set of rasters: render each under its light, compare with its
// (colour-corrected) photo, and write the images, contact sheet and table.
#include <string>
#include <vector>

#include "base/output_file.h"
#include "calibration/color_plan.h"
#include "inputs/light_source.h"
#include "inputs/photo.h"
#include "relight/relight_compare.h"
#include "relight/relight_images.h"
#include "samples/samples.h"  // ProgressFn

namespace vbrdf {

// One row of the per-raster table.
struct RelightRow {
  std::string label;     // raster label ("all" for the pooled row)
  std::string photo;     // photo path ("" for the pooled row / a novel view)
  PixelComparison comparison;     // lit visible interior pixels (compare_with_photo)
  PixelComparison whole_surface;  // whole surface (compare_whole_surface; no per-pixel map)
};
// CSV: raster,photo,pixels,mean_de2000,median_de2000,p95_de2000,psnr_db (lit visible interior
// pixels), then whole_surface_pixels, whole_surface_mean/median/p95_de2000, whole_surface_psnr_db
// (one row per entry).
std::string relight_table_csv(const std::vector<RelightRow> &rows);

// The fit corrects its samples with a ColorChecker seen in the photos (color_chart.h, when
// present); its model then predicts corrected colours. The compared photos get the same treatment:
// each viewpoint's photos are calibrated from their own chart and corrected before the comparison.

struct RelightOutputOptions {
  std::string folder;             // "" = compute the table only, write nothing
  float heat_map_max_de = 10.0f;  // CIEDE2000 at the top of the heat map colour scale
  int sheet_columns = 2;
  int sheet_panel_width = 1200;   // width of one side-by-side panel in the contact sheet
  PhotoEncoding encoding = PhotoEncoding::Auto;
  float saturation_level = kSaturationLevel;
  ColorCorrectionChoice color_correction = ColorCorrectionChoice::Auto;  // color_plan.h, as the fit's
  std::vector<float> chart_corners;  // as FitSettings::chart_corners: empty, 8, or 8 per viewpoint
  ExposureMode exposure = ExposureMode::Auto;
  // Existing files of the same names in `folder`: replaced (counted in RelightReport::replaced)
  // or the run refused before any rendering.
  OverwritePolicy overwrite = OverwritePolicy::Replace;
};

struct RelightReport {
  std::vector<RelightRow> rows;   // one per raster, in order
  RelightRow overall;             // pooled over every raster
  std::vector<std::string> files; // written files (images, contact sheet, table)
  size_t replaced = 0;            // of them, files that replaced an earlier one
  std::vector<std::string> color_log;  // per viewpoint: chart found / correction used
};


// Renders every raster's camera under its light (lights[r]),
// compares each render with the raster's photo (colour-corrected per viewpoint, see
// color_plan.h) and, when options.folder is set, writes
// relight_NNN_<label>.png (render | photo | heat map; the label without its image extension),
// contact_sheet.png and relight_table.csv
// there (creating the folder; each file atomically). Refuses (InputError) to write over a file
// the rasters read. Throws InputError naming the raster for an invalid shot or a photo that is
// missing or not the size of its viewport, for chart corners of the wrong count, and when the
// correction is Required and a viewpoint has no usable chart. `progress` may be empty; returning false cancels
// (ProcessingError "cancelled").
RelightReport relight_rasters(RelightRenderer &renderer, const std::vector<Raster> &rasters,
                              const std::vector<LightSource> &lights,
                              const RelightOutputOptions &options, const ProgressFn &progress = {});

} // namespace vbrdf
