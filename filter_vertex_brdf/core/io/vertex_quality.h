#pragma once
// Vertex quality, what MeshLab's "Colorize by vertex Quality" shows: one of the fit's measures per
// vertex, for a fresh fit (run/fit_outputs.h) and for a saved result put back onto its mesh
// (result_attach.h) alike.
#include <vector>

#include "fit/reflectance_fit.h"

namespace vbrdf {

enum class QualityOutput { DQ = 0, SQ = 1, RMSE = 2 };

// The measure `quality` chooses of a fitted vertex.
inline float vertex_quality(const VertexFit &fit, QualityOutput quality) {
  return quality == QualityOutput::SQ ? fit.sq : quality == QualityOutput::RMSE ? fit.rmse : fit.dq;
}

// Vertex quality of vertices without a model (fit_status 0) and of non-finite entries: the median
// of the modelled vertices' quality (0 when none), so that in MeshLab's "Colorize by vertex
// Quality" and its histogram they neither read as the worst (DQ/SQ 0) nor as the best (RMSE 0)
// nor stretch the range. fit_status tells them apart.
void neutral_quality_for_unmodelled(const std::vector<VertexFit> &fits, std::vector<float> &quality);

} // namespace vbrdf
