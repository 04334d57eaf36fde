// The benchmark's mesh helpers: a mesh resampled onto a decimated copy of itself keeps its vertices
// and faces, lies on the coarser surface, and takes that surface's (coarser) normals.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "bench_mesh.h"
#include "test_scenes.h"

using namespace vbrdf;

namespace {

double angle_degrees(const float *a, const float *b) {
  const double c = double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2];
  return std::acos(std::fmax(-1.0, std::fmin(1.0, c))) * 180.0 / M_PI;
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
  return v[v.size() / 2];
}

} // namespace

TEST(BenchMesh, ResampledOntoItselfIsUnchanged) {
  const float centre[3] = {0, 0, 0};
  const MeshData sphere = test::make_sphere(centre, 1.0f, 24, 48);
  MeshData copy = sphere;
  const std::vector<float> moved = bench::resample_onto(sphere, copy);
  ASSERT_EQ(moved.size(), sphere.positions.size() / 3);
  for (size_t k = 0; k < moved.size(); ++k) EXPECT_LT(moved[k], 1e-5f) << "vertex " << k;
  for (size_t k = 0; k < sphere.normals.size() / 3; ++k)
    EXPECT_LT(angle_degrees(&copy.normals[3 * k], &sphere.normals[3 * k]), 0.05) << "vertex " << k;
}

TEST(BenchMesh, ResampledOntoDecimatedCopyLiesOnItWithItsNormals) {
  const float centre[3] = {0, 0, 0};
  const MeshData sphere = test::make_sphere(centre, 1.0f, 40, 80);
  const size_t n = sphere.positions.size() / 3;
  const MeshData coarse = bench::decimate(sphere, n / 4);
  ASSERT_LE(coarse.positions.size() / 3, n / 4);
  MeshData scan = sphere;
  const std::vector<float> moved = bench::resample_onto(coarse, scan);
  // Same vertices and faces; every vertex moved onto the coarser surface (resampling again moves
  // nothing), near the sphere (the quadric placement may put the coarse surface a little outside).
  ASSERT_EQ(scan.positions.size(), sphere.positions.size());
  ASSERT_EQ(scan.indices, sphere.indices);
  std::vector<double> moves, turns;
  for (size_t v = 0; v < n; ++v) {
    const float *p = &scan.positions[3 * v];
    const double r = std::sqrt(double(p[0]) * p[0] + double(p[1]) * p[1] + double(p[2]) * p[2]);
    EXPECT_LE(r, 1.01) << "vertex " << v;
    EXPECT_GT(r, 0.97) << "vertex " << v;
    EXPECT_NEAR(std::sqrt(double(scan.normals[3 * v]) * scan.normals[3 * v] +
                          double(scan.normals[3 * v + 1]) * scan.normals[3 * v + 1] +
                          double(scan.normals[3 * v + 2]) * scan.normals[3 * v + 2]),
                1.0, 1e-4);
    moves.push_back(moved[v]);
    turns.push_back(angle_degrees(&scan.normals[3 * v], &sphere.normals[3 * v]));
  }
  EXPECT_GT(median(moves), 1e-5);
  MeshData again = scan;
  for (float d : bench::resample_onto(coarse, again)) ASSERT_LT(d, 1e-5f);
  // The interpolated normals of the coarse sphere stay close to the radial ones, but not equal.
  EXPECT_LT(median(turns), 3.0);
  EXPECT_GT(median(turns), 0.01);
}
