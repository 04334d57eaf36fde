#include "io/output_ply.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <sys/stat.h>

#include <vcg/complex/complex.h>
#include <wrap/io_trimesh/export_ply.h>

#include "base/errors.h"
#include "base/file_util.h"

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

// Bytes of the binary PLY written for `vertices`, `faces` and `attributes` float properties:
// its header (read back from the file) plus the records.
long long expected_ply_bytes(const std::string &file, size_t vertices, size_t faces, size_t attributes) {
  std::FILE *f = std::fopen(file.c_str(), "rb");
  if (!f) return -1;
  std::string head(65536, '\0');
  head.resize(std::fread(&head[0], 1, head.size(), f));
  std::fclose(f);
  const size_t end = head.find("end_header\n");
  if (end == std::string::npos) return -1;
  const long long vertex_bytes = 12 + 12 + 4 + 4 * (long long)attributes, face_bytes = 1 + 12;
  return (long long)(end + 11) + (long long)vertices * vertex_bytes + (long long)faces * face_bytes;
}
} // namespace

void stage_result_ply(AtomicOutput &out, const MeshView &mesh, const std::vector<uint8_t> &colors_rgba,
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

  const int err = vcg::tri::io::ExporterPLY<OutMesh>::Save(m, out.temporary().c_str(), true, info);
  // vcglib does not check its writes: a short file (disk full, file size limit) is found here.
  const long long expected = expected_ply_bytes(out.temporary(), mesh.vertex_count, mesh.index_count / 3, attributes.size());
  struct stat st;
  const bool complete = ::stat(out.temporary().c_str(), &st) == 0 && (long long)st.st_size == expected;
  if (err != 0 || !complete) {
    const std::string cause = err != 0 && expected < 0 && !file_exists(out.temporary())
                                  ? std::string(vcg::tri::io::ExporterPLY<OutMesh>::ErrorMsg(err)) + " (" +
                                        out.failure_cause() + ")"
                                  : out.failure_cause();
    std::remove(out.temporary().c_str());
    throw ProcessingError("Cannot write '" + out.path() + "': " + cause + ". Free space or choose another file; " +
                          (file_exists(out.path()) ? "the previous file is unchanged." : "nothing was written."));
  }
}

void write_result_ply(const std::string &path, const MeshView &mesh, const std::vector<uint8_t> &colors_rgba,
                      const std::vector<VertexAttribute> &attributes) {
  AtomicOutput out(path);
  stage_result_ply(out, mesh, colors_rgba, attributes);
  out.commit();
}

} // namespace vbrdf
