// Images for people: display, heat map, side-by-side panels, contact sheet (relight_images.h).
#include "relight/relight_images.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "base/color_difference.h"
#include "base/errors.h"
#include "base/number_format.h"
#include "base/file_util.h"
#include "base/output_file.h"
#include "inputs/image_codec.h"
#include "base/vec3.h"

namespace vbrdf {

// ---------------------------------------------------------------------------------------------
// Images

cv::Mat display_image(const cv::Mat &linear_rgb) {
  cv::Mat out(linear_rgb.rows, linear_rgb.cols, CV_8UC3);
  for (int y = 0; y < linear_rgb.rows; ++y) {
    const float *in = linear_rgb.ptr<float>(y);
    uint8_t *o = out.ptr<uint8_t>(y);
    for (int x = 0; x < linear_rgb.cols; ++x)
      for (int c = 0; c < 3; ++c)  // RGB -> BGR
        o[3 * x + 2 - c] = uint8_t(std::lround(255.0f * linear_to_srgb(in[3 * x + c])));
  }
  return out;
}

cv::Mat display_image(const RelitImage &render) {
  const cv::Mat wrapped(render.height, render.width, CV_32FC3, const_cast<float *>(render.rgb.data()));
  cv::Mat out = display_image(wrapped);
  // Unfitted surface in a colour no relit surface has, so that it is not mistaken for shadow.
  for (int y = 0; y < render.height; ++y)
    for (int x = 0; x < render.width; ++x)
      if (render.pixel_class[size_t(y) * size_t(render.width) + size_t(x)] == kRelitNoFit)
        out.at<cv::Vec3b>(y, x) = cv::Vec3b(110, 40, 110);
  return out;
}

cv::Mat heat_map_image(const PixelComparison &comparison, const RelitImage &render, float max_de) {
  cv::Mat grey(render.height, render.width, CV_8U, cv::Scalar(0));
  for (size_t i = 0; i < comparison.de2000.size(); ++i)
    if (comparison.de2000[i] >= 0)
      grey.data[i] =
          uint8_t(std::lround(255.0 * std::min(1.0, double(comparison.de2000[i]) / std::max(max_de, 1e-6f))));
  cv::Mat heat;
  cv::applyColorMap(grey, heat, cv::COLORMAP_TURBO);
  for (int y = 0; y < render.height; ++y)
    for (int x = 0; x < render.width; ++x) {
      const size_t i = size_t(y) * size_t(render.width) + size_t(x);
      if (i < comparison.de2000.size() && comparison.de2000[i] >= 0) continue;
      const uint8_t cls = render.pixel_class[i];
      const uint8_t v = cls == kRelitBackground ? 0 : cls == kRelitLit ? 128 : 48;
      heat.at<cv::Vec3b>(y, x) = cv::Vec3b(v, v, v);
    }
  return heat;
}

namespace {

cv::Mat placeholder(int width, int height, const std::string &text) {
  cv::Mat m(height, width, CV_8UC3, cv::Scalar(40, 40, 40));
  cv::putText(m, text, cv::Point(width / 10, height / 2), cv::FONT_HERSHEY_SIMPLEX, std::max(0.5, width / 640.0),
              cv::Scalar(200, 200, 200), 1, cv::LINE_AA);
  return m;
}

// Colour bar with ticks at 0, max/2 and max under a panel of `width` pixels.
cv::Mat colour_bar(int width, float max_de, double font) {
  const int h = int(std::lround(28 * font / 0.5)), bar_h = h / 2;
  cv::Mat strip(h, width, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::Mat ramp(1, width, CV_8U);
  for (int x = 0; x < width; ++x) ramp.at<uint8_t>(0, x) = uint8_t(255 * x / std::max(1, width - 1));
  cv::Mat colours;
  cv::applyColorMap(ramp, colours, cv::COLORMAP_TURBO);
  for (int y = 0; y < bar_h; ++y) colours.row(0).copyTo(strip.row(y));
  for (int t = 0; t <= 2; ++t) {
    const std::string text = three_significant(double(max_de) * t / 2) + (t == 2 ? " dE2000" : "");
    int base = 0;
    const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, font * 0.8, 1, &base);
    const int x = std::min(std::max(0, (width - 1) * t / 2 - size.width / 2), width - size.width);
    cv::putText(strip, text, cv::Point(x, h - 3), cv::FONT_HERSHEY_SIMPLEX, font * 0.8, cv::Scalar(230, 230, 230), 1,
                cv::LINE_AA);
  }
  return strip;
}

} // namespace

cv::Mat side_by_side(const cv::Mat &render_bgr, const cv::Mat &photo_bgr, const cv::Mat &heat_bgr,
                     const std::string &title, float max_de) {
  const cv::Mat &ref = !render_bgr.empty() ? render_bgr : !photo_bgr.empty() ? photo_bgr : heat_bgr;
  const int w = ref.empty() ? 320 : ref.cols, h = ref.empty() ? 240 : ref.rows;
  const double font = std::max(0.45, w / 1280.0);
  const int title_h = int(std::lround(30 * font / 0.5));
  const cv::Mat bar = colour_bar(w, max_de, font);
  cv::Mat out(title_h + h + bar.rows, 3 * w, CV_8UC3, cv::Scalar(0, 0, 0));
  const cv::Mat panels[3] = {render_bgr.empty() ? placeholder(w, h, "no render") : render_bgr,
                             photo_bgr.empty() ? placeholder(w, h, "no photo") : photo_bgr,
                             heat_bgr.empty() ? placeholder(w, h, "no comparison") : heat_bgr};
  const char *names[3] = {"model", "photo", "CIEDE2000"};
  for (int k = 0; k < 3; ++k) {
    cv::Mat panel;
    if (panels[k].size() == cv::Size(w, h)) panel = panels[k];
    else cv::resize(panels[k], panel, cv::Size(w, h));
    panel.copyTo(out(cv::Rect(k * w, title_h, w, h)));
    cv::putText(out, names[k], cv::Point(k * w + 6, title_h + int(22 * font / 0.5)), cv::FONT_HERSHEY_SIMPLEX, font,
                cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  cv::putText(out, title, cv::Point(6, title_h - int(8 * font / 0.5)), cv::FONT_HERSHEY_SIMPLEX, font,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  bar.copyTo(out(cv::Rect(2 * w, title_h + h, w, bar.rows)));
  return out;
}

cv::Mat contact_sheet(const std::vector<cv::Mat> &panels, int columns, int panel_width) {
  if (panels.empty()) return cv::Mat();
  columns = std::max(1, std::min(columns, int(panels.size())));
  panel_width = std::max(16, panel_width);
  std::vector<cv::Mat> scaled;
  int cell_h = 0;
  for (const cv::Mat &p : panels) {
    const int h = std::max(1, int(std::lround(double(p.rows) * panel_width / std::max(1, p.cols))));
    cv::Mat s;
    cv::resize(p, s, cv::Size(panel_width, h), 0, 0, cv::INTER_AREA);
    cell_h = std::max(cell_h, h);
    scaled.push_back(s);
  }
  const int rows = (int(scaled.size()) + columns - 1) / columns, gap = 4;
  cv::Mat sheet(rows * cell_h + (rows - 1) * gap, columns * panel_width + (columns - 1) * gap, CV_8UC3,
                cv::Scalar(24, 24, 24));
  for (size_t i = 0; i < scaled.size(); ++i) {
    const int r = int(i) / columns, c = int(i) % columns;
    scaled[i].copyTo(sheet(cv::Rect(c * (panel_width + gap), r * (cell_h + gap), panel_width, scaled[i].rows)));
  }
  return sheet;
}

void write_png_atomically(const std::string &path, const cv::Mat &image) {
  std::vector<uint8_t> bytes;
  if (!encode_png(image, bytes))
    throw ProcessingError("Cannot encode the image '" + path + "' as PNG.");
  write_text_file_atomically(path, std::string(bytes.begin(), bytes.end()));
}

} // namespace vbrdf
