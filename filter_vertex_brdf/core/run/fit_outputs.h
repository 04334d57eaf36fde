#pragma once
// What a fit run hands to the user: display colours, vertex quality, the PLY's attributes
// (result_schema.h) and the human-readable report. Pure functions of the run's result.
#include <string>

#include "run/fit_run.h"

namespace vbrdf {

// Fills r.colors_rgba (sRGB of the displayed reflectance where a vertex has one, else the input
// colour), r.quality (as settings.quality chooses), r.attributes and the vertex counters of r.
void build_outputs(const FitInput &input, const FitSettings &settings, FitResult &r);

// The report written beside the PLY (<ply stem>_report.txt) and logged line by line.
std::string build_report(const FitInput &input, const FitSettings &settings, const FitResult &r);

// The report's last line, once the files are staged: where the PLY went, what that did to a file
// already there, and how long writing took (FitResult::seconds_output).
std::string output_report_line(const FitResult &r);

// <folder>/<name>_report.txt for the PLY <folder>/<name>.ply.
std::string report_path_for(const std::string &ply);

} // namespace vbrdf
