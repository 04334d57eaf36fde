#pragma once
// Colour-chart parts of vbrdf_calibrate (command `chart`, colour section of `report`).
#include <string>
#include <vector>

namespace vbrdf {
namespace calib {
// `chart` command: returns the process exit code.
int run_chart(const std::vector<std::string> &images, const std::vector<float> &corners, const std::string &lights,
              bool require, const std::string &exposure, const std::string &out);
// Colour section of the report; clears `ok` when a target is missed.
void report_colour(const std::string &shared_dir, bool &ok);
} // namespace calib
} // namespace vbrdf
