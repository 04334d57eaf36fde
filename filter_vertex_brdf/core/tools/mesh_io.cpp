#include "tools/mesh_io.h"

#include <vcg/complex/complex.h>
#include <vcg/complex/algorithms/update/normal.h>
#include <wrap/io_trimesh/import_ply.h>

#include "base/errors.h"
#include "base/file_util.h"

namespace vbrdf {

namespace {
class InVertex;
class InFace;
struct InTypes : public vcg::UsedTypes<vcg::Use<InVertex>::AsVertexType, vcg::Use<InFace>::AsFaceType> {};
class InVertex : public vcg::Vertex<InTypes, vcg::vertex::Coord3f, vcg::vertex::Normal3f, vcg::vertex::Color4b,
                                    vcg::vertex::BitFlags> {};
class InFace : public vcg::Face<InTypes, vcg::face::VertexRef, vcg::face::Normal3f, vcg::face::BitFlags> {};
class InMesh : public vcg::tri::TriMesh<std::vector<InVertex>, std::vector<InFace>> {};
} // namespace

MeshData load_mesh_ply(const std::string &path, bool compute_missing_normals) {
  if (!file_exists(path)) throw InputError("Mesh '" + path + "' is missing.");
  InMesh m;
  int mask = 0;
  const int err = vcg::tri::io::ImporterPLY<InMesh>::Open(m, path.c_str(), mask);
  if (err != 0 && vcg::tri::io::ImporterPLY<InMesh>::ErrorCritical(err))
    throw InputError("Mesh '" + path + "' cannot be read: " + vcg::tri::io::ImporterPLY<InMesh>::ErrorMsg(err));
  const bool has_normals = (mask & vcg::tri::io::Mask::IOM_VERTNORMAL) != 0;
  if (!has_normals && compute_missing_normals) vcg::tri::UpdateNormal<InMesh>::PerVertexNormalizedPerFace(m);

  MeshData out;
  out.positions.reserve(3 * m.vert.size());
  out.normals.reserve(3 * m.vert.size());
  const bool has_colors = (mask & vcg::tri::io::Mask::IOM_VERTCOLOR) != 0;
  for (const InVertex &v : m.vert) {
    for (int k = 0; k < 3; ++k) out.positions.push_back(v.cP()[k]);
    for (int k = 0; k < 3; ++k) out.normals.push_back(has_normals || compute_missing_normals ? v.cN()[k] : 0.0f);
    if (has_colors)
      for (int k = 0; k < 4; ++k) out.colors.push_back(v.cC()[k]);
  }
  for (const InFace &f : m.face) {
    if (f.IsD()) continue;
    for (int k = 0; k < 3; ++k) out.indices.push_back(uint32_t(vcg::tri::Index(m, f.cV(k))));
  }
  return out;
}

} // namespace vbrdf
