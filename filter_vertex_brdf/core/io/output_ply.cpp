#include "io/output_ply.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <unistd.h>

#include <vcg/complex/complex.h>
#include <wrap/io_trimesh/export_ply.h>

#include "base/errors.h"

namespace vbrdf {

namespace {
// A minimal vcg mesh type for writing: position, normal, colour per vertex; triangles.
class OutVertex;
class OutFace;
struct OutTypes : public vcg::UsedTypes<vcg::Use<OutVertex>::AsVertexType, vcg::Use<OutFace>::AsFaceType> {};
class OutVertex : public vcg::Vertex<OutTypes, vcg::vertex::Coord3f, vcg::vertex::Normal3f, vcg::vertex::Color4b,
                                     vcg::vertex::BitFlags> {};
class OutFace : public vcg::Face<OutTypes, vcg::face::VertexRef, vcg::face::BitFlags> {};
class OutMesh : public vcg::tri::TriMesh<std::vector<OutVertex>, std::vector<OutFace>> {};

// PlyInfo::AddPerVertexFloatAttribute must not be used: it keeps pointers to the vectors of the
// FIRST PlyInfo it ever saw in function-local statics, so a second export in the same process
// (running the filter twice in MeshLab) writes into a destroyed object. Same fields, set here.
void add_float_property(vcg::tri::io::PlyInfo &info, const std::string &name) {
  info.VertDescriptorVec.push_back(vcg::ply::PropDescriptor());
  info.VertAttrNameVec.push_back(name);
  vcg::ply::PropDescriptor &d = info.VertDescriptorVec.back();
  d.elemname = "vertex";
  d.propname = strdup(name.c_str());  // vcglib's descriptor owns a C string (freed by nobody, as in vcglib)
  d.stotype1 = vcg::ply::T_FLOAT;
  d.memtype1 = vcg::ply::T_FLOAT;
}

std::string temporary_path_for(const std::string &path) {
  return path + ".tmp" + std::to_string(::getpid());
}

void commit_temporary(const std::string &tmp, const std::string &path) {
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw ProcessingError("Cannot move the result into place at '" + path + "': check that the folder is writable.");
  }
}
} // namespace

void write_result_ply(const std::string &path, const MeshView &mesh, const std::vector<uint8_t> &colors_rgba,
                      const std::vector<VertexAttribute> &attributes) {
  if (colors_rgba.size() != 4 * mesh.vertex_count)
    throw ProcessingError("internal: colour array size does not match the mesh");
  for (const VertexAttribute &a : attributes) {
    if (a.values.size() != mesh.vertex_count)
      throw ProcessingError("internal: attribute '" + a.name + "' size does not match the mesh");
    for (size_t v = 0; v < a.values.size(); ++v)
      if (!std::isfinite(a.values[v]))
        throw ProcessingError("internal: attribute '" + a.name + "' of vertex " + std::to_string(v) +
                              " is not finite; nothing was written");
  }

  OutMesh m;
  auto vi = vcg::tri::Allocator<OutMesh>::AddVertices(m, mesh.vertex_count);
  for (size_t v = 0; v < mesh.vertex_count; ++v, ++vi) {
    vi->P() = vcg::Point3f(mesh.positions + 3 * v);
    vi->N() = vcg::Point3f(mesh.normals + 3 * v);
    vi->C() = vcg::Color4b(colors_rgba[4 * v], colors_rgba[4 * v + 1], colors_rgba[4 * v + 2], colors_rgba[4 * v + 3]);
  }
  auto fi = vcg::tri::Allocator<OutMesh>::AddFaces(m, mesh.index_count / 3);
  for (size_t f = 0; f < mesh.index_count / 3; ++f, ++fi)
    for (int k = 0; k < 3; ++k) fi->V(k) = &m.vert[mesh.indices[3 * f + k]];

  vcg::tri::io::PlyInfo info;
  info.mask = vcg::tri::io::Mask::IOM_VERTCOORD | vcg::tri::io::Mask::IOM_VERTNORMAL |
              vcg::tri::io::Mask::IOM_VERTCOLOR | vcg::tri::io::Mask::IOM_FACEINDEX;
  for (const VertexAttribute &a : attributes) {
    auto handle = vcg::tri::Allocator<OutMesh>::AddPerVertexAttribute<float>(m, a.name);
    for (size_t v = 0; v < mesh.vertex_count; ++v) handle[v] = a.values[v];
    add_float_property(info, a.name);
  }

  const std::string tmp = temporary_path_for(path);
  const int err = vcg::tri::io::ExporterPLY<OutMesh>::Save(m, tmp.c_str(), true, info);
  if (err != 0) {
    std::remove(tmp.c_str());
    throw ProcessingError("Cannot write '" + path + "': " + vcg::tri::io::ExporterPLY<OutMesh>::ErrorMsg(err) +
                          ". Check that the folder exists and is writable.");
  }
  commit_temporary(tmp, path);
}

void write_text_file_atomically(const std::string &path, const std::string &text) {
  const std::string tmp = temporary_path_for(path);
  {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    if (!out.flush()) {
      std::remove(tmp.c_str());
      throw ProcessingError("Cannot write '" + path + "': check that the folder exists and is writable.");
    }
  }
  commit_temporary(tmp, path);
}

} // namespace vbrdf
