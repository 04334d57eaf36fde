#include "test_scenes.h"

#include <algorithm>
#include <cmath>

namespace vbrdf {
namespace test {

namespace {
vcg::Point3f p3(const float v[3]) { return vcg::Point3f(v[0], v[1], v[2]); }
} // namespace

Shot make_look_at_shot(const float centre[3], const float target[3], const float up[3], float focal_px, int width,
                       int height, float cx, float cy) {
  const vcg::Point3f c = p3(centre);
  vcg::Point3f back = (c - p3(target)).Normalize();
  vcg::Point3f right = (p3(up) ^ back).Normalize();
  vcg::Point3f cam_up = back ^ right;
  vcg::Matrix44f rot;
  rot.SetIdentity();
  for (int j = 0; j < 3; ++j) {
    rot[0][j] = right[j];
    rot[1][j] = cam_up[j];
    rot[2][j] = back[j];
  }
  Shot shot;
  shot.Intrinsics.cameraType = 0;
  shot.Intrinsics.PixelSizeMm = vcg::Point2f(0.01f, 0.01f);
  shot.Intrinsics.FocalMm = focal_px * 0.01f;
  shot.Intrinsics.ViewportPx = vcg::Point2i(width, height);
  shot.Intrinsics.CenterPx = vcg::Point2f(cx >= 0 ? cx : width / 2.0f, cy >= 0 ? cy : height / 2.0f);
  shot.Intrinsics.k[0] = shot.Intrinsics.k[1] = 0;
  shot.Extrinsics.SetRot(rot);
  shot.Extrinsics.SetTra(c);
  return shot;
}

MeshData make_grid(int n, float half, float height) {
  MeshData m;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      m.positions.insert(m.positions.end(), {-half + 2 * half * j / n, height, -half + 2 * half * i / n});
      m.normals.insert(m.normals.end(), {0, 1, 0});
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const uint32_t a = uint32_t(i * (n + 1) + j), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
      m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
    }
  return m;
}

MeshData make_sphere(const float centre[3], float radius, int rings, int segments) {
  MeshData m;
  const float pi = 3.14159265358979f;
  for (int i = 0; i <= rings; ++i) {
    const float theta = pi * i / rings;
    for (int j = 0; j <= segments; ++j) {
      const float phi = 2 * pi * j / segments;
      const float n[3] = {std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
      for (int k = 0; k < 3; ++k) {
        m.positions.push_back(centre[k] + radius * n[k]);
        m.normals.push_back(n[k]);
      }
    }
  }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const uint32_t a = uint32_t(i * (segments + 1) + j), b = a + 1, c = a + uint32_t(segments + 1), d = c + 1;
      m.indices.insert(m.indices.end(), {a, b, c, b, d, c});
    }
  return m;
}

MeshData make_bumpy_sphere(size_t target_vertices) {
  const int rings = std::max(8, int(std::sqrt(double(target_vertices) / 2)));
  const float c[3] = {0, 0, 0};
  MeshData m = make_sphere(c, 1.0f, rings, 2 * rings);
  for (size_t v = 0; v < m.positions.size() / 3; ++v) {
    float *n = &m.normals[3 * v];
    const float *p = &m.positions[3 * v];
    n[0] += 0.3f * std::sin(17 * p[1]), n[1] += 0.3f * std::sin(13 * p[2]), n[2] += 0.3f * std::sin(11 * p[0]);
    const float l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int k = 0; k < 3; ++k) n[k] /= l;
  }
  return m;
}

void append_mesh(MeshData &a, const MeshData &b) {
  const uint32_t base = uint32_t(a.positions.size() / 3);
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  a.normals.insert(a.normals.end(), b.normals.begin(), b.normals.end());
  for (uint32_t i : b.indices) a.indices.push_back(base + i);
}

} // namespace test
} // namespace vbrdf
