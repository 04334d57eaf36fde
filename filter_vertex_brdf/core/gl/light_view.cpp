#include "gl/light_view.h"

#include <algorithm>
#include <cmath>

#include "base/errors.h"

namespace vbrdf {

namespace {
float &at(float *m, int row, int col) { return m[col * 4 + row]; }
float at(const float *m, int row, int col) { return m[col * 4 + row]; }

// An orthonormal frame whose z axis is the unit vector d (GL looks along -z).
void frame_around(const float d[3], float x[3], float y[3]) {
  const int a = std::fabs(d[0]) < 0.6f ? 0 : (std::fabs(d[1]) < 0.6f ? 1 : 2);
  float helper[3] = {0, 0, 0};
  helper[a] = 1;
  x[0] = helper[1] * d[2] - helper[2] * d[1];
  x[1] = helper[2] * d[0] - helper[0] * d[2];
  x[2] = helper[0] * d[1] - helper[1] * d[0];
  const float xl = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
  for (int k = 0; k < 3; ++k) x[k] /= xl;
  y[0] = d[1] * x[2] - d[2] * x[1];
  y[1] = d[2] * x[0] - d[0] * x[2];
  y[2] = d[0] * x[1] - d[1] * x[0];
}
} // namespace

LightView make_light_view(const LightSource &light, const float origin[3], float radius) {
  LightView v;
  const float r = std::max(radius, 1e-12f);
  float d[3], eye[3] = {0, 0, 0}, dist = 0;
  if (light.positional) {
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(light.position[size_t(k)])) throw InputError("The light position is not finite.");
      eye[k] = light.position[size_t(k)] - origin[k];
    }
    dist = std::sqrt(eye[0] * eye[0] + eye[1] * eye[1] + eye[2] * eye[2]);
    if (!(dist > r))
      throw InputError("A point light lies within the mesh's bounding sphere: place the lights outside the object "
                       "(check the light file's positions, frame and units).");
    for (int k = 0; k < 3; ++k) d[k] = eye[k] / dist;
  } else {
    const float *dir = light.direction.data();
    const float len = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    if (!(len > 1e-12f) || !std::isfinite(len)) throw InputError("The light direction is zero or not finite.");
    for (int k = 0; k < 3; ++k) d[k] = dir[k] / len;
  }
  float x[3], y[3];
  frame_around(d, x, y);
  for (int k = 0; k < 3; ++k) {
    at(v.view, 0, k) = x[k];
    at(v.view, 1, k) = y[k];
    at(v.view, 2, k) = d[k];
  }
  at(v.view, 3, 3) = 1;
  if (!light.positional) {
    v.scale = 1 / r;
    at(v.projection, 0, 0) = 1 / r;
    at(v.projection, 1, 1) = 1 / r;
    at(v.projection, 2, 2) = -1 / r;
    at(v.projection, 3, 3) = 1;
    return v;
  }
  v.perspective = true;
  at(v.view, 0, 3) = -(x[0] * eye[0] + x[1] * eye[1] + x[2] * eye[2]);
  at(v.view, 1, 3) = -(y[0] * eye[0] + y[1] * eye[1] + y[2] * eye[2]);
  at(v.view, 2, 3) = -dist;
  const float f = 1.0f / std::tan(std::asin(std::min(r / dist, 0.999f)));  // cot of the half angle
  const float near_dist = std::max(dist - r, dist * 1e-3f), far_dist = dist + r;
  v.scale = f;
  at(v.projection, 0, 0) = f;
  at(v.projection, 1, 1) = f;
  at(v.projection, 2, 2) = -(far_dist + near_dist) / (far_dist - near_dist);
  at(v.projection, 2, 3) = -2 * far_dist * near_dist / (far_dist - near_dist);
  at(v.projection, 3, 2) = -1;
  return v;
}

bool light_view_project(const LightView &v, const float local[3], int size, float &wx, float &wy, float &depth) {
  float p[3];
  for (int row = 0; row < 3; ++row)
    p[row] = at(v.view, row, 0) * local[0] + at(v.view, row, 1) * local[1] + at(v.view, row, 2) * local[2] +
             at(v.view, row, 3);
  depth = -p[2];
  const float w = v.perspective ? depth : 1.0f;
  if (v.perspective && !(depth > 0)) return false;
  const float half = 0.5f * float(size);
  wx = (v.scale * p[0] / w + 1) * half;
  wy = (v.scale * p[1] / w + 1) * half;
  return true;
}

} // namespace vbrdf
