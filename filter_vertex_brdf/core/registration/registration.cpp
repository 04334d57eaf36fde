#include "registration/registration.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Dense>

#include "base/luminance.h"
#include "base/vec3.h"
#include "inputs/viewpoints.h"

namespace vbrdf {

bool RegistrationResult::any_applied() const {
  return std::any_of(viewpoints.begin(), viewpoints.end(), [](const ViewpointRegistration &v) { return v.applied; });
}

const Shot *RegistrationResult::corrected_for(const Shot &shot) const {
  for (const ViewpointRegistration &v : viewpoints)
    if (v.applied && same_shot(v.given, shot)) return &v.corrected;
  return nullptr;
}

void principal_point(const Shot &shot, double out[2]) {
  out[0] = shot.Intrinsics.CenterPx[0];
  out[1] = double(shot.Intrinsics.ViewportPx[1]) - shot.Intrinsics.CenterPx[1];
}

double focal_pixels(const Shot &shot) {
  const auto &in = shot.Intrinsics;
  return 0.5 * (double(in.FocalMm) / in.PixelSizeMm[0] + double(in.FocalMm) / in.PixelSizeMm[1]);
}

Shot warped_shot(const Shot &shot, const ImageWarp &warp) {
  Shot out = shot;
  out.Intrinsics.FocalMm = float(shot.Intrinsics.FocalMm * std::exp(warp.log_scale));
  // The rows of the shot's rotation are the camera's axes in the world (VCG: x right, y up, z back);
  // the warp turns the image frame (x right, y down, z along the view) = D (VCG) with D = diag(1, -1, -1).
  // The new world-to-camera rotation is D R_warp D R.
  double Rw[3][3];
  warp_rotation(warp, Rw);
  const double D[3] = {1, -1, -1};
  vcg::Matrix44f r;
  r = shot.Extrinsics.Rot();
  vcg::Matrix44f turned = r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double v = 0;
      for (int k = 0; k < 3; ++k) v += D[i] * Rw[i][k] * D[k] * double(r[k][j]);
      turned[i][j] = float(v);
    }
  out.Extrinsics.SetRot(turned);
  return out;
}

namespace {

// The visible vertices of a camera, as alignment points: not hidden by the camera pass, inside the
// image by a margin, facing the camera at under 60 degrees (grazing normals are read poorly by
// photometric stereo). Evenly strided to at most max_points.
std::vector<AlignmentPoint> visible_points(const MeshView &mesh, const Shot &shot, VisibilityBackend &visibility,
                                           size_t max_points) {
  std::vector<uint8_t> codes(mesh.vertex_count);
  visibility.camera_pass(shot, codes.data());
  float eye[3];
  camera_centre(shot, eye);
  const float margin = 4.0f, w = float(shot.Intrinsics.ViewportPx[0]), h = float(shot.Intrinsics.ViewportPx[1]);
  std::vector<AlignmentPoint> points;
  for (size_t v = 0; v < mesh.vertex_count; ++v) {
    if (codes[v] == kCameraHidden) continue;
    const float *p = mesh.positions + 3 * v, *n = mesh.normals + 3 * v;
    const ImagePoint ip = project_to_image(shot, p);
    if (!ip.in_front || !(ip.x >= margin && ip.y >= margin && ip.x < w - margin && ip.y < h - margin)) continue;
    const float to_eye[3] = {eye[0] - p[0], eye[1] - p[1], eye[2] - p[2]};
    const float d = std::sqrt(to_eye[0] * to_eye[0] + to_eye[1] * to_eye[1] + to_eye[2] * to_eye[2]);
    if (!(d > 0) || (n[0] * to_eye[0] + n[1] * to_eye[1] + n[2] * to_eye[2]) < 0.5f * d) continue;
    AlignmentPoint a;
    a.x = ip.x;
    a.y = ip.y;
    for (int k = 0; k < 3; ++k) a.n[k] = n[k];
    points.push_back(a);
  }
  if (points.size() > max_points && max_points > 0) {
    const double stride = double(points.size()) / double(max_points);
    std::vector<AlignmentPoint> kept;
    for (size_t i = 0; i < max_points; ++i) kept.push_back(points[size_t(double(i) * stride)]);
    points.swap(kept);
  }
  return points;
}

// The bounding box of the points, widened by the largest shift refined and the blur, on the image.
cv::Rect region_of(const std::vector<AlignmentPoint> &points, const Shot &shot, const RegistrationSettings &settings) {
  float x0 = 1e30f, y0 = 1e30f, x1 = -1e30f, y1 = -1e30f;
  for (const AlignmentPoint &p : points) {
    x0 = std::min(x0, p.x), y0 = std::min(y0, p.y), x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
  }
  const double blur = settings.alignment.levels.empty() ? 0 : *std::max_element(settings.alignment.levels.begin(),
                                                                                 settings.alignment.levels.end());
  const int pad = int(std::ceil(settings.max_correction_px + 3 * blur)) + 2;
  const cv::Rect image(0, 0, shot.Intrinsics.ViewportPx[0], shot.Intrinsics.ViewportPx[1]);
  return cv::Rect(cv::Point(int(std::floor(x0)) - pad, int(std::floor(y0)) - pad),
                  cv::Point(int(std::ceil(x1)) + pad, int(std::ceil(y1)) + pad)) & image;
}

// Linear luminance of the photo over `region` (CV_32F), NaN where any channel is clipped.
cv::Mat luminance_of(const Photo &photo, const cv::Rect &region) {
  Photo part = photo;
  part.pixels = photo.pixels(region);  // a header on the same pixels
  cv::Mat clipped;
  const cv::Mat rgb = photo_linear_rgb(part, &clipped);
  cv::Mat lum(region.size(), CV_32F);
  for (int y = 0; y < lum.rows; ++y) {
    const cv::Vec3f *c = rgb.ptr<cv::Vec3f>(y);
    const uint8_t *clip = clipped.ptr<uint8_t>(y);
    float *out = lum.ptr<float>(y);
    for (int x = 0; x < lum.cols; ++x) out[x] = clip[x] ? std::nanf("") : luminance(&c[x][0]);
  }
  return lum;
}

// Smallest eigenvalue of the lights' mean outer product: 0 when they lie in one plane.
double light_spread(const std::vector<std::array<float, 3>> &dirs) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  for (const auto &d : dirs) {
    const Eigen::Vector3d l = Eigen::Vector3d(d[0], d[1], d[2]).normalized();
    A += l * l.transpose();
  }
  if (dirs.empty()) return 0;
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(A / double(dirs.size()), Eigen::EigenvaluesOnly).eigenvalues()(0);
}

// At most `count` of the viewpoint's photos (indices into `dirs`), their lights spread as evenly as
// they allow: farthest-point order from the light nearest the mean direction. Photometric stereo
// determines a normal from a handful of well-spread lights; more photos cost time, not accuracy.
std::vector<size_t> spread_photos(const std::vector<std::array<float, 3>> &dirs, size_t count) {
  std::vector<size_t> chosen;
  if (count == 0 || dirs.size() <= count) {
    for (size_t k = 0; k < dirs.size(); ++k) chosen.push_back(k);
    return chosen;
  }
  std::vector<Eigen::Vector3d> l;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto &d : dirs) {
    l.push_back(Eigen::Vector3d(d[0], d[1], d[2]).normalized());
    mean += l.back();
  }
  size_t first = 0;
  for (size_t k = 1; k < l.size(); ++k)
    if (l[k].dot(mean) > l[first].dot(mean)) first = k;
  chosen.push_back(first);
  std::vector<double> nearest(l.size(), 4.0);  // squared distance to the nearest chosen light
  while (chosen.size() < count) {
    const Eigen::Vector3d &last = l[chosen.back()];
    size_t next = 0;
    for (size_t k = 0; k < l.size(); ++k) {
      nearest[k] = std::min(nearest[k], (l[k] - last).squaredNorm());
      if (nearest[k] > nearest[next]) next = k;
    }
    chosen.push_back(next);
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

// Measures one viewpoint at `shot` against its normal map: the warp and the points used.
AlignmentResult measure(const std::vector<AlignmentPoint> &points, const NormalMap &map, const Shot &shot,
                        const AlignmentSettings &settings) {
  double c[2];
  principal_point(shot, c);
  return align_to_normal_map(points, map, c, focal_pixels(shot), settings);
}

ViewpointRegistration register_viewpoint(const MeshView &mesh, const std::vector<Raster> &rasters,
                                         const Viewpoint &vp, const std::vector<LightSource> &lights,
                                         PhotoCache &photos, VisibilityBackend &visibility,
                                         const RegistrationSettings &settings) {
  ViewpointRegistration out;
  out.rasters = vp.rasters;
  out.label = rasters[vp.rasters.front()].label;
  out.given = out.corrected = vp.shot;
  if (vp.rasters.size() < size_t(settings.min_photos)) {
    out.not_measured = "fewer than " + std::to_string(settings.min_photos) + " photos (photometric stereo needs them)";
    return out;
  }
  std::vector<std::array<float, 3>> all_dirs;
  for (size_t r : vp.rasters) {
    if (lights[r].positional) {
      out.not_measured = "its lights are point lights (the normal map needs one direction per photo)";
      return out;
    }
    all_dirs.push_back(lights[r].direction);
  }
  const std::vector<size_t> used_photos = spread_photos(all_dirs, settings.max_photos);
  std::vector<std::array<float, 3>> dirs;
  for (size_t k : used_photos) dirs.push_back(all_dirs[k]);
  out.map_photos = used_photos.size();
  if (light_spread(dirs) < settings.normal_map.min_light_spread) {
    out.not_measured = "its lights lie nearly in one plane (the normals are not determined)";
    return out;
  }
  std::vector<AlignmentPoint> points = visible_points(mesh, vp.shot, visibility, settings.max_points);
  if (points.size() < settings.min_vertices) {
    out.not_measured = "it sees " + std::to_string(points.size()) + " vertices well (fewer than " +
                       std::to_string(settings.min_vertices) + ")";
    return out;
  }
  const cv::Rect region = region_of(points, vp.shot, settings);
  std::vector<cv::Mat> lum;
  for (size_t k : used_photos) {
    const Raster &raster = rasters[vp.rasters[k]];
    lum.push_back(luminance_of(*photos.get(raster.image_path, raster.width(), raster.height()), region));
  }
  const NormalMap map = photometric_normal_map(lum, dirs, region, settings.normal_map);
  lum.clear();
  const AlignmentResult before = measure(points, map, vp.shot, settings.alignment);
  out.points = before.points_used;
  if (before.points_used < settings.min_vertices) {
    out.not_measured = "the photos determine the normals of " + std::to_string(before.points_used) +
                       " of its vertices (fewer than " + std::to_string(settings.min_vertices) + ")";
    return out;
  }
  out.measured = true;
  out.before_px = out.after_px = before.rms_px;
  if (before.rms_px < settings.threshold_px) return out;
  if (before.rms_px > settings.max_correction_px) {
    out.too_large = true;
    return out;
  }
  out.correction = before.warp;
  out.shift_x = before.shift_x;
  out.shift_y = before.shift_y;
  out.roll_determined = before.roll_determined;
  out.scale_determined = before.scale_determined;
  out.corrected = warped_shot(vp.shot, before.warp);
  out.applied = true;
  // Measured again from the corrected camera, against the same normal map.
  double c0[2];
  principal_point(vp.shot, c0);
  for (AlignmentPoint &p : points) {
    const double p0[2] = {p.x, p.y};
    double q[2];
    warp_point(before.warp, c0, focal_pixels(vp.shot), p0, q);
    p.x = float(q[0]);
    p.y = float(q[1]);
  }
  AlignmentSettings again = settings.alignment;
  again.levels = {settings.alignment.levels.back()};
  out.after_px = measure(points, map, out.corrected, again).rms_px;
  return out;
}

} // namespace

std::string describe_registration(const ViewpointRegistration &v, const RegistrationSettings &settings) {
  std::string s = "viewpoint '" + v.label + "' (" + std::to_string(v.rasters.size()) + " photos): ";
  if (!v.measured) return s + "not measured, " + v.not_measured + "; camera unchanged";
  s += "misregistration " + fixed(v.before_px) + " px over " + std::to_string(v.points) + " vertices";
  if (v.map_photos < v.rasters.size())
    s += " (normal map from " + std::to_string(v.map_photos) + " photos, their lights spread evenly)";
  if (v.too_large)
    return s + ", beyond the " + fixed(settings.max_correction_px, 1) +
           " px this refines: camera unchanged (register the photos to the mesh again in MeshLab)";
  const std::string residuals = "the fitted model's residual over " + std::to_string(v.residual_vertices) +
                                " vertices: given camera " + three_significant(v.residual_given) + ", corrected " +
                                three_significant(v.residual_corrected);
  if (v.refused)
    return s + ", above " + fixed(settings.threshold_px) + " px, but " + residuals +
           ": the corrected camera explains the photos worse, camera unchanged";
  if (!v.applied) return s + ", below " + fixed(settings.threshold_px) + " px: camera unchanged";
  s += " -> " + fixed(v.after_px) + " px after correction (shift " + fixed(v.shift_x) + ", " + fixed(v.shift_y) +
       " px at the principal point";
  s += v.roll_determined ? ", roll " + fixed(degrees(v.correction.roll), 3) + " deg" : ", roll not determined";
  s += v.scale_determined ? ", focal x" + fixed(std::exp(v.correction.log_scale), 4) : ", focal not determined";
  s += ")";
  if (v.residual_checked && v.residual_beyond_trust)
    s += "; " + residuals + ", least " + fixed(std::hypot(v.residual_found_x, v.residual_found_y)) +
         " px from the correction, farther than the " + fixed(v.residual_trusted_px) +
         " px it refines (a residual made with normals that are off, as a smoothed scan's, is biased): "
         "the normal map's correction kept";
  else if (v.residual_checked)
    s += "; " + residuals + ", " + three_significant(v.residual_final) + " with the shift refined by " +
         fixed(v.refined_x, 3) + ", " + fixed(v.refined_y, 3) + " px and the roll by " +
         fixed(degrees(v.refined_roll), 3) + " deg";
  return s;
}

RegistrationResult refine_registration(const MeshView &mesh, const std::vector<Raster> &rasters,
                                       const std::vector<LightSource> &lights, PhotoCache &photos,
                                       VisibilityBackend &visibility, const RegistrationSettings &settings,
                                       const LogFn &log) {
  const auto t = Clock::now();
  RegistrationResult result;
  result.rasters = rasters;
  for (const Viewpoint &vp : group_viewpoints(rasters)) {
    result.viewpoints.push_back(register_viewpoint(mesh, rasters, vp, lights, photos, visibility, settings));
    const ViewpointRegistration &v = result.viewpoints.back();
    if (v.applied)
      for (size_t r : vp.rasters) result.rasters[r].shot = v.corrected;
    if (v.too_large) {
      result.warnings.push_back("WARNING: the camera of viewpoint '" + v.label + "' is " + fixed(v.before_px) +
                                " px off its photos, more than registration refinement corrects (" +
                                fixed(settings.max_correction_px, 1) +
                                " px): register the photos to the mesh again in MeshLab (e.g. Raster alignment).");
      if (log) log(result.warnings.back());
    }
    if (log) log("Registration: " + describe_registration(v, settings) + ".");
  }
  result.seconds = seconds_since(t);
  return result;
}

} // namespace vbrdf
