#pragma once
// What a fit run hands to the user: display colours, vertex quality, the PLY's attributes
// (result_schema.h) and the human-readable report. Pure functions of the run's result.
#include <string>

#include "run/fit_run.h"

namespace vbrdf {

// Fills r.colors_rgba (sRGB of the displayed reflectance where a vertex has one, else the input
// colour), r.quality (as settings.quality chooses), r.attributes and the vertex counters of r.
void build_outputs(const FitInput &input, const FitSettings &settings, FitResult &r);

// Vertex quality of vertices without a model (fit_status 0) and of non-finite entries: the median
// of the modelled vertices' quality (0 when none), so that in MeshLab's "Colorize by vertex
// Quality" and its histogram they neither read as the worst (DQ/SQ 0) nor as the best (RMSE 0)
// nor stretch the range. fit_status tells them apart.
void neutral_quality_for_unmodelled(const std::vector<VertexFit> &fits, std::vector<float> &quality);

// The report written beside the PLY (<ply stem>_report.txt) and logged line by line.
std::string build_report(const FitInput &input, const FitSettings &settings, const FitResult &r);

// <folder>/<name>_report.txt for the PLY <folder>/<name>.ply.
std::string report_path_for(const std::string &ply);

} // namespace vbrdf
