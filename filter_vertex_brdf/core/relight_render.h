#pragma once
// Image-space relighting: renders the fitted per-vertex Phong model (phong_fit.h) with OpenGL for
// any camera (vcg::Shot) and directional light, with cast shadows from a shadow map, and compares
// the render with a photo pixel by pixel (CIEDE2000, PSNR). Also composes what users look at
// (render | photo | CIEDE2000 heat map side by side, a contact sheet) and the per-raster table.
//
// Shading is per pixel: the vertex normal and the model parameters (rho = k_d C, k_s, alpha) are
// interpolated over each triangle and the model is evaluated per fragment as evaluate_phong does
// (E from the fragment to the camera centre, R = 2(N.L)N - L). Where k_s = 0 the shininess is
// undefined (0); such vertices take the median shininess of the fitted lobes, so that a lobe fades
// with k_s across a triangle instead of widening. Lights are directional with unit irradiance, as
// in the fit: the render is in the photos' linear units.
//
// Comparison with a photo uses the "lit visible" pixels: rendered lit (N.L > 0, not in cast
// shadow), every vertex of the triangle fitted, all 8 neighbours on the same surface (no
// silhouette or depth jump: those photo pixels mix surfaces) and no clipped photo channel.
// The prediction is clipped at 1 (what a camera records) for CIEDE2000 and PSNR.
// Beside it, labelled, the whole surface (the RTI protocol): every lit or unfitted surface pixel,
// silhouettes and depth jumps included, unfitted surface predicted black; clipped pixels left out.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "camera.h"
#include "light_source.h"
#include "color_chart.h"
#include "mesh_view.h"
#include "phong_fit.h"
#include "photo.h"
#include "samples.h"
#include "visibility_gl.h"  // GetProcAddressFn

namespace vbrdf {

// Per-pixel classes of a render.
enum RelitPixel : uint8_t {
  kRelitBackground = 0,  // no surface
  kRelitLit = 1,         // lit surface with a fitted model
  kRelitShadowed = 2,    // N.L <= 0 or in cast shadow: the model predicts black
  kRelitNoFit = 3,       // a vertex of the triangle has no fit (kFitNone)
};

struct RelitImage {
  int width = 0, height = 0;
  std::vector<float> rgb;            // linear RGB, 3 per pixel, row 0 = top of the image
  std::vector<uint8_t> pixel_class;  // RelitPixel per pixel
  std::vector<float> depth;          // view depth of the surface (0 on background)
};

struct RelightRenderSettings {
  int shadow_map_size = 0;        // light-view depth map, pixels per side; 0 = automatic, as the
                                  // fit's visibility pass (resolved_shadow_map_size)
  float depth_tolerance = 0.002f; // shadow test slack, fraction of the bounding-box diagonal
};

// Renders one mesh with its per-vertex fits (one VertexFit per vertex). The mesh and the fits are
// uploaded once; each render() draws a shadow map from the light and the surface from the camera.
// Requires a current OpenGL >= 3.3 context (core or compatibility) for the object's lifetime and
// leaves the host's GL state as it was (GlStateGuard). Throws ProcessingError when the context
// cannot run the passes, InputError for a fit count that does not match the mesh, a bad index or
// a negative shadow map size.
class RelightRenderer {
public:
  RelightRenderer(const MeshView &mesh, const std::vector<VertexFit> &fits, const GetProcAddressFn &get_proc,
                  const RelightRenderSettings &settings = RelightRenderSettings());
  ~RelightRenderer();
  RelightRenderer(const RelightRenderer &) = delete;
  RelightRenderer &operator=(const RelightRenderer &) = delete;

  // Renders the viewport of `shot` (no lens distortion) lit by `light` (directional, or a point
  // light with its per-fragment direction and fall-off, light_source.h), with cast shadows from
  // light_view.h's shadow map. Throws InputError for an invalid shot, a zero light direction or a
  // point light within the mesh's bounding sphere, ProcessingError when the viewport exceeds the
  // GL limits.
  RelitImage render(const Shot &shot, const LightSource &light);

  const char *renderer_name() const;  // GL_RENDERER, for logs

private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

// The model's image as the camera of `shot` records it: rendered with up to `max_scale` x
// `max_scale` subpixels per photo pixel (fewer for large photos: at most 2^23 subpixels, and
// within the GL size limits) and box-filtered back to the photo's size, as a sensor pixel
// integrates the light over its area, so that silhouettes and contacts are partly covered as in
// a photo. CV_32FC3 linear RGB, row 0 = top, the shot's size; background and shadow 0.
cv::Mat render_as_photographed(RelightRenderer &renderer, const Shot &shot, const LightSource &light,
                               int max_scale = 4);

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

// The photo as linear RGB floats (CV_32FC3, RGB order, row 0 = top) and its clipped pixels
// (CV_8U, 255 where a channel is at or above the photo's saturation code).
void photo_to_linear(const Photo &photo, cv::Mat &linear_rgb, cv::Mat &clipped);

// Compares `render` with the photo (linear, same size; see photo_to_linear) over the lit visible
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

// Images for people (8-bit BGR, OpenCV's channel order, ready for cv::imwrite):
// linear RGB (CV_32FC3 RGB or a RelitImage) -> sRGB, clipped to [0, 1]; a render's unfitted
// surface (kRelitNoFit) is shown dark magenta.
cv::Mat display_image(const cv::Mat &linear_rgb);
cv::Mat display_image(const RelitImage &render);
// CIEDE2000 in [0, max_de] through the "turbo" colour map; pixels not compared: background black,
// shadowed / unfitted surface dark grey, lit but excluded (silhouette, clipped) mid grey.
cv::Mat heat_map_image(const PixelComparison &comparison, const RelitImage &render, float max_de);
// render | photo | heat map (any may be empty: a grey "no photo" panel), with a title line above
// and a colour bar for the heat map below.
cv::Mat side_by_side(const cv::Mat &render_bgr, const cv::Mat &photo_bgr, const cv::Mat &heat_bgr,
                     const std::string &title, float max_de);
// Panels scaled to `panel_width` pixels and laid out in `columns` columns (row height = tallest).
cv::Mat contact_sheet(const std::vector<cv::Mat> &panels, int columns, int panel_width);

// Writes a PNG atomically (temporary file, then rename). Throws ProcessingError naming the path.
void write_png_atomically(const std::string &path, const cv::Mat &image);

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
enum class RelightColorCorrection { Off = 0, Auto = 1, Required = 2 };  // as the fit's colorCorrection

struct RelightOutputOptions {
  std::string folder;             // "" = compute the table only, write nothing
  float heat_map_max_de = 10.0f;  // CIEDE2000 at the top of the heat map colour scale
  int sheet_columns = 2;
  int sheet_panel_width = 1200;   // width of one side-by-side panel in the contact sheet
  PhotoEncoding encoding = PhotoEncoding::Auto;
  float saturation_level = 0.99f;
  RelightColorCorrection color_correction = RelightColorCorrection::Auto;
  std::vector<float> chart_corners;  // as FitSettings::chart_corners: empty, 8, or 8 per viewpoint
  ExposureMode exposure = ExposureMode::Auto;
};

struct RelightReport {
  std::vector<RelightRow> rows;   // one per raster, in order
  RelightRow overall;             // pooled over every raster
  std::vector<std::string> files; // written files (images, contact sheet, table)
  std::vector<std::string> color_log;  // per viewpoint: chart found / correction used
};

// Rasters grouped by viewpoint (identical shots), groups in order of their first raster.
std::vector<std::vector<size_t>> relight_viewpoints(const std::vector<Raster> &rasters);

// Renders every raster's camera under its light (lights[r]),
// compares each render with the raster's photo (colour-corrected per viewpoint, see
// RelightColorCorrection) and, when options.folder is set, writes
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

// A new viewpoint from an existing camera: orbits it around `pivot` by `azimuth_deg` about the
// camera's up axis (positive: the camera moves to its right) and `elevation_deg` about its right
// axis (positive: upwards), then scales its distance to the pivot by `distance_scale` (> 0).
// Intrinsics are kept. Throws InputError for a non-positive or non-finite scale.
Shot orbit_shot(const Shot &base, const float pivot[3], float azimuth_deg, float elevation_deg, float distance_scale);

// Characters of a raster label that are safe in a file name ("a b/c.png" -> "a_b_c.png").
std::string file_safe_label(const std::string &label);

} // namespace vbrdf
