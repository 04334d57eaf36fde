#include "bench_plot.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace vbrdf {
namespace bench {

namespace {

const cv::Scalar kPalette[] = {{180, 119, 31}, {14, 127, 255}, {44, 160, 44},  {40, 39, 214},  {189, 103, 148},
                               {75, 86, 140},  {194, 119, 227}, {127, 127, 127}, {34, 189, 188}, {207, 190, 23}};
constexpr int kPaletteSize = int(sizeof(kPalette) / sizeof(kPalette[0]));

struct Frame {
  cv::Rect area;
  double x0, x1, y0, y1;  // log10 x range, linear y range
  cv::Point map(double x, double y) const {
    const double u = (std::log10(x) - x0) / (x1 - x0), v = (y - y0) / (y1 - y0);
    return cv::Point(area.x + int(std::lround(u * area.width)), area.y + area.height - int(std::lround(v * area.height)));
  }
};

void marker(cv::Mat &img, cv::Point p, int shape, const cv::Scalar &colour) {
  const int r = 5;
  switch (shape % 4) {
  case 0: cv::circle(img, p, r, colour, cv::FILLED, cv::LINE_AA); break;
  case 1: cv::rectangle(img, p - cv::Point(r, r), p + cv::Point(r, r), colour, cv::FILLED); break;
  case 2: {
    const cv::Point tri[3] = {p + cv::Point(0, -r - 1), p + cv::Point(r + 1, r), p + cv::Point(-r - 1, r)};
    cv::fillConvexPoly(img, tri, 3, colour, cv::LINE_AA);
    break;
  }
  default: cv::drawMarker(img, p, colour, cv::MARKER_TILTED_CROSS, 2 * r + 2, 2, cv::LINE_AA);
  }
}

std::string tick_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

void put(cv::Mat &img, const std::string &text, cv::Point p, double scale = 0.5, const cv::Scalar &c = {0, 0, 0}) {
  cv::putText(img, text, p, cv::FONT_HERSHEY_SIMPLEX, scale, c, 1, cv::LINE_AA);
}

void axes(cv::Mat &img, const Frame &f, const PlotOptions &o) {
  cv::rectangle(img, f.area, cv::Scalar(0, 0, 0), 1);
  // x: 1-2-5 ticks per decade.
  for (int e = int(std::floor(f.x0)); e <= int(std::ceil(f.x1)); ++e)
    for (double m : {1.0, 2.0, 5.0}) {
      const double x = m * std::pow(10.0, e);
      if (std::log10(x) < f.x0 || std::log10(x) > f.x1) continue;
      const cv::Point p = f.map(x, f.y0);
      cv::line(img, cv::Point(p.x, f.area.y), cv::Point(p.x, f.area.y + f.area.height), cv::Scalar(225, 225, 225), 1);
      put(img, tick_text(x), cv::Point(p.x - 10, f.area.y + f.area.height + 20));
    }
  const double span = f.y1 - f.y0, step = std::pow(10.0, std::floor(std::log10(span / 4)));
  const double nice = span / step > 20 ? 5 * step : span / step > 8 ? 2 * step : step;
  for (double y = std::ceil(f.y0 / nice) * nice; y <= f.y1 + 1e-9; y += nice) {
    const cv::Point p = f.map(std::pow(10.0, f.x0), y);
    cv::line(img, cv::Point(f.area.x, p.y), cv::Point(f.area.x + f.area.width, p.y), cv::Scalar(225, 225, 225), 1);
    put(img, tick_text(std::round(y / nice) * nice), cv::Point(f.area.x - 45, p.y + 5));
  }
  cv::rectangle(img, f.area, cv::Scalar(0, 0, 0), 1);
  put(img, o.x_label, cv::Point(f.area.x + f.area.width / 2 - 120, f.area.y + f.area.height + 45), 0.6);
  put(img, o.y_label, cv::Point(10, f.area.y - 12), 0.6);
  put(img, o.title, cv::Point(f.area.x, 28), 0.7);
}

Frame make_frame(const std::vector<PlotPoint> &pts, const PlotOptions &o) {
  double xmin = 1e300, xmax = -1e300, ymax = 0;
  for (const PlotPoint &p : pts) {
    xmin = std::min(xmin, p.x), xmax = std::max(xmax, p.x);
    ymax = std::max(ymax, p.y);
  }
  Frame f;
  f.area = cv::Rect(70, 60, o.width - 70 - 260, o.height - 60 - 70);
  f.x0 = std::log10(xmin) - 0.08, f.x1 = std::log10(xmax) + 0.08;
  if (f.x1 - f.x0 < 0.5) f.x0 -= 0.25, f.x1 += 0.25;
  f.y0 = 0, f.y1 = ymax > 0 ? ymax * 1.08 : 1;
  return f;
}

} // namespace

cv::Mat draw_scatter(const std::vector<PlotPoint> &all, const PlotOptions &o) {
  std::vector<PlotPoint> pts;
  for (const PlotPoint &p : all)
    if (std::isfinite(p.x) && std::isfinite(p.y) && p.x > 0) pts.push_back(p);
  cv::Mat img(o.height, o.width, CV_8UC3, cv::Scalar(255, 255, 255));
  if (pts.empty()) {
    put(img, "no data", cv::Point(o.width / 2 - 40, o.height / 2), 0.8);
    return img;
  }
  const Frame f = make_frame(pts, o);
  axes(img, f, o);
  std::map<std::string, int> series;
  for (const PlotPoint &p : pts) series.emplace(p.series, int(series.size()));
  std::vector<PlotPoint> front;
  for (const PlotPoint &p : pts) {
    const int s = series[p.series];
    marker(img, f.map(p.x, p.y), s / kPaletteSize + s, kPalette[s % kPaletteSize]);
    if (p.front) front.push_back(p);
  }
  std::sort(front.begin(), front.end(), [](const PlotPoint &a, const PlotPoint &b) {
    return a.group != b.group ? a.group < b.group : a.x < b.x;
  });
  for (size_t i = 0; i + 1 < front.size(); ++i)
    if (front[i].group == front[i + 1].group)
      cv::line(img, f.map(front[i].x, front[i].y), f.map(front[i + 1].x, front[i + 1].y), cv::Scalar(0, 0, 0), 1,
             cv::LINE_AA);
  std::vector<cv::Rect> placed;  // labels never overlap: try a few offsets, else leave it out
  for (const PlotPoint &p : front) {
    const cv::Point at = f.map(p.x, p.y);
    cv::circle(img, at, 9, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    if (p.label.empty()) continue;
    int base = 0;
    const cv::Size size = cv::getTextSize(p.label, cv::FONT_HERSHEY_SIMPLEX, 0.42, 1, &base);
    for (const cv::Point offset : {cv::Point(10, -10), cv::Point(10, 18), cv::Point(-size.width - 10, -10),
                                   cv::Point(-size.width - 10, 18)}) {
      const cv::Rect box(at + offset - cv::Point(0, size.height), cv::Size(size.width, size.height + base));
      const bool free = std::none_of(placed.begin(), placed.end(), [&](const cv::Rect &r) { return (r & box).area() > 0; });
      if (!free) continue;
      put(img, p.label, at + offset, 0.42, cv::Scalar(60, 60, 60));
      placed.push_back(box);
      break;
    }
  }
  // Legend to the right of the frame.
  int y = f.area.y + 10;
  for (const auto &s : series) {
    marker(img, cv::Point(f.area.x + f.area.width + 25, y), s.second / kPaletteSize + s.second,
           kPalette[s.second % kPaletteSize]);
    put(img, s.first, cv::Point(f.area.x + f.area.width + 40, y + 5), 0.45);
    y += 22;
  }
  cv::circle(img, cv::Point(f.area.x + f.area.width + 25, y + 6), 9, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  put(img, "Pareto front", cv::Point(f.area.x + f.area.width + 40, y + 11), 0.45);
  return img;
}

std::vector<PlotPoint> read_plot_points(const std::string &path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::vector<PlotPoint> out;
  std::string line;
  std::getline(in, line);
  if (line.rfind("series,x,y,front", 0) != 0) throw std::runtime_error(path + ": header must be series,x,y,front,label");
  for (int n = 2; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    std::stringstream ss(line);
    std::string cells[6];
    for (std::string &c : cells) std::getline(ss, c, ',');
    try {
      PlotPoint p;
      p.series = cells[0];
      p.x = std::stod(cells[1]);
      p.y = std::stod(cells[2]);
      p.front = cells[3] == "1";
      p.label = cells[4];
      p.group = cells[5];
      out.push_back(p);
    } catch (const std::exception &) {
      throw std::runtime_error(path + ":" + std::to_string(n) + ": bad row '" + line + "'");
    }
  }
  return out;
}

} // namespace bench
} // namespace vbrdf
