// New viewpoints from existing cameras, and file-safe labels (orbit_camera.h).
#include "relight/orbit_camera.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/color_difference.h"
#include "base/errors.h"
#include "base/file_util.h"
#include "base/vec3.h"

namespace vbrdf {

// ---------------------------------------------------------------------------------------------
// Cameras and names

namespace {

// Rodrigues rotation of v about the unit axis u by angle t (radians).
vcg::Point3f rotate(const vcg::Point3f &v, const vcg::Point3f &u, float t) {
  const float c = std::cos(t), s = std::sin(t);
  return v * c + (u ^ v) * s + u * ((u * v) * (1 - c));
}

} // namespace


Shot orbit_shot(const Shot &base, const float pivot[3], float azimuth_deg, float elevation_deg, float distance_scale) {
  if (!(distance_scale > 0) || !std::isfinite(distance_scale) || !std::isfinite(azimuth_deg) ||
      !std::isfinite(elevation_deg))
    throw InputError("Novel view: the distance scale must be positive and the angles finite.");
  const vcg::Matrix44f rot = base.Extrinsics.Rot();
  vcg::Point3f axis[3];
  for (int i = 0; i < 3; ++i) axis[i] = vcg::Point3f(rot[i][0], rot[i][1], rot[i][2]);
  const float deg = float(kRadiansPerDegree);
  const vcg::Point3f p(pivot[0], pivot[1], pivot[2]);
  // Azimuth about the camera's up axis (y), then elevation about the rotated right axis (x):
  // positive elevation moves the camera up, i.e. a rotation by -elevation about x.
  auto apply = [&](vcg::Point3f v) {
    const vcg::Point3f up = axis[1];
    v = rotate(v, up, azimuth_deg * deg);
    const vcg::Point3f right = rotate(axis[0], up, azimuth_deg * deg);
    return rotate(v, right, -elevation_deg * deg);
  };
  Shot out = base;
  vcg::Matrix44f r;
  r.SetIdentity();
  for (int i = 0; i < 3; ++i) {
    const vcg::Point3f a = apply(axis[i]);
    for (int j = 0; j < 3; ++j) r[i][j] = a[j];
  }
  out.Extrinsics.SetRot(r);
  out.Extrinsics.SetTra(p + apply(base.GetViewPoint() - p) * distance_scale);
  return out;
}

std::string file_safe_label(const std::string &label) {
  std::string out;
  for (char c : label) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                    c == '-' || c == '_';
    out += ok ? c : '_';
  }
  return out.empty() ? std::string("raster") : out;
}

} // namespace vbrdf
