#include "base/mesh_view.h"

#include <algorithm>
#include <cmath>

#include "base/errors.h"

namespace vbrdf {

float Bounds::diagonal() const {
  if (min[0] > max[0]) return 0;
  const float dx = max[0] - min[0], dy = max[1] - min[1], dz = max[2] - min[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

std::array<float, 3> Bounds::centre() const {
  if (min[0] > max[0]) return {{0, 0, 0}};
  return {{0.5f * (min[0] + max[0]), 0.5f * (min[1] + max[1]), 0.5f * (min[2] + max[2])}};
}

Bounds compute_bounds(const MeshView &mesh) {
  Bounds b;
  for (size_t v = 0; v < mesh.vertex_count; ++v)
    for (int k = 0; k < 3; ++k) {
      b.min[k] = std::min(b.min[k], mesh.positions[3 * v + k]);
      b.max[k] = std::max(b.max[k], mesh.positions[3 * v + k]);
    }
  return b;
}

void validate_mesh(const MeshView &mesh, const std::string &name) {
  if (mesh.vertex_count == 0)
    throw InputError("Mesh '" + name + "' has no vertices: load the scanned mesh of the project.");
  if (mesh.index_count < 3)
    throw InputError("Mesh '" + name + "' has no triangles: visibility and shadows need a triangle mesh "
                     "(reconstruct a surface first).");
  if (!mesh.normals)
    throw InputError("Mesh '" + name + "' has no per-vertex normals: run 'Re-Compute Vertex Normals' "
                     "(or load a mesh with normals) first.");
  for (size_t v = 0; v < mesh.vertex_count; ++v) {
    const float *p = mesh.positions + 3 * v, *n = mesh.normals + 3 * v;
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw InputError("Mesh '" + name + "': vertex " + std::to_string(v) + " has a non-finite position.");
    const float len2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    if (!std::isfinite(len2) || len2 < 1e-12f)
      throw InputError("Mesh '" + name + "': vertex " + std::to_string(v) +
                       " has no normal (zero or invalid): run 'Re-Compute Vertex Normals' first.");
  }
  for (size_t i = 0; i < mesh.index_count; ++i)
    if (mesh.indices[i] >= mesh.vertex_count)
      throw InputError("Mesh '" + name + "': face " + std::to_string(i / 3) + " references vertex " +
                       std::to_string(mesh.indices[i]) + " which does not exist.");
}

} // namespace vbrdf
