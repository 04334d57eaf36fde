#pragma once
// What the mesh file itself holds, for the report: MeshLab computes per-vertex normals when it
// loads a file without them (angle-weighted average of the adjacent face normals, vcglib's
// UpdateNormal::PerVertexAngleWeighted, in meshlabserver and the GUI alike), so a filter sees
// normals either way; the user should know which ones the fit used.
#include <string>

namespace vbrdf {

enum class FileNormals { Present, Absent, Unknown };

// Reads the header of a PLY (or scans an OBJ for "vn" lines): whether it stores per-vertex
// normals. Unknown for other formats, a missing path or an unreadable file.
FileNormals normals_in_mesh_file(const std::string &path);

// One line for the log and report on where the fit's normals come from.
std::string describe_normals_source(const std::string &mesh_path);

} // namespace vbrdf
