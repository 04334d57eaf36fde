#pragma once
// What users look at: renders and photos for display, CIEDE2000 heat maps, render | photo | heat
// map panels and contact sheets, written as PNG atomically.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "relight/relight_compare.h"

namespace vbrdf {

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

} // namespace vbrdf
