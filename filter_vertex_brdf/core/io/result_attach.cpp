#include "io/result_attach.h"

#include <algorithm>
#include <cmath>

#include "base/errors.h"
#include "io/result_schema.h"
#include "io/vertex_quality.h"

namespace vbrdf {

namespace {

float bounding_box_diagonal(const MeshView &mesh) {
  if (mesh.vertex_count == 0) return 0.0f;
  float lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = hi[k] = mesh.positions[k];
  for (size_t v = 0; v < mesh.vertex_count; ++v)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], mesh.positions[3 * v + size_t(k)]);
      hi[k] = std::max(hi[k], mesh.positions[3 * v + size_t(k)]);
    }
  return std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                   (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

std::string point(const float *p) {
  return "(" + std::to_string(p[0]) + ", " + std::to_string(p[1]) + ", " + std::to_string(p[2]) + ")";
}

} // namespace

AttachedResult attach_result(const ResultPly &result, const MeshView &mesh, const std::string &mesh_name,
                             const std::string &path, QualityOutput quality) {
  const size_t n = mesh.vertex_count;
  const size_t file_n = result.mesh.positions.size() / 3;
  if (file_n != n)
    throw InputError("Result '" + path + "' has " + std::to_string(file_n) + " vertices but mesh '" + mesh_name +
                     "' has " + std::to_string(n) + ": it was fitted on another mesh, or the mesh was edited since. "
                     "Open the mesh the result was fitted on (its project) and load the result onto it.");
  AttachedResult out;
  const float tolerance = kAttachRelativeTolerance * std::max(bounding_box_diagonal(mesh), 1e-30f);
  for (size_t v = 0; v < n; ++v) {
    const float *a = &result.mesh.positions[3 * v], *b = &mesh.positions[3 * v];
    const float d = std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
    if (!(d <= tolerance))
      throw InputError("Result '" + path + "': vertex " + std::to_string(v) + " is at " + point(a) + " but mesh '" +
                       mesh_name + "' has it at " + point(b) + " (" + std::to_string(d) + " apart, more than " +
                       std::to_string(tolerance) + "): the result belongs to another mesh, the mesh was edited, or "
                       "the layer's transformation differs from the fit's. Load it onto the mesh it was fitted on.");
    out.max_position_error = std::max(out.max_position_error, d);
  }
  for (const ResultAttribute &a : result_schema()) {
    const auto column = result.vertex_properties.find(a.name);
    if (column == result.vertex_properties.end()) continue;
    if (column->second.size() != n)
      throw InputError("Result '" + path + "': attribute '" + a.name + "' has " + std::to_string(column->second.size()) +
                       " values for " + std::to_string(n) + " vertices (damaged file).");
    out.attributes.push_back(VertexAttribute{a.name, column->second});
  }
  if (result.mesh.colors.size() == 4 * n) out.colors_rgba = result.mesh.colors;
  out.missing_model_attribute = first_missing_model_attribute(result.vertex_properties);
  if (out.missing_model_attribute.empty()) {
    const std::vector<VertexFit> fits = fits_from_result(result, path);
    out.quality.resize(n);
    for (size_t v = 0; v < n; ++v) {
      const VertexFit &f = fits[v];
      out.quality[v] = vertex_quality(f, quality);
      out.modelled += f.status != kFitNone;
    }
    neutral_quality_for_unmodelled(fits, out.quality);
  }
  return out;
}

} // namespace vbrdf
