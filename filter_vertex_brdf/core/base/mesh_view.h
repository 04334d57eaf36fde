#pragma once
// A read-only view of a triangle mesh as plain arrays owned by the caller (the plugin maps CMeshO
// onto it, tests and tools build it from vectors). Positions and normals are xyz float triples.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace vbrdf {

struct MeshView {
  const float *positions = nullptr;  // vertex_count * 3, world coordinates
  const float *normals = nullptr;    // vertex_count * 3, unit length (zero = no normal)
  size_t vertex_count = 0;
  const uint32_t *indices = nullptr; // index_count = 3 * triangle count
  size_t index_count = 0;
};

// Owning storage for a mesh, with a view onto it.
struct MeshData {
  std::vector<float> positions;
  std::vector<float> normals;
  std::vector<uint32_t> indices;
  std::vector<uint8_t> colors;       // optional RGBA8 per vertex (sRGB), empty if none

  MeshView view() const {
    MeshView v;
    v.positions = positions.data();
    v.normals = normals.data();
    v.vertex_count = positions.size() / 3;
    v.indices = indices.data();
    v.index_count = indices.size();
    return v;
  }
};

// Axis-aligned bounds of the vertices: min[3], max[3]. Empty mesh gives min > max.
struct Bounds {
  float min[3] = {1e30f, 1e30f, 1e30f};
  float max[3] = {-1e30f, -1e30f, -1e30f};
  float diagonal() const;
  std::array<float, 3> centre() const;  // (0, 0, 0) for an empty mesh
};
Bounds compute_bounds(const MeshView &mesh);

// Throws InputError naming the first bad vertex when a normal is missing (zero) or not finite,
// or when the mesh has no vertex / no triangle. `mesh_name` is used in messages.
void validate_mesh(const MeshView &mesh, const std::string &mesh_name);

} // namespace vbrdf
