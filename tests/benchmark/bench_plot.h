#pragma once
// Scatter plot of the benchmark (time against error) drawn with OpenCV: no plotting library is
// needed on the machine. x is logarithmic (seconds), y linear (error); points on the Pareto front
// are circled and joined.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace vbrdf {
namespace bench {

struct PlotPoint {
  std::string series;  // legend entry (one colour and marker each)
  double x = 0, y = 0; // x > 0
  bool front = false;  // on the Pareto front (circled, joined in x order within its group)
  std::string label;   // short text drawn beside front points ("" = none)
  std::string group;   // front points of one group are joined (one front per group)
};

struct PlotOptions {
  std::string title, x_label, y_label;
  int width = 1100, height = 700;
};

// Draws the plot (8-bit BGR). Points with non-finite or non-positive x are skipped.
cv::Mat draw_scatter(const std::vector<PlotPoint> &points, const PlotOptions &options);

// Reads points from a CSV with the header series,x,y,front,label[,group] (front: 0/1; no quoting:
// fields may not contain commas). Throws std::runtime_error naming the file and line.
std::vector<PlotPoint> read_plot_points(const std::string &path);

} // namespace bench
} // namespace vbrdf
