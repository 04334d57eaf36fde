#include "synth_camera.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <vector>

namespace synth {
namespace {

const double kSensorWidthMm = 36.0;  // as in the Mitsuba scenes: PixelSizeMm = 36 / width

// %.10g, with tiny values and negative zero written as "0" (like spot_dir24/project.mlp).
std::string num(double v) {
  if (std::fabs(v) < 1e-9) v = 0;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

std::vector<double> parse_numbers(const std::string &s) {
  std::vector<double> out;
  std::istringstream in(s);
  std::string tok;
  while (in >> tok) out.push_back(std::strtod(tok.c_str(), nullptr));
  return out;
}

} // namespace

float framing_distance(float radius, int width, int height, float fov_x_deg) {
  const double f_px = 0.5 * width / std::tan(0.5 * fov_x_deg * M_PI / 180);
  const double half = std::atan(0.5 * std::min(width, height) / f_px);
  return float(radius / std::sin(half));
}

CameraSpec look_at(V3 target, float distance, float azimuth_deg, float elevation_deg, int width,
                   int height, float fov_x_deg, float offset_x, float offset_y) {
  const double az = azimuth_deg * M_PI / 180, el = elevation_deg * M_PI / 180;
  CameraSpec c;
  const double back[3] = {std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az)};
  // right = normalize(world up x back), up = back x right
  const double rn = std::hypot(back[2], back[0]);
  const double right[3] = {back[2] / rn, 0, -back[0] / rn};
  const double up[3] = {back[1] * right[2] - back[2] * right[1], back[2] * right[0] - back[0] * right[2],
                        back[0] * right[1] - back[1] * right[0]};
  const double t[3] = {target.x, target.y, target.z};
  for (int i = 0; i < 3; ++i) {
    c.back[i] = back[i];
    c.right[i] = right[i];
    c.up[i] = up[i];
    c.centre[i] = t[i] + back[i] * distance;
  }
  c.width = width;
  c.height = height;
  c.pixel_mm = kSensorWidthMm / width;
  c.focal_mm = 0.5 * width / std::tan(0.5 * fov_x_deg * M_PI / 180) * c.pixel_mm;
  c.cx = 0.5 * width + offset_x;
  c.cy = 0.5 * height + offset_y;
  return c;
}

VcgCameraText format_camera(const CameraSpec &c) {
  VcgCameraText t;
  t.translation = num(-c.centre[0]) + " " + num(-c.centre[1]) + " " + num(-c.centre[2]) + " 1";
  t.lens_distortion = "0 0";
  t.viewport = std::to_string(c.width) + " " + std::to_string(c.height);
  t.pixel_size = num(c.pixel_mm) + " " + num(c.pixel_mm);
  t.center = num(c.cx) + " " + num(c.cy);
  t.focal = num(c.focal_mm);
  for (const double *r : {c.right, c.up, c.back})
    t.rotation += num(r[0]) + " " + num(r[1]) + " " + num(r[2]) + " 0 ";
  t.rotation += "0 0 0 1 ";
  return t;
}

Shot shot_from_text(const VcgCameraText &t) {
  Shot shot;
  const std::vector<double> tr = parse_numbers(t.translation), rot = parse_numbers(t.rotation);
  const vcg::Point3f tra{float(tr[0]), float(tr[1]), float(tr[2])};
  shot.Extrinsics.SetTra(-tra);  // the file stores minus the camera centre
  vcg::Matrix44f m;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) m[y][x] = float(rot[x + 4 * y]);
  shot.Extrinsics.SetRot(m);
  vcg::Camera<float> &cam = shot.Intrinsics;
  cam.cameraType = 0;
  cam.FocalMm = float(std::strtod(t.focal.c_str(), nullptr));
  const std::vector<double> vp = parse_numbers(t.viewport), ps = parse_numbers(t.pixel_size),
                            cp = parse_numbers(t.center), k = parse_numbers(t.lens_distortion);
  cam.ViewportPx = vcg::Point2i(int(vp[0]), int(vp[1]));
  cam.PixelSizeMm = vcg::Point2f(float(ps[0]), float(ps[1]));
  cam.CenterPx = vcg::Point2f(float(cp[0]), float(cp[1]));
  cam.k[0] = float(k[0]);
  cam.k[1] = float(k[1]);
  return shot;
}

V3 shot_axis(const Shot &shot, int row) {
  const vcg::Matrix44f m = shot.Extrinsics.Rot();
  return V3(m[row][0], m[row][1], m[row][2]);
}

V3 shot_centre(const Shot &shot) {
  const vcg::Point3f c = shot.GetViewPoint();
  return V3(c[0], c[1], c[2]);
}

V3 camera_to_world(const Shot &shot, V3 d) {
  return normalize(shot_axis(shot, 0) * d.x + shot_axis(shot, 1) * d.y + shot_axis(shot, 2) * d.z);
}

} // namespace synth
