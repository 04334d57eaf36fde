#pragma once
// Small scenes built in code for unit tests: shots and meshes.
#include "inputs/camera.h"
#include "base/mesh_view.h"

namespace vbrdf {
namespace test {

// Perspective shot at `centre` looking at `target` (world up `up`), focal length in pixels,
// principal point at the image centre unless given (VCG pixels, y up).
Shot make_look_at_shot(const float centre[3], const float target[3], const float up[3], float focal_px, int width,
                       int height, float cx = -1, float cy = -1);

// A flat n x n grid in the plane y = height spanning [-half, half] in x and z, normals +y.
MeshData make_grid(int n, float half, float height);

// A UV sphere (outward normals).
MeshData make_sphere(const float centre[3], float radius, int rings, int segments);

// A unit sphere of about `target_vertices` vertices whose normals carry a deterministic bump
// pattern (a normal field that is not trivially smooth): the benchmarks' light-suggestion mesh.
MeshData make_bumpy_sphere(size_t target_vertices);

// Appends b to a (indices shifted).
void append_mesh(MeshData &a, const MeshData &b);

} // namespace test
} // namespace vbrdf
