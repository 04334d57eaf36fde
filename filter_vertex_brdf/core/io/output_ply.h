#pragma once
// Output PLY: the input geometry (never changed) with per-vertex results as named properties any
// PLY reader sees, written atomically (base/output_file.h: temporary file in the same folder, checked
// complete, then renamed), so a partial file is never left under the final name.
#include <string>
#include <vector>

#include "base/mesh_view.h"
#include "base/output_file.h"

namespace vbrdf {

struct VertexAttribute {
  std::string name;            // PLY property name
  std::vector<float> values;   // one per vertex
};

// Writes a binary little-endian PLY with x y z, nx ny nz, red green blue alpha (uchar, from
// `colors_rgba`, which must have 4 * vertex_count entries), faces, and every attribute as a float
// property. Throws ProcessingError (naming the path) on I/O failure or when an attribute holds a
// NaN/Inf (the caller must have replaced them by documented sentinels).
void write_result_ply(const std::string &path, const MeshView &mesh, const std::vector<uint8_t> &colors_rgba,
                      const std::vector<VertexAttribute> &attributes);
// The same, into out.temporary() only, checked complete (a short file, e.g. disk full, throws
// ProcessingError naming the cause); out.commit() then puts it in place.
void stage_result_ply(AtomicOutput &out, const MeshView &mesh, const std::vector<uint8_t> &colors_rgba,
                      const std::vector<VertexAttribute> &attributes);

} // namespace vbrdf
