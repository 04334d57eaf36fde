#pragma once
// Attaching a saved result PLY to the mesh it was fitted on ("Vertex BRDF: load result
// attributes"): MeshLab 2020.09 drops a PLY's custom properties when it opens the file, so the
// per-vertex values come back from the file by name (result_schema.h) and are checked against the
// mesh: same vertex count, same positions in the same order (the fit writes the mesh's vertices,
// deleted ones skipped, in world coordinates).
#include <cstdint>
#include <string>
#include <vector>

#include "base/mesh_view.h"
#include "io/output_ply.h"  // VertexAttribute
#include "io/result_ply.h"
#include "io/vertex_quality.h"

namespace vbrdf {

struct AttachedResult {
  std::vector<VertexAttribute> attributes;  // every schema attribute the file has, in table order
  std::vector<uint8_t> colors_rgba;         // the file's display colours (empty when it has none)
  std::vector<float> quality;               // as FitSettings::quality, neutral where unmodelled;
                                            // empty when the file has no reflectance model
  std::string missing_model_attribute;      // why quality is empty ("" otherwise)
  size_t modelled = 0;                      // vertices with fit_status != 0
  float max_position_error = 0.0f;          // largest vertex distance found (mesh units)
};

// Largest distance a vertex may lie from its counterpart: `relative` times the mesh's
// bounding-box diagonal (PLY floats and a layer matrix round positions).
constexpr float kAttachRelativeTolerance = 1e-4f;

// The result `result` (read from `path`) for `mesh`. Throws InputError naming the file and the
// mesh when the vertex counts differ, or the first vertex whose position differs by more than the
// tolerance (another mesh, an edited mesh, or another layer matrix), with the remedy.
AttachedResult attach_result(const ResultPly &result, const MeshView &mesh, const std::string &mesh_name,
                             const std::string &path, QualityOutput quality);

} // namespace vbrdf
