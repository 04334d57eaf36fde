#pragma once
// Registers a camera's projection of the mesh to a normal map of its photos (normal_map.h): finds
// the image-plane warp that best carries each visible vertex's projection onto the pixel whose
// photometric normal is the vertex's own normal. The warp is a similarity about the principal
// point (shift, roll about the optical axis, focal scale): exactly what a change of principal
// point, roll and focal length does to a pinhole camera (registration.h applies it to the shot).
// A small pitch or yaw reads as a shift (the two differ by under 0.1 px across an object a few
// hundred pixels wide for the tenths of a degree a registration is off).
#include <vector>

#include "registration/normal_map.h"

namespace vbrdf {

// The camera turned by R = Rz(roll) Rx(pitch) Ry(yaw) in the image frame (x right, y down, z along the
// view; angles in radians) and its focal length scaled by exp(log_scale): the ray of image point p,
// d = ((p - c) / f, 1), moves to c + exp(log_scale) f (R d).xy / (R d).z. Positive roll turns +x
// towards +y (clockwise as the image is seen); positive yaw moves the image towards -x.
struct ImageWarp {
  double pitch = 0, yaw = 0, roll = 0, log_scale = 0;
};
// c: principal point, f: focal length, both in image pixels.
void warp_point(const ImageWarp &w, const double c[2], double f, const double p[2], double out[2]);
// The warp's rotation in the image frame (x right, y down, z along the view), row-major.
void warp_rotation(const ImageWarp &w, double out[3][3]);

// One visible vertex: where the camera projects it (image pixels) and its unit normal, in the
// frame of the normal map.
struct AlignmentPoint {
  float x = 0, y = 0;
  float n[3] = {0, 0, 0};
};

struct AlignmentSettings {
  // Blur of the normal map (Gaussian sigma, pixels) per level, coarse to fine: the coarse levels
  // widen the basin (errors of several pixels), the finest keeps the detail. Pitch and yaw (the
  // shift) are solved on every level; roll and scale on the finest.
  std::vector<double> levels = {3.0, 1.5, 0.75};
  int iterations = 12;       // Gauss-Newton steps per level at most
  // Points the coarse levels use (evenly strided; 0: all): they only bring the shift within the
  // finest level's reach, which solves with every point.
  size_t max_coarse_points = 5000;
  // Normal residual (unit vectors) beyond which a point's weight falls as 1/r: 0.1 keeps the estimate
  // on exact cameras within 0.07 px on the shared scenes (0.3: 0.11 px; docs/benchmark.md#real-captures-cameras-off-and-smoothed-normals).
  double huber = 0.1;
  // Roll and scale are kept only where the data determine them: each must exceed this many of its
  // standard deviations and move the points by at least min_effect_px (RMS); else it stays 0.
  double significance = 3.0;
  double min_effect_px = 0.15;
  // The focal length (scale) needs more: a mesh whose normals are smoother than the surface's reads
  // as a scale of 0.995-0.996 on every smoothed scene and relief (0.35-0.45 px RMS over the points;
  // docs/decisions/registration.md), where a shift or a roll reads nothing false. Below this a focal
  // error cannot be told from a smoothed scan, and the focal length is kept.
  double min_scale_effect_px = 0.75;
  bool solve_roll_and_scale = true;
};

struct AlignmentResult {
  ImageWarp warp;
  double shift_x = 0, shift_y = 0;  // where the warp moves the principal point (pixels)
  bool roll_determined = false, scale_determined = false;
  double rms_px = 0;          // RMS displacement of the points by the warp: the measured misregistration
  double cost_before = 0, cost_after = 0;  // mean robust cost at the given and the warped projection (finest level)
  size_t points_used = 0;     // points on determined pixels of the map at the end
  int iterations = 0;
};

// Gauss-Newton (Levenberg-Marquardt damped, Huber-weighted) on
//   sum_v rho(| N_map(warp(p_v)) - n_v |)
// with N_map bilinear on the blurred map (weighted by its `weight`). `c`: the principal point,
// `f`: the focal length (image pixels). Points outside the map or on undetermined pixels do not count. With fewer than
// 20 usable points the warp stays the identity (points_used says so). Never returns NaN: a step
// that is not finite or raises the cost is halved, then refused.
AlignmentResult align_to_normal_map(const std::vector<AlignmentPoint> &points, const NormalMap &map, const double c[2],
                                    double f, const AlignmentSettings &settings = AlignmentSettings());

} // namespace vbrdf
