#include "inputs/mesh_file.h"

#include <fstream>
#include <sstream>

#include "base/file_util.h"

namespace vbrdf {

FileNormals normals_in_mesh_file(const std::string &path) {
  const std::string ext = extension_of(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) return FileNormals::Unknown;
  std::string line;
  if (ext == "ply") {
    bool in_vertex = false;
    for (int i = 0; i < 10000 && std::getline(in, line); ++i) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      std::istringstream words(line);
      std::string w, type, name;
      words >> w;
      if (w == "end_header") return FileNormals::Absent;
      if (w == "element") {
        words >> name;
        in_vertex = name == "vertex";
      } else if (w == "property" && in_vertex) {
        words >> type;
        if (type == "list") words >> type >> type;
        words >> name;
        if (name == "nx") return FileNormals::Present;
      }
    }
    return FileNormals::Unknown;
  }
  if (ext == "obj") {
    while (std::getline(in, line))
      if (line.compare(0, 3, "vn ") == 0) return FileNormals::Present;
    return FileNormals::Absent;
  }
  return FileNormals::Unknown;
}

std::string describe_normals_source(const std::string &mesh_path) {
  switch (normals_in_mesh_file(mesh_path)) {
  case FileNormals::Present: return "normals: the per-vertex normals the mesh file stores";
  case FileNormals::Absent:
    return "normals: the mesh file '" + file_name_of(mesh_path) +
           "' has none; MeshLab computed them when loading it, from the faces (angle-weighted average of "
           "the adjacent face normals). For sharp edges or a scanner's own normals, load a mesh that stores them.";
  case FileNormals::Unknown: break;
  }
  return "normals: the mesh's per-vertex normals (as MeshLab holds them)";
}

} // namespace vbrdf
