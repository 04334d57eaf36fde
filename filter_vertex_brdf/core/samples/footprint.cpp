#include "samples/footprint.h"

#include <cmath>

#include "model/lobe.h"

namespace vbrdf {
namespace {
double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// An orthonormal tangent basis t1, t2 of the unit normal n.
void tangent_basis(const double n[3], double t1[3], double t2[3]) {
  const double a[3] = {std::fabs(n[0]) < 0.9 ? 1.0 : 0.0, std::fabs(n[0]) < 0.9 ? 0.0 : 1.0, 0.0};
  const double d = dot(a, n);
  for (int i = 0; i < 3; ++i) t1[i] = a[i] - d * n[i];
  const double l = std::sqrt(dot(t1, t1));
  for (int i = 0; i < 3; ++i) t1[i] /= l;
  t2[0] = n[1] * t1[2] - n[2] * t1[1], t2[1] = n[2] * t1[0] - n[0] * t1[2], t2[2] = n[0] * t1[1] - n[1] * t1[0];
}
} // namespace

std::vector<float> normal_gradients(const MeshView &mesh) {
  const size_t n_vertices = mesh.vertex_count;
  // Per vertex: unit normal, tangent basis, and the least-squares sums over its triangles' edges
  // (an interior edge is met from both of its triangles: every neighbour weighs twice, alike).
  std::vector<double> basis(9 * n_vertices, 0.0), sums(9 * n_vertices, 0.0);  // A: 3, B: 6 per vertex
  std::vector<uint8_t> valid(n_vertices, 0);
  for (size_t v = 0; v < n_vertices; ++v) {
    double n[3];
    for (int i = 0; i < 3; ++i) n[i] = mesh.normals[3 * v + i];
    const double l = std::sqrt(dot(n, n));
    if (!(l > 0) || !std::isfinite(l)) continue;
    for (double &x : n) x /= l;
    double *b = &basis[9 * v];
    for (int i = 0; i < 3; ++i) b[i] = n[i];
    tangent_basis(n, b + 3, b + 6);
    valid[v] = 1;
  }
  auto add_edge = [&](size_t v, size_t u) {
    if (!valid[v] || !valid[u]) return;
    const double *b = &basis[9 * v], *bu = &basis[9 * u];
    double dp[3], dn[3];
    for (int i = 0; i < 3; ++i) dp[i] = double(mesh.positions[3 * u + i]) - mesh.positions[3 * v + i], dn[i] = bu[i] - b[i];
    const double q0 = dot(dp, b + 3), q1 = dot(dp, b + 6);
    double *S = &sums[9 * v];
    S[0] += q0 * q0, S[1] += q0 * q1, S[2] += q1 * q1;
    for (int i = 0; i < 3; ++i) S[3 + 2 * i] += dn[i] * q0, S[4 + 2 * i] += dn[i] * q1;
  };
  for (size_t t = 0; t + 2 < mesh.index_count; t += 3) {
    const size_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    if (a >= n_vertices || b >= n_vertices || c >= n_vertices) continue;
    add_edge(a, b), add_edge(a, c), add_edge(b, a), add_edge(b, c), add_edge(c, a), add_edge(c, b);
  }
  std::vector<float> out(9 * n_vertices, 0.0f);
#pragma omp parallel for schedule(static)
  for (long long vi = 0; vi < (long long)n_vertices; ++vi) {
    const size_t v = size_t(vi);
    const double *S = &sums[9 * v], *t1 = &basis[9 * v + 3], *t2 = &basis[9 * v + 6];
    // Gt = (sum dN q^T) (sum q q^T)^-1, q = (dp.t1, dp.t2).
    const double det = S[0] * S[2] - S[1] * S[1], tr = S[0] + S[2];
    if (!valid[v] || !(det > 1e-12 * tr * tr) || !std::isfinite(det)) continue;  // collinear or no neighbours
    const double inv[3] = {S[2] / det, -S[1] / det, S[0] / det};
    double G[9];
    bool finite = true;
    for (int i = 0; i < 3; ++i) {
      const double b0 = S[3 + 2 * i], b1 = S[4 + 2 * i];
      const double g0 = b0 * inv[0] + b1 * inv[1], g1 = b0 * inv[1] + b1 * inv[2];
      for (int j = 0; j < 3; ++j) finite = finite && std::isfinite(G[3 * i + j] = g0 * t1[j] + g1 * t2[j]);
    }
    if (finite)
      for (int k = 0; k < 9; ++k) out[9 * v + k] = float(G[k]);
  }
  return out;
}

FootprintCamera footprint_camera(const Raster &raster) {
  FootprintCamera c;
  float centre[3], axis[3];
  camera_centre(raster.shot, centre);
  const float x[3] = {1, 0, 0}, y[3] = {0, 1, 0}, z[3] = {0, 0, 1};
  for (int i = 0; i < 3; ++i) c.centre[i] = centre[i];
  camera_to_world_direction(raster.shot, x, axis);
  for (int i = 0; i < 3; ++i) c.x_axis[i] = axis[i];
  camera_to_world_direction(raster.shot, y, axis);
  for (int i = 0; i < 3; ++i) c.y_axis[i] = axis[i];
  camera_to_world_direction(raster.shot, z, axis);  // towards the viewer: the camera looks along -z
  for (int i = 0; i < 3; ++i) c.forward[i] = -axis[i];
  c.fx = raster.shot.Intrinsics.FocalMm / raster.shot.Intrinsics.PixelSizeMm[0];
  c.fy = raster.shot.Intrinsics.FocalMm / raster.shot.Intrinsics.PixelSizeMm[1];
  return c;
}

float footprint_variance(const FootprintCamera &camera, const float position[3], const float normal[3],
                         const float gradient[9]) {
  double d[3], n[3];
  for (int i = 0; i < 3; ++i) d[i] = double(position[i]) - camera.centre[i], n[i] = normal[i];
  const double dist = std::sqrt(dot(d, d)), nl = std::sqrt(dot(n, n));
  const double depth = dot(d, camera.forward);
  if (!(dist > 0) || !(nl > 0) || !(depth > 0) || !(camera.fx > 0) || !(camera.fy > 0)) return 0.0f;
  for (int i = 0; i < 3; ++i) d[i] /= dist, n[i] /= nl;
  const double dn = dot(d, n);
  if (!(dn < 0)) return 0.0f;  // back-facing (d points from the camera to the vertex)
  double sum = 0;
  for (int a = 0; a < 2; ++a) {
    const double *axis = a == 0 ? camera.x_axis : camera.y_axis;
    // One pixel along the image axis at the vertex's depth, then along the ray onto the tangent plane.
    const double scale = depth / (a == 0 ? camera.fx : camera.fy);
    double step[3];
    for (int i = 0; i < 3; ++i) step[i] = scale * axis[i];
    const double along = dot(step, n) / dn;
    for (int i = 0; i < 3; ++i) step[i] -= along * d[i];
    for (int i = 0; i < 3; ++i) {
      const double g = gradient[3 * i] * step[0] + gradient[3 * i + 1] * step[1] + gradient[3 * i + 2] * step[2];
      sum += g * g;
    }
  }
  const double v = kPhotoFootprintVariance * sum;
  if (!std::isfinite(v)) return float(kMaxFootprintVariance);  // a step along the tangent plane's edge-on ray
  return float(std::fmin(v, kMaxFootprintVariance));
}

} // namespace vbrdf
