#include "calibration/sphere_lights.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <set>

#include <opencv2/imgproc.hpp>

#include "base/clip_level.h"
#include "base/errors.h"
#include "base/number_format.h"
#include "inputs/photo.h"
#include "base/vec3.h"

namespace vbrdf {

namespace {


// --- Constants of detect_spheres (lengths in full-resolution image pixels unless said) ---------
// Bright spots: the brightest local maxima of each photo, where a mirror sphere's highlight is.
constexpr double kSpotMinPeak = 0.2;        // a spot is at least this bright (fraction of full scale)
constexpr int kSpotsPerPhoto = 3;           // spots kept per photo (the highlight, plus the object's)
constexpr int kSpotMinSeparationPx = 2;     // spots closer than max(this, min radius) are one
constexpr double kSpotInsideRadii = 0.97;   // a spot within this fraction of the radius is inside
// Hough circles on the reduced max and median images (pixels of the reduced image).
constexpr int kHoughMinRegionPx = 8;              // smaller search regions are skipped
constexpr double kHoughMinRadiusPx = 2;           // smallest radius searched
constexpr double kHoughStretchExponent = 0.25;    // fourth root: a dark sphere's faint glow shows
constexpr double kHoughWhitePercentile = 0.99;    // this percentile maps to white (whole image)
constexpr double kHoughTrackWhitePercentile = 0.9;  // ... near the highlight track (a small region)
constexpr float kHoughMinWhiteLevel = 1e-3f;      // the white level of a black image
constexpr double kHoughBlurSigmaPx = 1.5;         // blur before Canny
constexpr double kHoughMinCentreDistancePx = 4;   // closest centres (or the smallest radius)
constexpr double kHoughCannyThreshold = 40;       // upper Canny threshold (8-bit)
constexpr double kHoughAccumulatorThreshold = 20; // votes a circle needs
constexpr size_t kHoughMaxCircles = 12;           // strongest circles kept per search
// Around the highlight track (the smallest circle holding most photos' spots).
constexpr double kTrackReachRadii = 5;    // Hough search region: track radius times this ...
constexpr double kTrackReachPx = 20;      // ... plus this
constexpr double kOutermostGapPx = 1;     // outermost-edge search starts this far outside the track
constexpr double kOutermostReachRadii = 4;  // ... and ends at track radius times this ...
constexpr double kOutermostReachPx = 10;    // ... plus this
// Outline edges (make_edge_image) of the full-resolution max and median images.
constexpr double kEdgeExponent = 0.25;  // fourth root, as for Hough
constexpr double kEdgeSigmaPx = 1.0;    // gradient blur
// Refinement and plausibility of a candidate.
constexpr double kRefineShiftMinPx = 2;      // the outline is searched within max(this, ...
constexpr double kRefineShiftRadii = 0.15;   // ... this fraction of the radius) of the candidate
constexpr double kMinOutlineCoverage = 0.5;  // the outline shows on at least this fraction of its length
constexpr size_t kMinPhotosWithSpots = 3;    // with fewer photos with spots, the outline score decides
constexpr size_t kMinSupportTenths = 7;      // a sphere holds a spot in 70 % of the photos with spots ...
constexpr size_t kMinSupportPhotos = 3;      // ... and in at least this many
constexpr double kBorderTolerancePx = 1.0;   // a sphere may touch the image border by this much
// Merging duplicates: centres within this fraction of the smaller radius, radii within this one.
constexpr double kSameSphereCentreRadii = 0.5;
constexpr double kSameSphereRadiusRadii = 0.3;
constexpr double kOuterOutlineMinScore = 0.6;  // the outer outline wins unless below this of the inner's score
// Nested candidates: the inner one is dropped when the outer one, with as much support, has at
// least this fraction of its score (the inner one is the edge of the highlight cloud).
constexpr double kNestedOuterMinScore = 0.3;
constexpr double kNestedSlackPx = 1;      // "inside" allows this much overlap
constexpr double kFinalRefineShiftPx = 2.0;  // refine_sphere's search range for the final outline
// check_sphere_circle: a given circle is the sphere's when the strongest outline near it (within
// the refinement's reach) is at most max(this many pixels, this fraction of the radius) away.
// Detected and published outlines of the same sphere differ by up to 0.7 % of the radius
// (tests/calib/RESULTS.md); a circle with y counted from the wrong edge is off by far more.
constexpr double kCircleCheckMinOffsetPx = 3.0;
constexpr double kCircleCheckOffsetRadii = 0.03;



std::string photo_name(const std::vector<std::string> &names, size_t i) {
  if (i < names.size() && !names[i].empty()) return "'" + names[i] + "'";
  return "photo " + std::to_string(i + 1);
}

double mean_focal(const SphereCamera &cam) { return 0.5 * (cam.fx + cam.fy); }

// Two unit vectors orthogonal to `axis` (unit) and to each other.
void orthonormal_basis(const double axis[3], double e1[3], double e2[3]) {
  const double helper[3] = {std::fabs(axis[0]) < 0.9 ? 1.0 : 0.0, std::fabs(axis[0]) < 0.9 ? 0.0 : 1.0, 0.0};
  cross3(axis, helper, e1);
  normalize3(e1);
  cross3(axis, e1, e2);
  normalize3(e2);
}

// Outline circle of a model: the projected contour is an ellipse; its centre and the geometric
// mean of its semi-axes are what a circle fitted to it gives (and what a user measures).
SphereCircle outline_circle(const SphereCamera &cam, const SphereModel &m) {
  if (!cam.perspective) return m.circle;
  const std::vector<cv::Point2d> pts = sphere_outline(cam, m, 64);
  SphereCircle c;
  if (pts.size() < 5) return c;
  std::vector<cv::Point2f> f(pts.begin(), pts.end());
  const cv::RotatedRect e = cv::fitEllipse(f);
  c.x = e.center.x;
  c.y = e.center.y;
  c.r = 0.5 * std::sqrt(double(e.size.width) * double(e.size.height));
  return c;
}

// Search parameters of a sphere: image of the centre (u, v) and a radius-like rho in pixels
// (orthographic: the radius; perspective: f * tan(half_angle), the radius it would have on axis).
struct SphereParams {
  double u, v, rho;
};

SphereParams params_of(const SphereCamera &cam, const SphereModel &m) {
  if (!cam.perspective) return {m.circle.x, m.circle.y, m.circle.r};
  return {m.centre_x, m.centre_y, mean_focal(cam) * std::tan(m.half_angle)};
}

SphereModel model_of(const SphereCamera &cam, const SphereParams &p) {
  if (!cam.perspective) return sphere_from_centre(cam, p.u, p.v, p.rho);
  return sphere_from_centre(cam, p.u, p.v, std::atan(std::max(p.rho, 1e-6) / mean_focal(cam)));
}

// Bilinear sample of a CV_32FC1 image at image-pixel coordinates; false outside.
bool sample_f(const cv::Mat &m, double x, double y, float &out) {
  const double fx = x - 0.5, fy = y - 0.5;
  const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= m.cols || y0 + 1 >= m.rows) return false;
  const float ax = float(fx - x0), ay = float(fy - y0);
  const float *r0 = m.ptr<float>(y0), *r1 = m.ptr<float>(y0 + 1);
  out = (1 - ay) * ((1 - ax) * r0[x0] + ax * r0[x0 + 1]) + ay * ((1 - ax) * r1[x0] + ax * r1[x0 + 1]);
  return true;
}

// Gradients of a grey image for outline search, after a power stretch (exponent < 1) so that
// the faint outline of a dark sphere weighs like that of a bright one, and a blur of `sigma`
// pixels. `offset` is the image position of pixel (0, 0) of these gradients (a crop).
struct EdgeImage {
  cv::Mat gx, gy;
  cv::Point2d offset{0, 0};
  double norm = 1;  // robust scale of strong gradients in the image
};

EdgeImage make_edge_image(const cv::Mat &gray, double exponent, double sigma, cv::Point2d offset = {0, 0}) {
  EdgeImage e;
  e.offset = offset;
  cv::Mat s;
  cv::max(gray, 0.0, s);
  cv::pow(s, exponent, s);
  cv::GaussianBlur(s, s, cv::Size(0, 0), sigma);
  cv::Sobel(s, e.gx, CV_32F, 1, 0, 3, 1.0 / 8);
  cv::Sobel(s, e.gy, CV_32F, 0, 1, 3, 1.0 / 8);
  cv::Mat mag;
  cv::magnitude(e.gx, e.gy, mag);
  // 95th percentile of the non-zero gradients: the level of a clear edge in this image.
  std::vector<float> v;
  v.reserve(mag.total());
  for (int y = 0; y < mag.rows; ++y) {
    const float *row = mag.ptr<float>(y);
    for (int x = 0; x < mag.cols; ++x)
      if (row[x] > 1e-5f) v.push_back(row[x]);
  }
  if (!v.empty()) {
    const size_t k = size_t(0.95 * double(v.size() - 1));
    std::nth_element(v.begin(), v.begin() + long(k), v.end());
    e.norm = std::max(double(v[k]), 1e-4);
  }
  return e;
}

// Mean absolute radial gradient along the outline, relative to the image's edge level. Points
// outside the image count as zero, so a sphere cut by the border scores lower.
double edge_score(const EdgeImage &e, const SphereCamera &cam, const SphereModel &m) {
  const double r = m.circle.r;
  if (!(r > 0)) return 0;
  const int n = std::max(64, std::min(720, int(2 * kPi * r)));
  const std::vector<cv::Point2d> pts = sphere_outline(cam, m, n);
  if (pts.empty()) return 0;
  double sum = 0;
  for (const auto &p : pts) {
    double ux = p.x - m.circle.x, uy = p.y - m.circle.y;
    const double len = std::hypot(ux, uy);
    if (len <= 0) continue;
    ux /= len;
    uy /= len;
    float gx, gy;
    const double x = p.x - e.offset.x, y = p.y - e.offset.y;
    if (!sample_f(e.gx, x, y, gx) || !sample_f(e.gy, x, y, gy)) continue;
    sum += std::fabs(gx * ux + gy * uy);
  }
  return sum / double(pts.size()) / e.norm;
}

// Fraction of 32 angular sectors of the outline whose mean radial gradient reaches a quarter of
// the outline's mean: near 1 for a round outline, small for the corner of a box that happens to
// score well on a few sectors.
double edge_coverage(const EdgeImage &e, const SphereCamera &cam, const SphereModel &m) {
  const int sectors = 32, per = 8;
  const std::vector<cv::Point2d> pts = sphere_outline(cam, m, sectors * per);
  if (pts.empty()) return 0;
  std::vector<double> s(sectors, 0.0);
  double mean = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    double ux = pts[i].x - m.circle.x, uy = pts[i].y - m.circle.y;
    const double len = std::hypot(ux, uy);
    float gx, gy;
    const double x = pts[i].x - e.offset.x, y = pts[i].y - e.offset.y;
    if (len <= 0 || !sample_f(e.gx, x, y, gx) || !sample_f(e.gy, x, y, gy)) continue;
    const double v = std::fabs(gx * ux / len + gy * uy / len);
    s[i / per] += v / per;
    mean += v / double(pts.size());
  }
  int covered = 0;
  for (double v : s) covered += v >= 0.25 * mean && mean > 0;
  return double(covered) / sectors;
}

// Pattern search of (u, v, rho) maximising `score` within +-max_shift of the start.
template <class Score>
SphereModel pattern_search(const SphereCamera &cam, const SphereModel &start, double max_shift, const Score &score,
                           double *score_out) {
  const SphereParams p0 = params_of(cam, start);
  SphereParams best = p0;
  double best_score = score(start);
  double step = std::max(0.25, max_shift / 4);
  while (step > 0.02) {
    bool moved = false;
    for (int k = 0; k < 6; ++k) {
      SphereParams q = best;
      double &c = k / 2 == 0 ? q.u : (k / 2 == 1 ? q.v : q.rho);
      c += (k % 2 ? -step : step);
      if (std::fabs(q.u - p0.u) > max_shift || std::fabs(q.v - p0.v) > max_shift ||
          std::fabs(q.rho - p0.rho) > max_shift || q.rho < 2)
        continue;
      const double s = score(model_of(cam, q));
      if (s > best_score) {
        best_score = s;
        best = q;
        moved = true;
      }
    }
    if (!moved) step *= 0.5;
  }
  if (score_out) *score_out = best_score;
  return model_of(cam, best);
}

SphereModel refine_on(const EdgeImage &e, const SphereCamera &cam, const SphereModel &start, double max_shift,
                      double *score_out) {
  return pattern_search(
      cam, start, max_shift, [&](const SphereModel &m) { return edge_score(e, cam, m); }, score_out);
}

// How far the outline is from the half-way crossings of a linear image: for any symmetric blur,
// at the true outline I(p) = (I(p - d n) + I(p + d n)) / 2 along the outward normal n. Returns
// -sum(mismatch^2) / sum(contrast^2) (0 is perfect), so dark and bright spheres weigh alike.
double crossing_score(const cv::Mat &img, cv::Point2d offset, const SphereCamera &cam, const SphereModel &m) {
  const double r = m.circle.r;
  if (!(r > 0)) return -1e9;
  const int n = std::max(64, std::min(1440, int(2 * kPi * r)));
  const double d = std::max(1.5, 0.006 * r);
  const std::vector<cv::Point2d> pts = sphere_outline(cam, m, n);
  double se = 0, sc = 0;
  for (const auto &p : pts) {
    double ux = p.x - m.circle.x, uy = p.y - m.circle.y;
    const double len = std::hypot(ux, uy);
    if (len <= 0) continue;
    ux /= len;
    uy /= len;
    const double x = p.x - offset.x, y = p.y - offset.y;
    float i0, in, out;
    if (!sample_f(img, x, y, i0) || !sample_f(img, x - d * ux, y - d * uy, in) ||
        !sample_f(img, x + d * ux, y + d * uy, out))
      continue;
    const double e = i0 - 0.5 * (double(in) + out);
    se += e * e;
    sc += (double(in) - out) * (double(in) - out);
  }
  return sc > 0 ? -se / sc : -1e9;
}

// Median value of a CV_32FC1 image under a mask (all pixels when the mask is empty).
double masked_median(const cv::Mat &img, const cv::Mat &mask) {
  std::vector<float> v;
  v.reserve(img.total());
  for (int y = 0; y < img.rows; ++y) {
    const float *row = img.ptr<float>(y);
    const uchar *mr = mask.empty() ? nullptr : mask.ptr<uchar>(y);
    for (int x = 0; x < img.cols; ++x)
      if (!mr || mr[x]) v.push_back(row[x]);
  }
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

cv::Mat median_image(const std::vector<cv::Mat> &stack) {
  cv::Mat out(stack[0].size(), CV_32F);
  std::vector<float> v(stack.size());
  for (int y = 0; y < out.rows; ++y)
    for (int x = 0; x < out.cols; ++x) {
      for (size_t i = 0; i < stack.size(); ++i) v[i] = stack[i].at<float>(y, x);
      std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
      out.at<float>(y, x) = v[v.size() / 2];
    }
  return out;
}

bool circle_inside(const SphereCircle &c, int w, int h, double tolerance) {
  return c.x - c.r >= -tolerance && c.y - c.r >= -tolerance && c.x + c.r <= w + tolerance &&
         c.y + c.r <= h + tolerance;
}

struct Candidate {
  SphereModel model;
  bool hough = false, track = false;
  std::set<std::string> sources;
  double score = 0;
  bool on_median = false;  // its outline is clearer in the median image than in the max image
  double coverage = 0;     // see edge_coverage()
  int support = 0;
};

std::string join(const std::set<std::string> &items) {
  std::string out;
  for (const auto &s : items) out += (out.empty() ? "" : " and ") + s;
  return out;
}

// Up to `k` brightest spots (local maxima of the blurred image, at least `min_peak` and half the
// brightest, `sep` pixels apart) of a grey image: a mirror sphere's highlight is usually one.
std::vector<cv::Point2d> bright_spots(const cv::Mat &gray, double min_peak, int k, int sep) {
  cv::Mat s, dil;
  cv::GaussianBlur(gray, s, cv::Size(0, 0), 1.0);
  cv::dilate(s, dil, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * sep + 1, 2 * sep + 1)));
  double mx;
  cv::minMaxLoc(s, nullptr, &mx);
  const double level = std::max(min_peak, 0.5 * mx);
  std::vector<std::pair<float, cv::Point>> peaks;
  for (int y = 0; y < s.rows; ++y) {
    const float *r = s.ptr<float>(y), *d = dil.ptr<float>(y);
    for (int x = 0; x < s.cols; ++x)
      if (r[x] >= level && r[x] >= d[x]) peaks.emplace_back(r[x], cv::Point(x, y));
  }
  std::sort(peaks.begin(), peaks.end(), [](const std::pair<float, cv::Point> &a, const std::pair<float, cv::Point> &b) {
    return a.first > b.first;
  });
  std::vector<cv::Point2d> out;
  for (const auto &p : peaks) {
    if (int(out.size()) >= k) break;
    bool near = false;
    for (const auto &q : out) near = near || std::hypot(q.x - p.second.x - 0.5, q.y - p.second.y - 0.5) < sep;
    if (!near) out.emplace_back(p.second.x + 0.5, p.second.y + 0.5);
  }
  return out;
}

// Circle around the track of the highlights. The highlights of one sphere stay inside it in
// (nearly) every photo, those on the object wander: the track's centre is the spot with the
// smallest radius holding a spot of 60% of the photos; the track is then each photo's spot
// nearest to it (within twice that radius), and the circle encloses them.
bool track_circle(const std::vector<std::vector<cv::Point2d>> &spots, double max_r, SphereCircle &out) {
  std::vector<const std::vector<cv::Point2d> *> photos;
  for (const auto &s : spots)
    if (!s.empty()) photos.push_back(&s);
  if (photos.size() < 3) return false;
  const size_t need = std::max<size_t>(3, (photos.size() * 6 + 9) / 10);
  double best_d = 1e300;
  cv::Point2d best;
  std::vector<double> d(photos.size());
  for (const auto *ps : photos)
    for (const auto &p : *ps) {
      for (size_t j = 0; j < photos.size(); ++j) {
        d[j] = 1e300;
        for (const auto &q : *photos[j]) d[j] = std::min(d[j], cv::norm(q - p));
      }
      std::nth_element(d.begin(), d.begin() + long(need - 1), d.end());
      if (d[need - 1] < best_d) {
        best_d = d[need - 1];
        best = p;
      }
    }
  if (best_d > max_r) return false;
  std::vector<cv::Point2f> cloud;
  for (const auto *ps : photos) {
    double dmin = 1e300;
    cv::Point2d q0;
    for (const auto &q : *ps)
      if (cv::norm(q - best) < dmin) {
        dmin = cv::norm(q - best);
        q0 = q;
      }
    if (dmin <= std::max(2 * best_d, 3.0)) cloud.emplace_back(float(q0.x), float(q0.y));
  }
  if (cloud.size() < 3) return false;
  cv::Point2f c;
  float r;
  cv::minEnclosingCircle(cloud, c, r);
  out = SphereCircle{c.x, c.y, std::max(1.0f, r)};
  return true;
}

// Radius (for a fixed centre) of the outermost clear outline between r_min and r_max: around a
// cloud of highlights the sphere's own outline is the last circular edge, the edges of the
// highlights lie inside it.
double outermost_radius(const EdgeImage &e, const SphereCamera &cam, double u, double v, double r_min, double r_max) {
  std::vector<double> rs, ss;
  for (double r = r_min; r <= r_max; r += std::max(0.5, r * 0.01)) {
    rs.push_back(r);
    ss.push_back(edge_score(e, cam, sphere_from_circle(cam, SphereCircle{u, v, r})));
  }
  if (rs.empty()) return r_min;
  const double top = *std::max_element(ss.begin(), ss.end());
  for (size_t i = rs.size(); i-- > 0;) {
    const bool local_max = (i == 0 || ss[i] >= ss[i - 1]) && (i + 1 == rs.size() || ss[i] >= ss[i + 1]);
    if (local_max && ss[i] >= 0.3 * top && i + 1 < rs.size()) return rs[i];
  }
  return rs[size_t(std::max_element(ss.begin(), ss.end()) - ss.begin())];
}

} // namespace

SphereCamera camera_from_shot(const Shot &shot) {
  SphereCamera c;
  const auto &in = shot.Intrinsics;
  c.perspective = true;
  c.fx = double(in.FocalMm) / double(in.PixelSizeMm[0]);
  c.fy = double(in.FocalMm) / double(in.PixelSizeMm[1]);
  c.px = in.CenterPx[0];
  c.py = double(in.ViewportPx[1]) - double(in.CenterPx[1]);
  return c;
}

void pixel_ray(const SphereCamera &cam, double x, double y, double ray[3]) {
  if (!cam.perspective) {
    ray[0] = 0;
    ray[1] = 0;
    ray[2] = -1;
    return;
  }
  ray[0] = (x - cam.px) / cam.fx;
  ray[1] = -(y - cam.py) / cam.fy;
  ray[2] = -1;
  normalize3(ray);
}

bool project_direction(const SphereCamera &cam, const double dir[3], double &x, double &y) {
  if (!(dir[2] < -1e-12)) return false;
  x = cam.px + cam.fx * dir[0] / -dir[2];
  y = cam.py - cam.fy * dir[1] / -dir[2];
  return true;
}

SphereModel sphere_from_centre(const SphereCamera &cam, double cx, double cy, double radius) {
  SphereModel m;
  m.centre_x = cx;
  m.centre_y = cy;
  if (!cam.perspective) {
    m.circle = SphereCircle{cx, cy, radius};
    return m;
  }
  pixel_ray(cam, cx, cy, m.axis);
  m.half_angle = radius;
  m.circle = outline_circle(cam, m);
  return m;
}

SphereModel sphere_from_circle(const SphereCamera &cam, const SphereCircle &circle) {
  if (!cam.perspective) return sphere_from_centre(cam, circle.x, circle.y, circle.r);
  // The outline rays of a sphere form a circular cone: their unit vectors lie on a plane
  // axis . ray = cos(half_angle). Fit that plane to rays through points of the circle.
  const int n = 90;
  cv::Mat rays(n, 3, CV_64F);
  for (int i = 0; i < n; ++i) {
    const double t = 2 * kPi * i / n;
    pixel_ray(cam, circle.x + circle.r * std::cos(t), circle.y + circle.r * std::sin(t), rays.ptr<double>(i));
  }
  cv::PCA pca(rays, cv::noArray(), cv::PCA::DATA_AS_ROW);
  double axis[3] = {pca.eigenvectors.at<double>(2, 0), pca.eigenvectors.at<double>(2, 1),
                    pca.eigenvectors.at<double>(2, 2)};
  const double *mean = pca.mean.ptr<double>(0);
  if (dot3(axis, mean) < 0)
    for (double &a : axis) a = -a;
  const double c = std::min(1.0, dot3(axis, mean));
  double x, y;
  if (!project_direction(cam, axis, x, y)) return SphereModel{};
  SphereModel m = sphere_from_centre(cam, x, y, std::acos(c));
  // The plane fit treats the circle as the outline; the true outline is an ellipse whose centre
  // and mean radius should match the circle: a few fixed-point steps make them match.
  for (int iter = 0; iter < 8 && m.circle.r > 0; ++iter) {
    const double dx = circle.x - m.circle.x, dy = circle.y - m.circle.y, k = circle.r / m.circle.r;
    if (std::fabs(dx) + std::fabs(dy) + std::fabs(k - 1) * circle.r < 1e-6) break;
    SphereParams p = params_of(cam, m);
    p.u += dx;
    p.v += dy;
    p.rho *= k;
    const SphereModel next = model_of(cam, p);
    if (!(next.circle.r > 0)) break;
    m = next;
  }
  return m;
}

std::vector<cv::Point2d> sphere_outline(const SphereCamera &cam, const SphereModel &m, int n) {
  std::vector<cv::Point2d> pts;
  pts.reserve(size_t(std::max(n, 0)));
  if (!cam.perspective) {
    for (int i = 0; i < n; ++i) {
      const double t = 2 * kPi * i / n;
      pts.emplace_back(m.circle.x + m.circle.r * std::cos(t), m.circle.y + m.circle.r * std::sin(t));
    }
    return pts;
  }
  double e1[3], e2[3];
  orthonormal_basis(m.axis, e1, e2);
  const double ca = std::cos(m.half_angle), sa = std::sin(m.half_angle);
  for (int i = 0; i < n; ++i) {
    const double t = 2 * kPi * i / n;
    double ray[3];
    for (int k = 0; k < 3; ++k) ray[k] = ca * m.axis[k] + sa * (std::cos(t) * e1[k] + std::sin(t) * e2[k]);
    double x, y;
    if (!project_direction(cam, ray, x, y)) return {};
    pts.emplace_back(x, y);
  }
  return pts;
}

bool highlight_to_light(const SphereCamera &cam, const SphereModel &m, double hx, double hy, double light[3],
                        double normal[3], double point[3]) {
  double n[3], p[3], v[3];
  if (!cam.perspective) {
    if (!(m.circle.r > 0)) return false;
    n[0] = (hx - m.circle.x) / m.circle.r;
    n[1] = -(hy - m.circle.y) / m.circle.r;
    const double q = 1 - n[0] * n[0] - n[1] * n[1];
    if (q < 0) return false;
    n[2] = std::sqrt(q);
    v[0] = 0;
    v[1] = 0;
    v[2] = 1;
    p[0] = m.circle.x + m.circle.r * n[0];
    p[1] = -m.circle.y + m.circle.r * n[1];
    p[2] = m.circle.r * n[2];
  } else {
    // Sphere of radius sin(half_angle) centred at distance 1 on the axis; nearest intersection.
    double d[3];
    pixel_ray(cam, hx, hy, d);
    const double s = std::sin(m.half_angle), c = std::cos(m.half_angle);
    const double b = dot3(d, m.axis);
    const double disc = b * b - c * c;
    if (disc < 0 || !(s > 0)) return false;
    const double t = b - std::sqrt(disc);
    for (int k = 0; k < 3; ++k) {
      p[k] = t * d[k];
      n[k] = (p[k] - m.axis[k]) / s;
      v[k] = -d[k];
    }
    normalize3(n);
  }
  const double nv = dot3(n, v);
  for (int k = 0; k < 3; ++k) light[k] = 2 * nv * n[k] - v[k];
  normalize3(light);
  if (normal)
    for (int k = 0; k < 3; ++k) normal[k] = n[k];
  if (point)
    for (int k = 0; k < 3; ++k) point[k] = p[k];
  return true;
}

bool light_to_highlight(const SphereCamera &cam, const SphereModel &m, const double light_in[3], double &hx,
                        double &hy) {
  double l[3] = {light_in[0], light_in[1], light_in[2]};
  normalize3(l);
  if (!cam.perspective) {
    double n[3] = {l[0], l[1], l[2] + 1};
    normalize3(n);
    if (!(n[2] > 0)) return false;
    hx = m.circle.x + m.circle.r * n[0];
    hy = m.circle.y - m.circle.r * n[1];
    return true;
  }
  // Fixed point: the normal bisects the light and the direction to the camera at the point.
  const double s = std::sin(m.half_angle);
  double n[3], p[3], v[3];
  for (int k = 0; k < 3; ++k) n[k] = l[k] - m.axis[k];
  normalize3(n);
  for (int iter = 0; iter < 100; ++iter) {
    for (int k = 0; k < 3; ++k) p[k] = m.axis[k] + s * n[k];
    for (int k = 0; k < 3; ++k) v[k] = -p[k];
    normalize3(v);
    double nn[3] = {l[0] + v[0], l[1] + v[1], l[2] + v[2]};
    normalize3(nn);
    double change = 0;
    for (int k = 0; k < 3; ++k) {
      change += std::fabs(nn[k] - n[k]);
      n[k] = nn[k];
    }
    if (change < 1e-14) break;
  }
  for (int k = 0; k < 3; ++k) p[k] = m.axis[k] + s * n[k];
  for (int k = 0; k < 3; ++k) v[k] = -p[k];
  normalize3(v);
  if (dot3(n, v) <= 0) return false;
  double dir[3] = {p[0], p[1], p[2]};
  normalize3(dir);
  return project_direction(cam, dir, hx, hy);
}

double angle_deg(const double a[3], const double b[3]) {
  const double na = std::sqrt(dot3(a, a)), nb = std::sqrt(dot3(b, b));
  if (!(na > 0) || !(nb > 0)) return 180;
  double cr[3];
  cross3(a, b, cr);
  // atan2 keeps precision for small angles, where acos does not.
  return degrees(std::atan2(std::sqrt(dot3(cr, cr)), dot3(a, b)));
}

cv::Mat gray_image(const cv::Mat &image, bool decode_srgb) {
  if (image.empty()) return cv::Mat();
  cv::Mat f;
  try {
    f = decode_to_linear(image, decode_srgb);  // 8-bit photos are sRGB: decoded so that intensities add like light
  } catch (const InputError &e) {
    throw InputError(std::string("Sphere detection: ") + e.what());
  }
  if (f.channels() == 1) return f;
  std::vector<cv::Mat> ch;
  cv::split(f, ch);
  const int n = std::min(3, int(ch.size()));
  cv::Mat sum = ch[0].clone();
  for (int i = 1; i < n; ++i) sum += ch[i];
  return sum / double(n);
}

Highlight find_highlight(const cv::Mat &gray, const SphereCircle &c, const HighlightSettings &s) {
  Highlight h;
  CV_Assert(gray.type() == CV_32FC1);
  const double rs = c.r * (1 - s.rim_margin);
  const cv::Rect box = cv::Rect(int(std::floor(c.x - rs)), int(std::floor(c.y - rs)), int(std::ceil(2 * rs)) + 2,
                                int(std::ceil(2 * rs)) + 2) &
                       cv::Rect(0, 0, gray.cols, gray.rows);
  if (!(rs > 0) || box.area() == 0) {
    h.problem = "the sphere is outside the image";
    return h;
  }
  const cv::Mat roi = gray(box);
  cv::Mat mask(box.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < box.height; ++y)
    for (int x = 0; x < box.width; ++x)
      if (std::hypot(box.x + x + 0.5 - c.x, box.y + y + 0.5 - c.y) <= rs) mask.at<uchar>(y, x) = 255;
  if (cv::countNonZero(mask) < 9) {
    h.problem = "the visible part of the sphere is too small";
    return h;
  }
  // A blur of about a hundredth of the radius hides noise and scratches, not the highlight.
  cv::Mat smooth;
  cv::GaussianBlur(roi, smooth, cv::Size(0, 0), std::max(0.8, c.r / 150));
  double peak, raw_peak;
  cv::Point peak_at;
  cv::minMaxLoc(smooth, nullptr, &peak, nullptr, &peak_at, mask);
  cv::minMaxLoc(roi, nullptr, &raw_peak, nullptr, nullptr, mask);
  h.peak = peak;
  h.background = masked_median(roi, mask);
  if (peak < s.min_peak) {
    h.problem = formatted("no highlight: the brightest point of the sphere is %.2f of full scale (sphere in shadow, "
                    "or the light is behind it)",
                    peak);
    return h;
  }
  if (peak - h.background < s.min_contrast) {
    h.problem = formatted("no distinct highlight: brightest %.2f, sphere median %.2f (sphere in shadow or overexposed)",
                    peak, h.background);
    return h;
  }
  const double min_area = std::max(s.min_area_px, s.min_area_fraction * kPi * c.r * c.r);
  const double lowest = h.background + 0.5 * (peak - h.background);
  double t = raw_peak >= s.start_level ? s.start_level : raw_peak * (1 - s.level_step);
  cv::Mat labels, stats, centroids, best_blob;
  double best_t = t;
  for (; t >= lowest || best_blob.empty(); t -= s.level_step * raw_peak) {
    if (t <= 0) break;
    cv::Mat bin = (roi >= t) & mask;
    cv::connectedComponentsWithStats(bin, labels, stats, centroids, 8, CV_32S);
    const int label = labels.at<int>(peak_at);
    if (label == 0) continue;  // the blob has not reached the smoothed peak yet
    best_blob = labels == label;
    best_t = t;
    if (stats.at<int>(label, cv::CC_STAT_AREA) >= min_area) break;
  }
  if (best_blob.empty()) {
    h.problem = "no compact highlight blob";
    return h;
  }
  // A small blob is then widened to the half-maximum level so that its anti-aliased, unsaturated
  // flanks weight the centroid: a small saturated plateau has a pixel-quantised outline. A large
  // core is accurate as it is, and widening it would take in lens flare and scratches.
  {
    const double tw = lowest;
    const int core_area = cv::countNonZero(best_blob);
    if (tw < best_t && core_area < 100) {
      cv::Mat bin = (roi >= tw) & mask;
      cv::connectedComponentsWithStats(bin, labels, stats, centroids, 8, CV_32S);
      const int label = labels.at<int>(peak_at);
      if (label > 0) {
        best_blob = labels == label;
        best_t = tw;
      }
    }
  }
  // Intensity above the threshold weights the centroid: a saturated plateau counts uniformly.
  double sw = 0, sx = 0, sy = 0, su = 0, ux = 0, uy = 0;
  int area = 0;
  bool saturated = false;
  for (int y = 0; y < roi.rows; ++y) {
    const uchar *b = best_blob.ptr<uchar>(y);
    const float *r = roi.ptr<float>(y);
    for (int x = 0; x < roi.cols; ++x) {
      if (!b[x]) continue;
      const double w = std::max(0.0, double(r[x]) - best_t);
      const double px = box.x + x + 0.5, py = box.y + y + 0.5;
      sw += w;
      sx += w * px;
      sy += w * py;
      su += 1;
      ux += px;
      uy += py;
      ++area;
      saturated = saturated || r[x] >= kClippedLinearValue;
    }
  }
  h.found = true;
  h.x = sw > 0 ? sx / sw : ux / su;
  h.y = sw > 0 ? sy / sw : uy / su;
  h.threshold = best_t;
  h.area = area;
  h.saturated = saturated;
  return h;
}

const char *sphere_method_name(SphereMethod m) {
  switch (m) {
  case SphereMethod::Manual: return "manual centre and radius";
  case SphereMethod::Hough: return "Hough circles on the median/max image";
  case SphereMethod::HighlightTrack: return "highlight track across the photos";
  }
  return "?";
}

SphereModel refine_sphere(const cv::Mat &gray, const SphereCamera &cam, const SphereModel &start, double max_shift,
                          double *score) {
  CV_Assert(gray.type() == CV_32FC1);
  const SphereCircle &c = start.circle;
  const double margin = c.r * 1.15 + max_shift + 8;
  const cv::Rect box = cv::Rect(int(c.x - margin), int(c.y - margin), int(2 * margin), int(2 * margin)) &
                       cv::Rect(0, 0, gray.cols, gray.rows);
  if (box.area() == 0) {
    if (score) *score = 0;
    return start;
  }
  const cv::Point2d offset(box.x, box.y);
  // Centre: strongest outline of the square-root image (its edge shift is the same all around,
  // so it only biases the radius); radius: half-way crossings of the linear image.
  const EdgeImage e = make_edge_image(gray(box), 0.5, 0.7, offset);
  SphereModel m = refine_on(e, cam, start, max_shift, nullptr);
  cv::Mat img;
  cv::GaussianBlur(gray(box), img, cv::Size(0, 0), 1.0);
  SphereParams p = params_of(cam, m);
  double best = -1e300, best_rho = p.rho;
  for (double rho = p.rho - max_shift; rho <= p.rho + max_shift; rho += 0.02) {
    SphereParams q = p;
    q.rho = rho;
    const double sc = crossing_score(img, offset, cam, model_of(cam, q));
    if (sc > best) {
      best = sc;
      best_rho = rho;
    }
  }
  p.rho = best_rho;
  if (score) *score = best;
  return model_of(cam, p);
}

namespace {

// --- detect_spheres, step by step ------------------------------------------------------------------

// Pass 1 over the photos: the (reduced) max and median images and every photo's brightest spots.
struct PhotoSummary {
  cv::Mat max_img, median_img;                  // at `scale` of the photos
  std::vector<std::vector<cv::Point2d>> spots;  // brightest spots per photo, full resolution
  int width = 0, height = 0;                    // of the photos
  double scale = 1;                             // reduced / full size (1: not reduced)
};

PhotoSummary summarize_photos(size_t count, const GrayLoader &load, const SphereSearch &search) {
  PhotoSummary s;
  s.spots.resize(count);
  std::vector<cv::Mat> median_stack;
  const size_t median_every = std::max<size_t>(1, count / size_t(std::max(1, search.max_median_photos)));
  for (size_t i = 0; i < count; ++i) {
    cv::Mat g = load(i);
    if (g.empty()) continue;
    if (s.width == 0) {
      s.width = g.cols;
      s.height = g.rows;
      s.scale = std::min(1.0, double(search.detect_size) / std::max(s.width, s.height));
    } else if (g.cols != s.width || g.rows != s.height) {
      throw InputError("Sphere detection: photo " + std::to_string(i + 1) +
                       " has a different size from the first photo of the viewpoint");
    }
    // Spots at full resolution: a small highlight would fade in the reduced image.
    const int separation = std::max(kSpotMinSeparationPx, int(search.min_radius_px));
    for (const auto &p : bright_spots(g, kSpotMinPeak, kSpotsPerPhoto, separation)) s.spots[i].push_back(p);
    if (s.scale < 1) cv::resize(g, g, cv::Size(), s.scale, s.scale, cv::INTER_AREA);
    if (s.max_img.empty()) s.max_img = g.clone();
    else s.max_img = cv::max(s.max_img, g);
    if (i % median_every == 0 && median_stack.size() < size_t(search.max_median_photos)) median_stack.push_back(g);
  }
  if (!s.max_img.empty()) s.median_img = median_image(median_stack);
  return s;
}

// HoughCircles on (a region of) a reduced image, radii in [r_lo, r_hi] full-resolution pixels,
// appended to `out` in full-resolution coordinates. Fourth root, then a high percentile to white:
// a dark sphere on a dark ground keeps an outline Canny can see; the highlights clip, which does
// not matter for the outline.
void add_hough_candidates(const cv::Mat &img, double scale, cv::Rect roi, double percentile, double r_lo,
                          double r_hi, const SphereCamera &cam, const std::string &source, bool from_track,
                          std::vector<Candidate> &out) {
  roi &= cv::Rect(0, 0, img.cols, img.rows);
  if (roi.width < kHoughMinRegionPx || roi.height < kHoughMinRegionPx || r_hi * scale < kHoughMinRadiusPx) return;
  cv::Mat s, u8;
  cv::pow(cv::max(img(roi), 0.0), kHoughStretchExponent, s);
  std::vector<float> v(s.begin<float>(), s.end<float>());
  const size_t k = size_t(percentile * double(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + long(k), v.end());
  s.convertTo(u8, CV_8U, 255.0 / std::max(kHoughMinWhiteLevel, v[k]));
  cv::GaussianBlur(u8, u8, cv::Size(0, 0), kHoughBlurSigmaPx);
  std::vector<cv::Vec3f> circles;
  cv::HoughCircles(u8, circles, cv::HOUGH_GRADIENT, 1, std::max(kHoughMinCentreDistancePx, r_lo * scale),
                   kHoughCannyThreshold, kHoughAccumulatorThreshold, int(std::max(kHoughMinRadiusPx, r_lo * scale)),
                   int(std::ceil(r_hi * scale)));
  for (size_t n = 0; n < circles.size() && n < kHoughMaxCircles; ++n) {
    Candidate c;
    // Hough returns pixel-index centres; image pixels put centres at +0.5.
    c.model = sphere_from_circle(cam, SphereCircle{(roi.x + circles[n][0] + 0.5) / scale,
                                                   (roi.y + circles[n][1] + 0.5) / scale, circles[n][2] / scale});
    if (!(c.model.circle.r > 0)) continue;
    c.hough = !from_track;
    c.track = from_track;
    c.sources = {source};
    out.push_back(c);
  }
}

// Hough candidates in the whole median and max images, then around the track of the highlights
// (a dark sphere's outline is too faint to win in the whole image): the sphere contains the track,
// so circles just larger than it are searched, stretching the contrast of that region only.
std::vector<Candidate> hough_candidates(const PhotoSummary &s, const SphereCamera &cam, double min_r, double max_r,
                                        bool have_track, const SphereCircle &track) {
  std::vector<Candidate> cands;
  const cv::Rect whole(0, 0, s.max_img.cols, s.max_img.rows);
  add_hough_candidates(s.median_img, s.scale, whole, kHoughWhitePercentile, min_r, max_r, cam,
                       "Hough on the median image", false, cands);
  add_hough_candidates(s.max_img, s.scale, whole, kHoughWhitePercentile, min_r, max_r, cam, "Hough on the max image",
                       false, cands);
  if (!have_track) return cands;
  const double reach = std::min(max_r, kTrackReachRadii * track.r + kTrackReachPx);
  const double scale = s.scale;
  const cv::Rect roi(int((track.x - reach) * scale), int((track.y - reach) * scale), int(2 * reach * scale) + 1,
                     int(2 * reach * scale) + 1);
  const double r_lo = std::max(min_r, track.r);
  add_hough_candidates(s.median_img, scale, roi, kHoughTrackWhitePercentile, r_lo, reach, cam,
                       "highlight track (Hough near the highlights, median image)", true, cands);
  add_hough_candidates(s.max_img, scale, roi, kHoughTrackWhitePercentile, r_lo, reach, cam,
                       "highlight track (Hough near the highlights, max image)", true, cands);
  return cands;
}

// Pass 2 (only when pass 1 reduced the photos): the max image at full resolution; the median image
// is the reduced one scaled up.
void full_resolution_images(const PhotoSummary &s, size_t count, const GrayLoader &load, cv::Mat &full_max,
                            cv::Mat &full_median) {
  full_max = s.max_img;
  full_median = s.median_img;
  if (s.scale >= 1) return;
  full_max.release();
  for (size_t i = 0; i < count; ++i) {
    cv::Mat g = load(i);
    if (g.empty()) continue;
    if (full_max.empty()) full_max = g.clone();
    else full_max = cv::max(full_max, g);
  }
  cv::resize(s.median_img, full_median, full_max.size(), 0, 0, cv::INTER_LINEAR);
}

// The outermost circular edge around the track's own centre, as a candidate (none when its radius
// collapses).
void add_outermost_edge_candidate(const EdgeImage &edges_max, const SphereCamera &cam, const SphereCircle &track,
                                  double min_r, double max_r, std::vector<Candidate> &cands) {
  const double r = outermost_radius(edges_max, cam, track.x, track.y, std::max(min_r, track.r + kOutermostGapPx),
                                    std::min(max_r, kOutermostReachRadii * track.r + kOutermostReachPx));
  Candidate c;
  c.model = sphere_from_circle(cam, SphereCircle{track.x, track.y, r});
  if (!(c.model.circle.r > 0)) return;
  c.track = true;
  c.sources = {"highlight track (outermost edge)"};
  cands.push_back(c);
}

// Photos holding a bright spot inside `c`, and photos holding any spot.
int spot_support(const std::vector<std::vector<cv::Point2d>> &spots, const SphereCircle &c, size_t &with_spots) {
  int support = 0;
  with_spots = 0;
  for (const auto &ps : spots) {
    with_spots += ps.empty() ? 0 : 1;
    for (const auto &p : ps)
      if (std::hypot(p.x - c.x, p.y - c.y) < kSpotInsideRadii * c.r) {
        ++support;
        break;
      }
  }
  return support;
}

// Refines `c` to its strongest outline in the max or the median image (whichever is clearer) and
// scores it. True when it is a plausible sphere: radius in [min_r, max_r], round all around, and a
// bright spot inside in most photos that have one (a sphere holds one in (nearly) every photo,
// other round things do not) or, without spots, a clear outline.
bool refine_and_score(Candidate &c, const EdgeImage &edges_max, const EdgeImage &edges_med, const SphereCamera &cam,
                      const std::vector<std::vector<cv::Point2d>> &spots, double min_r, double max_r,
                      double min_edge_score) {
  double s_max = 0, s_med = 0;
  const double shift = std::max(kRefineShiftMinPx, kRefineShiftRadii * c.model.circle.r);
  const SphereModel a = refine_on(edges_max, cam, c.model, shift, &s_max);
  const SphereModel b = refine_on(edges_med, cam, c.model, shift, &s_med);
  c.model = s_max >= s_med ? a : b;
  c.score = std::max(s_max, s_med);
  c.on_median = s_max < s_med;
  c.coverage = edge_coverage(c.on_median ? edges_med : edges_max, cam, c.model);
  const SphereCircle &cc = c.model.circle;
  if (cc.r < min_r || cc.r > max_r) return false;
  size_t with_spots = 0;
  c.support = spot_support(spots, cc, with_spots);
  // ceil(with_spots * kMinSupportTenths / 10) in integers.
  const size_t needed = std::max<size_t>(kMinSupportPhotos, (with_spots * kMinSupportTenths + 9) / 10);
  return c.coverage >= kMinOutlineCoverage &&
         (with_spots >= kMinPhotosWithSpots ? c.support >= int(needed) : c.score >= min_edge_score);
}

// Merges `c` into the candidate of `kept` that is the same sphere (close centres and radii), else
// appends it. The merged outline is the outermost of the two unless clearly weaker (the inner one
// is then shading or the edge of the highlight cloud).
void merge_candidate(std::vector<Candidate> &kept, const Candidate &c) {
  const SphereCircle &cc = c.model.circle;
  for (Candidate &k : kept) {
    const SphereCircle &kc = k.model.circle;
    const double r = std::min(kc.r, cc.r);
    if (std::hypot(kc.x - cc.x, kc.y - cc.y) >= kSameSphereCentreRadii * r ||
        std::fabs(kc.r - cc.r) >= kSameSphereRadiusRadii * r)
      continue;
    const bool replace =
        cc.r > kc.r ? c.score >= kOuterOutlineMinScore * k.score : k.score < kOuterOutlineMinScore * c.score;
    if (replace) {
      k.model = c.model;
      k.score = c.score;
      k.support = c.support;
      k.on_median = c.on_median;
      k.coverage = c.coverage;
    }
    k.sources.insert(c.sources.begin(), c.sources.end());
    k.hough = k.hough || c.hough;
    k.track = k.track || c.track;
    return;
  }
  kept.push_back(c);
}

// Best supported first; of two nested candidates with the same support the outer one is kept when
// its outline is clear (the inner one is the edge of the highlight cloud).
void rank_and_drop_nested(std::vector<Candidate> &kept) {
  std::sort(kept.begin(), kept.end(), [](const Candidate &a, const Candidate &b) {
    if (a.support != b.support) return a.support > b.support;
    return a.score > b.score;
  });
  for (size_t i = 0; i < kept.size(); ++i)
    for (size_t j = 0; j < kept.size(); ++j) {
      if (i == j || kept[j].score < 0) continue;
      const SphereCircle &in = kept[i].model.circle, &out = kept[j].model.circle;
      if (kept[i].score >= 0 && in.r < out.r && std::hypot(in.x - out.x, in.y - out.y) + in.r <= out.r + kNestedSlackPx &&
          kept[j].support >= kept[i].support && kept[j].score >= kNestedOuterMinScore * kept[i].score) {
        kept[j].sources.insert(kept[i].sources.begin(), kept[i].sources.end());
        kept[j].track = kept[j].track || kept[i].track;
        kept[i].score = -1;  // dropped
      }
    }
  kept.erase(std::remove_if(kept.begin(), kept.end(), [](const Candidate &c) { return c.score < 0; }), kept.end());
}

// The final sphere of a candidate: refined at full resolution (refine_sphere) in `fine`, with its
// log line.
DetectedSphere detected_sphere(const Candidate &c, const cv::Mat &fine, const SphereCamera &cam, size_t count) {
  DetectedSphere d;
  d.model = refine_sphere(fine, cam, c.model, kFinalRefineShiftPx);
  d.method = c.hough ? SphereMethod::Hough : SphereMethod::HighlightTrack;
  d.edge_score = c.score;
  d.highlights_inside = c.support;
  d.description = formatted("centre (%.2f, %.2f), radius %.2f px", d.model.circle.x, d.model.circle.y, d.model.circle.r) +
                  formatted(", outline contrast %.2f, a bright spot inside in %.0f of %.0f photos", c.score, c.support,
                      double(count)) +
                  "; found by " + join(c.sources);
  return d;
}

} // namespace

std::vector<DetectedSphere> detect_spheres(size_t count, const GrayLoader &load, const SphereCamera &cam,
                                           const SphereSearch &search, std::vector<std::string> &log) {
  std::vector<DetectedSphere> found;
  if (count == 0) return found;
  const PhotoSummary summary = summarize_photos(count, load, search);
  if (summary.max_img.empty()) return found;
  const double min_r = search.min_radius_px;
  const double max_r = search.max_radius_px > 0 ? search.max_radius_px
                                                : 0.5 * std::min(summary.width, summary.height);

  SphereCircle track;
  const bool have_track = track_circle(summary.spots, max_r, track);
  std::vector<Candidate> cands = hough_candidates(summary, cam, min_r, max_r, have_track, track);
  cv::Mat full_max, full_med;
  full_resolution_images(summary, count, load, full_max, full_med);
  const EdgeImage edges_max = make_edge_image(full_max, kEdgeExponent, kEdgeSigmaPx);
  const EdgeImage edges_med = make_edge_image(full_med, kEdgeExponent, kEdgeSigmaPx);
  if (have_track) add_outermost_edge_candidate(edges_max, cam, track, min_r, max_r, cands);

  std::vector<Candidate> kept;
  for (Candidate &c : cands) {
    if (!refine_and_score(c, edges_max, edges_med, cam, summary.spots, min_r, max_r, search.min_edge_score)) continue;
    const SphereCircle &cc = c.model.circle;
    if (!circle_inside(cc, summary.width, summary.height, kBorderTolerancePx)) {
      log.push_back(formatted("Sphere candidate at (%.1f, %.1f), radius %.1f px rejected: the image border cuts it. "
                        "Move the sphere fully into the frame, or set its centre and radius manually.",
                        cc.x, cc.y, cc.r));
      continue;
    }
    merge_candidate(kept, c);
  }
  rank_and_drop_nested(kept);
  for (const Candidate &c : kept) {
    if (int(found.size()) >= search.max_spheres) break;
    // The median image exists at full resolution only when the photos were not reduced.
    const cv::Mat &fine = c.on_median && summary.scale == 1 ? full_med : full_max;
    found.push_back(detected_sphere(c, fine, cam, count));
  }
  return found;
}

size_t LightCalibration::valid_count() const {
  size_t n = 0;
  for (const auto &p : photos) n += p.valid ? 1 : 0;
  return n;
}

bool closest_point_to_rays(const std::vector<std::array<double, 3>> &origins,
                           const std::vector<std::array<double, 3>> &dirs, double point[3], double *rms) {
  if (origins.size() < 2 || origins.size() != dirs.size()) return false;
  // Sum over rays of (I - d d^T) (X - o) = 0.
  cv::Matx33d a = cv::Matx33d::zeros();
  cv::Vec3d b(0, 0, 0);
  for (size_t i = 0; i < origins.size(); ++i) {
    cv::Vec3d d(dirs[i][0], dirs[i][1], dirs[i][2]);
    const double n = cv::norm(d);
    if (!(n > 0)) return false;
    d /= n;
    const cv::Matx33d p = cv::Matx33d::eye() - d * d.t();
    const cv::Vec3d o(origins[i][0], origins[i][1], origins[i][2]);
    a += p;
    b += p * o;
  }
  // Nearly parallel rays: the smallest eigenvalue of A vanishes.
  cv::Vec3d ev;
  cv::eigen(a, ev);
  if (ev[2] < 1e-6 * ev[0]) return false;
  const cv::Vec3d x = a.solve(b, cv::DECOMP_CHOLESKY);
  double sum = 0;
  for (size_t i = 0; i < origins.size(); ++i) {
    cv::Vec3d d(dirs[i][0], dirs[i][1], dirs[i][2]);
    d /= cv::norm(d);
    const cv::Vec3d r = x - cv::Vec3d(origins[i][0], origins[i][1], origins[i][2]);
    if (r.dot(d) <= 0) return false;  // the rays diverge: no point in front of them
    const cv::Vec3d perp = r - d * r.dot(d);
    sum += perp.dot(perp);
  }
  for (int k = 0; k < 3; ++k) point[k] = x[k];
  if (rms) *rms = std::sqrt(sum / double(origins.size()));
  return true;
}

namespace {

// The spheres: given by the user (settings.manual_spheres) or detected in the photos; InputError
// when a given circle is unusable or no sphere is found.
void locate_spheres(size_t count, const GrayLoader &load, const SphereCamera &cam, const LightSettings &settings,
                    LightCalibration &cal) {
  if (!settings.manual_spheres.empty()) {
    for (size_t k = 0; k < settings.manual_spheres.size(); ++k) {
      const SphereCircle &c = settings.manual_spheres[k];
      if (!(c.r > 0))
        throw InputError("Sphere " + std::to_string(k + 1) + ": the manual radius must be positive (image pixels)");
      DetectedSphere d;
      d.model = sphere_from_circle(cam, c);
      if (!(d.model.circle.r > 0))
        throw InputError("Sphere " + std::to_string(k + 1) + ": the manual circle is not in front of the camera");
      d.method = SphereMethod::Manual;
      d.description = formatted("centre (%.2f, %.2f), radius %.2f px", c.x, c.y, c.r) + "; given by the user";
      cal.spheres.push_back(d);
    }
  } else {
    cal.spheres = detect_spheres(count, load, cam, settings.search, cal.log);
    if (cal.spheres.empty()) {
      std::string msg = "No reflective sphere found in the " + std::to_string(count) +
                        " photos of this viewpoint. Set the sphere's centre and radius (image pixels) "
                        "manually, and check that the whole sphere is in the frame.";
      for (const auto &line : cal.log) msg += " " + line;
      throw InputError(msg);
    }
  }
  for (size_t k = 0; k < cal.spheres.size(); ++k)
    cal.log.push_back("Sphere " + std::to_string(k + 1) + ": " + cal.spheres[k].description + " (" +
                      sphere_method_name(cal.spheres[k].method) + ", " +
                      (cam.perspective ? "perspective camera of the shot" : "orthographic view") + ").");
}

// Every photo's highlight on every sphere.
void find_highlights(size_t count, const GrayLoader &load, const LightSettings &settings, LightCalibration &cal) {
  const size_t ns = cal.spheres.size();
  cal.photos.resize(count);
  for (size_t i = 0; i < count; ++i) {
    PhotoLight &pl = cal.photos[i];
    pl.spheres.resize(ns);
    const cv::Mat g = load(i);
    for (size_t k = 0; k < ns; ++k) {
      SphereLight &sl = pl.spheres[k];
      if (g.empty()) {
        sl.highlight.problem = "the photo could not be read";
        continue;
      }
      sl.highlight = find_highlight(g, cal.spheres[k].model.circle, settings.highlight);
    }
  }
}

// A highlight far weaker than the same sphere's in the other photos is a reflection of the
// surroundings, not of the light (sphere in shadow): not found.
void reject_shadowed_highlights(LightCalibration &cal) {
  for (size_t k = 0; k < cal.spheres.size(); ++k) {
    std::vector<double> peaks;
    for (const auto &pl : cal.photos)
      if (pl.spheres[k].highlight.found) peaks.push_back(pl.spheres[k].highlight.peak);
    if (peaks.empty()) continue;
    std::nth_element(peaks.begin(), peaks.begin() + long(peaks.size() / 2), peaks.end());
    const double median_peak = peaks[peaks.size() / 2];
    for (auto &pl : cal.photos) {
      Highlight &h = pl.spheres[k].highlight;
      if (h.found && h.peak < 0.3 * median_peak) {
        h.found = false;
        h.problem = formatted("no highlight: the brightest point (%.2f) is far below this sphere's usual highlight "
                        "(%.2f): sphere in shadow?",
                        h.peak, median_peak);
      }
    }
  }
}

// Photo i's light from its spheres' highlights: the mean direction, the spheres' disagreement and,
// where they disagree beyond noise, the triangulated position; a warning naming what failed.
void light_of_photo(size_t i, const SphereCamera &cam, const LightSettings &settings,
                    const std::vector<std::string> &names, LightCalibration &cal) {
  const double radius_world = settings.sphere_radius_world > 0 ? settings.sphere_radius_world : 1.0;
  PhotoLight &pl = cal.photos[i];
  std::vector<std::array<double, 3>> origins, dirs;
  double sum[3] = {0, 0, 0};
  std::string problems;
  for (size_t k = 0; k < cal.spheres.size(); ++k) {
    SphereLight &sl = pl.spheres[k];
    const SphereModel &m = cal.spheres[k].model;
    double point[3];
    if (sl.highlight.found && !highlight_to_light(cam, m, sl.highlight.x, sl.highlight.y, sl.dir, nullptr, point)) {
      sl.highlight.found = false;
      sl.highlight.problem = "the highlight is outside the sphere's outline";
    }
    if (!sl.highlight.found) {
      problems += (problems.empty() ? "" : "; ") + std::string("sphere ") + std::to_string(k + 1) + ": " +
                  sl.highlight.problem;
      continue;
    }
    sl.valid = true;
    for (int c = 0; c < 3; ++c) sum[c] += sl.dir[c];
    // Surface point in common units: perspective spheres sit at distance R / sin(half_angle).
    const double s = cam.perspective ? radius_world / std::sin(m.half_angle) : 1.0;
    origins.push_back({point[0] * s, point[1] * s, point[2] * s});
    dirs.push_back({sl.dir[0], sl.dir[1], sl.dir[2]});
  }
  if (!origins.empty()) {
    pl.valid = true;
    normalize3(sum);
    for (int c = 0; c < 3; ++c) pl.dir[c] = sum[c];
    for (size_t a = 0; a < dirs.size(); ++a)
      for (size_t b = a + 1; b < dirs.size(); ++b)
        pl.disagreement_deg = std::max(pl.disagreement_deg, angle_deg(dirs[a].data(), dirs[b].data()));
    // Spheres that agree within noise see a distant light: its position would be noise.
    pl.has_position = pl.disagreement_deg >= settings.min_triangulation_deg &&
                      closest_point_to_rays(origins, dirs, pl.position, &pl.position_rms);
  }
  if (!problems.empty()) {
    pl.warning = photo_name(names, i) + (pl.valid ? ": " : " gets no light: ") + problems;
    cal.log.push_back("Warning: " + pl.warning);
  }
}

// The log's summary: photos with a light, the spheres' disagreement, the positions triangulated.
void summarise_lights(size_t count, const SphereCamera &cam, const LightSettings &settings, LightCalibration &cal) {
  std::vector<double> disagreements;
  size_t positions = 0;
  for (const PhotoLight &pl : cal.photos) {
    if (pl.valid && std::count_if(pl.spheres.begin(), pl.spheres.end(), [](const SphereLight &s) { return s.valid; }) >= 2)
      disagreements.push_back(pl.disagreement_deg);
    positions += pl.has_position ? 1 : 0;
  }
  cal.log.push_back(std::to_string(cal.valid_count()) + " of " + std::to_string(count) +
                    " photos got a light direction.");
  if (!disagreements.empty()) {
    std::sort(disagreements.begin(), disagreements.end());
    cal.log.push_back(formatted("Angular disagreement between the spheres: median %.2f deg, max %.2f deg over %.0f photos.",
                                disagreements[disagreements.size() / 2], disagreements.back(), double(disagreements.size())));
  }
  if (positions > 0)
    cal.log.push_back(formatted("Near-light positions triangulated for %.0f photos (camera frame, ", double(positions)) +
                      (cam.perspective ? (settings.sphere_radius_world > 0 ? "world units" : "units of the sphere radius")
                                       : "pixels") +
                      ").");
}

} // namespace

LightCalibration calibrate_lights(size_t count, const GrayLoader &load, const SphereCamera &cam,
                                  const LightSettings &settings, const std::vector<std::string> &names) {
  LightCalibration cal;
  locate_spheres(count, load, cam, settings, cal);
  find_highlights(count, load, settings, cal);
  reject_shadowed_highlights(cal);
  for (size_t i = 0; i < count; ++i) light_of_photo(i, cam, settings, names, cal);
  summarise_lights(count, cam, settings, cal);
  return cal;
}

LightCalibration calibrate_lights(const std::vector<cv::Mat> &photos, const SphereCamera &cam,
                                  const LightSettings &settings, const std::vector<std::string> &names) {
  std::vector<cv::Mat> gray(photos.size());
  for (size_t i = 0; i < photos.size(); ++i) gray[i] = gray_image(photos[i], settings.decode_srgb);
  return calibrate_lights(
      photos.size(), [&](size_t i) { return gray[i]; }, cam, settings, names);
}

std::vector<LightEntry> light_entries(const LightCalibration &cal, const std::vector<std::string> &image_names) {
  std::vector<LightEntry> out;
  for (size_t i = 0; i < cal.photos.size() && i < image_names.size(); ++i) {
    const PhotoLight &p = cal.photos[i];
    if (!p.valid) continue;
    LightEntry e;
    e.image = image_names[i];
    for (int c = 0; c < 3; ++c) e.dir_cam[c] = float(p.dir[c]);
    out.push_back(e);
  }
  return out;
}

CircleCheck check_sphere_circle(size_t count, const GrayLoader &load, const SphereCamera &cam,
                                const SphereCircle &circle, const SphereSearch &search) {
  CircleCheck out;
  out.refined = circle;
  const PhotoSummary summary = summarize_photos(count, load, search);
  if (summary.max_img.empty() || !(circle.r > 0)) {
    out.description = "no photo or no circle to check";
    return out;
  }
  cv::Mat full_max, full_med;
  full_resolution_images(summary, count, load, full_max, full_med);
  const EdgeImage edges_max = make_edge_image(full_max, kEdgeExponent, kEdgeSigmaPx);
  const EdgeImage edges_med = make_edge_image(full_med, kEdgeExponent, kEdgeSigmaPx);
  const SphereModel given = sphere_from_circle(cam, circle);
  const double s_max = edge_score(edges_max, cam, given), s_med = edge_score(edges_med, cam, given);
  out.outline_score = std::max(s_max, s_med);
  out.outline_coverage = edge_coverage(s_max >= s_med ? edges_max : edges_med, cam, given);
  out.spots_inside = size_t(spot_support(summary.spots, circle, out.photos_with_spot));
  const size_t needed = std::max<size_t>(kMinSupportPhotos, (out.photos_with_spot * kMinSupportTenths + 9) / 10);
  out.plausible = out.outline_coverage >= kMinOutlineCoverage &&
                  (out.photos_with_spot >= kMinPhotosWithSpots ? out.spots_inside >= needed
                                                               : out.outline_score >= search.min_edge_score);
  const double shift = std::max(kRefineShiftMinPx, kRefineShiftRadii * circle.r);
  out.refined = refine_on(s_max >= s_med ? edges_max : edges_med, cam, given, shift, nullptr).circle;
  out.offset_px = std::max(std::hypot(out.refined.x - circle.x, out.refined.y - circle.y),
                           std::fabs(out.refined.r - circle.r));
  const bool on_outline = out.offset_px <= std::max(kCircleCheckMinOffsetPx, kCircleCheckOffsetRadii * circle.r);
  out.description = formatted("circle (%.1f, %.1f) r %.1f px: outline visible on %.0f %% of its length", circle.x, circle.y,
                        circle.r, 100.0 * out.outline_coverage) +
                    ", bright spot inside in " + std::to_string(out.spots_inside) + " of " +
                    std::to_string(out.photos_with_spot) + " photos with one" +
                    formatted(", strongest outline nearby at (%.1f, %.1f) r %.1f px", out.refined.x, out.refined.y,
                        out.refined.r) + formatted(" (%.1f px away)", out.offset_px);
  out.plausible = out.plausible && on_outline;
  out.description += out.plausible ? ": a sphere" : ": NOT this sphere's outline in these photos";
  return out;
}

std::vector<HighlightBlob> highlight_blobs(const cv::Mat &gray, const SphereCircle &c, const HighlightSettings &s) {
  std::vector<HighlightBlob> blobs;
  if (gray.empty() || !(c.r > 0)) return blobs;
  const double r_in = c.r * (1.0 - s.rim_margin);
  const cv::Rect box = cv::Rect(int(std::floor(c.x - r_in)), int(std::floor(c.y - r_in)), int(2 * r_in) + 2,
                                int(2 * r_in) + 2) & cv::Rect(0, 0, gray.cols, gray.rows);
  if (box.width < 3 || box.height < 3) return blobs;
  cv::Mat img, mask = cv::Mat::zeros(box.size(), CV_8U);
  cv::GaussianBlur(gray(box), img, cv::Size(0, 0), 1.0);
  cv::circle(mask, cv::Point2d(c.x - box.x - 0.5, c.y - box.y - 0.5), int(r_in), cv::Scalar(255), cv::FILLED);
  double peak = 0;
  cv::minMaxLoc(img, nullptr, &peak, nullptr, nullptr, mask);
  const double background = masked_median(img, mask);
  if (peak < s.min_peak || peak - background < s.min_contrast) return blobs;
  const cv::Mat bright = (img > background + 0.5 * (peak - background)) & mask;
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(bright, labels, stats, centroids, 8, CV_32S);
  std::vector<HighlightBlob> all(size_t(std::max(0, n - 1)));
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x) {
      const int l = labels.at<int>(y, x);
      if (l > 0) all[size_t(l - 1)].peak = std::max(all[size_t(l - 1)].peak, double(img.at<float>(y, x)));
    }
  int largest = 0;
  for (int i = 1; i < n; ++i) {
    HighlightBlob &b = all[size_t(i - 1)];
    b.area = stats.at<int>(i, cv::CC_STAT_AREA);
    b.x = centroids.at<double>(i, 0) + box.x + 0.5;
    b.y = centroids.at<double>(i, 1) + box.y + 0.5;
    largest = std::max(largest, b.area);
  }
  const double min_area = std::max({1.0, 0.25 * s.min_area_px, 0.05 * largest});
  for (const HighlightBlob &b : all)
    if (b.peak >= 0.8 * peak && b.area >= min_area) blobs.push_back(b);
  return blobs;
}

std::vector<int> moving_highlight_counts(const std::vector<std::vector<HighlightBlob>> &blobs, double radius) {
  const double near = 0.1 * radius;
  const size_t needed = std::max<size_t>(3, (blobs.size() + 1) / 2);
  std::vector<int> counts(blobs.size(), 0);
  for (size_t i = 0; i < blobs.size(); ++i)
    for (const HighlightBlob &b : blobs[i]) {
      size_t photos_with_it = 0;
      for (const std::vector<HighlightBlob> &other : blobs)
        for (const HighlightBlob &o : other)
          if (std::hypot(o.x - b.x, o.y - b.y) <= near) {
            ++photos_with_it;
            break;
          }
      counts[i] += photos_with_it < needed;  // counts the photo itself: a static blob is in most
    }
  return counts;
}

} // namespace vbrdf
