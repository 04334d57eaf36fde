#include "inputs/camera.h"

#include <algorithm>
#include <cmath>

namespace vbrdf {

namespace {
vcg::Matrix44f rotation(const Shot &shot) {
  vcg::Matrix44f r;
  r = shot.Extrinsics.Rot();
  return r;
}
bool finite3(const vcg::Point3f &p) { return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]); }
bool nearly_equal(double a, double b) {
  return std::fabs(a - b) <= 1e-6 * std::max({1.0, std::fabs(a), std::fabs(b)});
}
} // namespace

bool same_shot(const Shot &a, const Shot &b) {
  const auto &ia = a.Intrinsics, &ib = b.Intrinsics;
  bool same = ia.ViewportPx == ib.ViewportPx && nearly_equal(ia.FocalMm, ib.FocalMm);
  for (int k = 0; k < 2; ++k)
    same = same && nearly_equal(ia.PixelSizeMm[k], ib.PixelSizeMm[k]) && nearly_equal(ia.CenterPx[k], ib.CenterPx[k]) &&
           nearly_equal(ia.k[k], ib.k[k]);
  const vcg::Matrix44f ra = rotation(a), rb = rotation(b);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) same = same && nearly_equal(ra[r][c], rb[r][c]);
  for (int k = 0; k < 3; ++k) same = same && nearly_equal(a.Extrinsics.Tra()[k], b.Extrinsics.Tra()[k]);
  return same;
}

bool shot_is_valid(const Shot &shot) {
  const auto &in = shot.Intrinsics;
  if (!(in.FocalMm > 0) || !std::isfinite(in.FocalMm)) return false;
  if (!(in.PixelSizeMm[0] > 0) || !(in.PixelSizeMm[1] > 0)) return false;
  if (in.ViewportPx[0] <= 0 || in.ViewportPx[1] <= 0) return false;
  if (!std::isfinite(in.CenterPx[0]) || !std::isfinite(in.CenterPx[1])) return false;
  if (!finite3(shot.Extrinsics.Tra())) return false;
  // A rotation must be orthonormal; an all-zero matrix (missing <VCGCamera>) is not.
  const vcg::Matrix44f r = rotation(shot);
  for (int i = 0; i < 3; ++i) {
    const vcg::Point3f row(r[i][0], r[i][1], r[i][2]);
    if (!finite3(row) || std::fabs(row.Norm() - 1.0f) > 1e-3f) return false;
  }
  return true;
}

bool shot_is_identity(const Shot &shot) {
  const vcg::Matrix44f r = rotation(shot);
  const vcg::Point3f t = shot.Extrinsics.Tra();
  for (int i = 0; i < 3; ++i) {
    if (t[i] != 0.0f) return false;
    for (int j = 0; j < 3; ++j)
      if (r[i][j] != (i == j ? 1.0f : 0.0f)) return false;
  }
  return true;
}

ImagePoint project_to_image(const Shot &shot, const float world[3]) {
  const vcg::Point3f p(world[0], world[1], world[2]);
  ImagePoint ip;
  ip.in_front = shot.ConvertWorldToCameraCoordinates(p)[2] > 0;
  const vcg::Point2f vp = shot.Project(p);
  ip.x = vp[0];
  ip.y = float(shot.Intrinsics.ViewportPx[1]) - vp[1];
  return ip;
}

float view_depth(const Shot &shot, const float world[3]) {
  return shot.ConvertWorldToCameraCoordinates(vcg::Point3f(world[0], world[1], world[2]))[2];
}

void camera_centre(const Shot &shot, float out[3]) {
  const vcg::Point3f c = shot.GetViewPoint();
  out[0] = c[0];
  out[1] = c[1];
  out[2] = c[2];
}

void camera_to_world_direction(const Shot &shot, const float d[3], float out[3]) {
  // Rows of the rotation are the camera axes in world coordinates: world = R^T * d.
  const vcg::Matrix44f r = rotation(shot);
  vcg::Point3f w(0, 0, 0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) w[j] += r[i][j] * d[i];
  w.Normalize();
  out[0] = w[0];
  out[1] = w[1];
  out[2] = w[2];
}

void world_to_camera_direction(const Shot &shot, const float d[3], float out[3]) {
  const vcg::Matrix44f r = rotation(shot);
  vcg::Point3f c(0, 0, 0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c[i] += r[i][j] * d[j];
  c.Normalize();
  out[0] = c[0];
  out[1] = c[1];
  out[2] = c[2];
}

void gl_view_matrix(const Shot &shot, float m[16]) {
  // eye = R (p - C): GL looks along -z, which is exactly vcg's camera "back" axis convention.
  const vcg::Matrix44f r = rotation(shot);
  const vcg::Point3f c = shot.GetViewPoint();
  for (int i = 0; i < 16; ++i) m[i] = 0;
  for (int row = 0; row < 3; ++row) {
    float t = 0;
    for (int col = 0; col < 3; ++col) {
      m[col * 4 + row] = r[row][col];
      t -= r[row][col] * c[col];
    }
    m[12 + row] = t;
  }
  m[15] = 1;
}

void gl_projection_matrix(const Shot &shot, float near_dist, float far_dist, float m[16]) {
  // px = f/ps * x/(-z) + cx (VCG pixels, y up). NDC x = 2 px / W - 1, hence
  // clip.x = (2 fx / W) x + (1 - 2 cx / W) z with w = -z (same for y).
  const auto &in = shot.Intrinsics;
  const float w = float(in.ViewportPx[0]), h = float(in.ViewportPx[1]);
  const float fx = in.FocalMm / in.PixelSizeMm[0], fy = in.FocalMm / in.PixelSizeMm[1];
  for (int i = 0; i < 16; ++i) m[i] = 0;
  m[0] = 2 * fx / w;
  m[5] = 2 * fy / h;
  m[8] = 1 - 2 * in.CenterPx[0] / w;
  m[9] = 1 - 2 * in.CenterPx[1] / h;
  m[10] = -(far_dist + near_dist) / (far_dist - near_dist);
  m[11] = -1;
  m[14] = -2 * far_dist * near_dist / (far_dist - near_dist);
}

} // namespace vbrdf
