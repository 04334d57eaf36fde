#pragma once
// Mesh helpers of the benchmark: quadric-edge-collapse decimation (vcglib, as MeshLab's
// "Simplification: Quadric Edge Collapse Decimation") and nearest-vertex transfer of per-vertex
// ground truth onto a decimated mesh; a mesh resampled onto a decimated copy of itself.
#include <cstddef>
#include <vector>

#include "base/mesh_view.h"

namespace vbrdf {
namespace bench {

// Decimates `in` to at most `target_vertices` vertices (quality threshold 0.3, boundaries kept,
// no normal flips, optimal vertex placement), then recomputes area-weighted vertex normals.
// Returns the input unchanged when it already has no more vertices than the target.
MeshData decimate(const MeshData &in, size_t target_vertices);

// For every vertex of `to`, the index of the nearest vertex of `from` (uniform grid, exact).
std::vector<size_t> nearest_vertices(const MeshView &from, const MeshView &to);

// Moves every vertex of `mesh` to the closest point of `surface` (vcglib's uniform grid) and gives
// it `surface`'s vertex normals interpolated there (barycentric): `mesh`'s own vertices and faces
// with the geometry of `surface`, e.g. of its decimated copy. `surface` needs faces and vertex
// normals (throws otherwise). Returns how far each vertex moved.
std::vector<float> resample_onto(const MeshData &surface, MeshData &mesh);

} // namespace bench
} // namespace vbrdf
