#include "registration/image_alignment.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

namespace vbrdf {

void warp_rotation(const ImageWarp &w, double out[3][3]) {
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(w.roll, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(w.pitch, Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(w.yaw, Eigen::Vector3d::UnitY())).toRotationMatrix();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[i][j] = R(i, j);
}

namespace {

// A warp with its rotation and scale computed once, applied to many points.
struct PreparedWarp {
  double R[3][3];
  double c[2];
  double f, s;
  PreparedWarp(const ImageWarp &w, const double centre[2], double focal) : c{centre[0], centre[1]}, f(focal) {
    warp_rotation(w, R);
    s = std::exp(w.log_scale) * f;
  }
  void apply(const double p[2], double out[2]) const {
    const double d[3] = {(p[0] - c[0]) / f, (p[1] - c[1]) / f, 1.0};
    double e[3];
    for (int i = 0; i < 3; ++i) e[i] = R[i][0] * d[0] + R[i][1] * d[1] + R[i][2] * d[2];
    // A ray turned behind the camera (never for the fractions of a degree refined) keeps its point.
    if (!(e[2] > 1e-6)) {
      out[0] = p[0], out[1] = p[1];
      return;
    }
    out[0] = c[0] + s * e[0] / e[2];
    out[1] = c[1] + s * e[1] / e[2];
  }
};

} // namespace

void warp_point(const ImageWarp &w, const double c[2], double f, const double p[2], double out[2]) {
  PreparedWarp(w, c, f).apply(p, out);
}

namespace {

constexpr size_t kMinPoints = 20;

// The map blurred by sigma, normals weighted by the map's weight (undetermined pixels do not
// spread), and the blurred weight. Sampled bilinearly by sample_level.
struct Level {
  cv::Mat n;  // CV_32FC3, normalised by the blurred weight
  cv::Mat w;  // CV_32F
  cv::Rect roi;
};

Level blurred_level(const NormalMap &map, double sigma) {
  Level l;
  l.roi = map.roi;
  cv::Mat weighted;
  std::vector<cv::Mat> ch;
  cv::split(map.normals, ch);
  for (cv::Mat &c : ch) c = c.mul(map.weight);
  cv::merge(ch, weighted);
  cv::GaussianBlur(weighted, l.n, cv::Size(0, 0), sigma, sigma, cv::BORDER_REPLICATE);
  cv::GaussianBlur(map.weight, l.w, cv::Size(0, 0), sigma, sigma, cv::BORDER_REPLICATE);
  for (int y = 0; y < l.n.rows; ++y) {
    cv::Vec3f *n = l.n.ptr<cv::Vec3f>(y);
    const float *w = l.w.ptr<float>(y);
    for (int x = 0; x < l.n.cols; ++x) n[x] = w[x] > 1e-3f ? n[x] / w[x] : cv::Vec3f(0, 0, 0);
  }
  return l;
}

// Bilinear sample at image point (x, y) (pixel centres at +0.5); false outside the map or where
// the blurred weight is below one half (the point's pixel is mostly undetermined).
bool sample_level(const Level &l, double x, double y, Eigen::Vector3d &n) {
  const double fx = x - 0.5 - l.roi.x, fy = y - 0.5 - l.roi.y;
  const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= l.n.cols || y0 + 1 >= l.n.rows) return false;
  const double ax = fx - x0, ay = fy - y0;
  const double wt[4] = {(1 - ax) * (1 - ay), ax * (1 - ay), (1 - ax) * ay, ax * ay};
  double weight = 0;
  n.setZero();
  for (int k = 0; k < 4; ++k) {
    const int xx = x0 + (k & 1), yy = y0 + (k >> 1);
    const cv::Vec3f v = l.n.at<cv::Vec3f>(yy, xx);
    n += wt[k] * Eigen::Vector3d(v[0], v[1], v[2]);
    weight += wt[k] * l.w.at<float>(yy, xx);
  }
  return weight >= 0.5;
}

struct Problem {
  const std::vector<AlignmentPoint> &points;
  const double *c;
  double f;
  const AlignmentSettings &settings;
  double radius;  // RMS distance of the points from c (pixels): a roll or scale's effect per unit
};

double &parameter(ImageWarp &w, int i) { return i == 0 ? w.pitch : i == 1 ? w.yaw : i == 2 ? w.roll : w.log_scale; }

// Pixels the image moves per unit of parameter i (near the identity): for the convergence test and
// the finite differences.
double pixels_per_unit(const Problem &pb, int i) { return i < 2 ? pb.f : pb.radius; }

double huber_weight(double r, double k) { return r <= k ? 1.0 : k / r; }
double huber_cost(double r, double k) { return r <= k ? 0.5 * r * r : k * (r - 0.5 * k); }

// Sums over points 0..n-1 in kSumBlocks fixed blocks, each block's partial added in block order:
// the same bits whatever the thread count or schedule (a reduction or a critical section adds
// partials in the order threads finish). add_block(part, begin, end) accumulates one block.
constexpr long kSumBlocks = 64;

template <class Part, class AddBlock>
Part sum_in_blocks(long n, const Part &zero, AddBlock add_block) {
  std::vector<Part> parts(size_t(kSumBlocks), zero);
#pragma omp parallel for schedule(dynamic, 1)
  for (long b = 0; b < kSumBlocks; ++b) add_block(parts[size_t(b)], n * b / kSumBlocks, n * (b + 1) / kSumBlocks);
  Part total = zero;
  for (const Part &part : parts) total += part;
  return total;
}

struct CostSum {
  double sum = 0;
  size_t count = 0;
  CostSum &operator+=(const CostSum &o) {
    sum += o.sum;
    count += o.count;
    return *this;
  }
};

// Mean robust cost over the points that land on determined pixels, and their count.
double cost_of(const Problem &pb, const Level &l, const ImageWarp &s, size_t &used) {
  const PreparedWarp warp(s, pb.c, pb.f);
  const CostSum total = sum_in_blocks(long(pb.points.size()), CostSum(), [&](CostSum &part, long begin, long end) {
    for (long i = begin; i < end; ++i) {
      const AlignmentPoint &p = pb.points[size_t(i)];
      const double p0[2] = {p.x, p.y};
      double q[2];
      warp.apply(p0, q);
      Eigen::Vector3d m;
      if (!sample_level(l, q[0], q[1], m)) continue;
      part.sum += huber_cost((m - Eigen::Vector3d(p.n[0], p.n[1], p.n[2])).norm(), pb.settings.huber);
      ++part.count;
    }
  });
  used = total.count;
  return used ? total.sum / double(used) : 0.0;
}

void add_step(ImageWarp &w, const Eigen::VectorXd &d, const int *param) {
  for (int i = 0; i < d.size(); ++i) parameter(w, param[i]) += d(i);
}

struct NormalEquations {
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  double residual_sq = 0;  // weighted squared residuals
  size_t used = 0;
  explicit NormalEquations(int n) : H(Eigen::MatrixXd::Zero(n, n)), g(Eigen::VectorXd::Zero(n)) {}
  NormalEquations &operator+=(const NormalEquations &o) {
    H += o.H;
    g += o.g;
    residual_sq += o.residual_sq;
    used += o.used;
    return *this;
  }
};

// J^T W J and J^T W r of the free parameters `param` (count n) at warp w; the map's derivative by
// central differences of the bilinear sample half a pixel apart.
NormalEquations normal_equations(const Problem &pb, const Level &l, const ImageWarp &w, const int *param, int n) {
  const PreparedWarp warp(w, pb.c, pb.f);
  // Each parameter's warps half a finite-difference step either side, a hundredth of a pixel's
  // effect apart, prepared once for every point.
  std::vector<PreparedWarp> plus, minus;
  std::vector<double> step;
  for (int i = 0; i < n; ++i) {
    const double h = 0.01 / pixels_per_unit(pb, param[i]);
    ImageWarp up = w, down = w;
    parameter(up, param[i]) += h;
    parameter(down, param[i]) -= h;
    plus.emplace_back(up, pb.c, pb.f);
    minus.emplace_back(down, pb.c, pb.f);
    step.push_back(h);
  }
  auto add_block = [&](NormalEquations &part, long begin, long end) {
    Eigen::MatrixXd J(3, n);
    for (long k = begin; k < end; ++k) {
      const AlignmentPoint &p = pb.points[size_t(k)];
      const double p0[2] = {p.x, p.y};
      double q[2];
      warp.apply(p0, q);
      Eigen::Vector3d n0, nx0, nx1, ny0, ny1;
      if (!sample_level(l, q[0], q[1], n0) || !sample_level(l, q[0] - 0.5, q[1], nx0) ||
          !sample_level(l, q[0] + 0.5, q[1], nx1) || !sample_level(l, q[0], q[1] - 0.5, ny0) ||
          !sample_level(l, q[0], q[1] + 0.5, ny1))
        continue;
      const Eigen::Vector3d r = n0 - Eigen::Vector3d(p.n[0], p.n[1], p.n[2]);
      const double weight = huber_weight(r.norm(), pb.settings.huber);
      Eigen::Matrix<double, 3, 2> dn;
      dn.col(0) = nx1 - nx0;
      dn.col(1) = ny1 - ny0;
      for (int i = 0; i < n; ++i) {
        double qp[2], qm[2];
        plus[size_t(i)].apply(p0, qp);
        minus[size_t(i)].apply(p0, qm);
        const double h = step[size_t(i)];
        J.col(i) = dn * Eigen::Vector2d((qp[0] - qm[0]) / (2 * h), (qp[1] - qm[1]) / (2 * h));
      }
      part.H += weight * J.transpose() * J;
      part.g += weight * J.transpose() * r;
      part.residual_sq += weight * r.squaredNorm();
      ++part.used;
    }
  };
  return sum_in_blocks(long(pb.points.size()), NormalEquations(n), add_block);
}

// Levenberg-Marquardt on the parameters `param`; returns the iterations taken.
int solve_level(const Problem &pb, const Level &l, const int *param, int n, ImageWarp &w) {
  double lambda = 1e-3;
  int it = 0;
  size_t used = 0;
  double cost = cost_of(pb, l, w, used);
  for (; it < pb.settings.iterations; ++it) {
    const NormalEquations ne = normal_equations(pb, l, w, param, n);
    if (ne.used < kMinPoints) break;
    bool accepted = false;
    for (int tries = 0; tries < 8 && !accepted; ++tries) {
      Eigen::MatrixXd H = ne.H;
      H.diagonal() += lambda * ne.H.diagonal().cwiseMax(1e-9);
      const Eigen::VectorXd d = -H.ldlt().solve(ne.g);
      if (!d.allFinite()) { lambda *= 10; continue; }
      ImageWarp trial = w;
      add_step(trial, d, param);
      size_t trial_used = 0;
      const double trial_cost = cost_of(pb, l, trial, trial_used);
      if (trial_used >= kMinPoints && trial_cost <= cost) {
        double moved = 0;  // the largest parameter step, in pixels of image motion
        for (int i = 0; i < n; ++i) moved = std::max(moved, std::fabs(d(i)) * pixels_per_unit(pb, param[i]));
        w = trial;
        cost = trial_cost;
        lambda = std::max(1e-6, lambda / 3);
        accepted = true;
        if (moved < 1e-3) return it + 1;
      } else {
        lambda *= 10;
      }
    }
    if (!accepted) break;
  }
  return it;
}

// Standard deviation of each free parameter from the normal equations at w (Gauss-Newton
// covariance, residual variance from the weighted residuals).
Eigen::VectorXd parameter_sigma(const Problem &pb, const Level &l, const ImageWarp &w, const int *param, int n) {
  const NormalEquations ne = normal_equations(pb, l, w, param, n);
  Eigen::VectorXd sigma = Eigen::VectorXd::Constant(n, 1e30);
  if (ne.used <= size_t(3 * n)) return sigma;
  const double variance = ne.residual_sq / double(3 * ne.used - size_t(n));
  Eigen::FullPivLU<Eigen::MatrixXd> lu(ne.H);
  if (!lu.isInvertible()) return sigma;
  const Eigen::MatrixXd cov = lu.inverse() * variance;
  for (int i = 0; i < n; ++i) sigma(i) = std::sqrt(std::max(0.0, cov(i, i)));
  return sigma;
}

double rms_displacement(const std::vector<AlignmentPoint> &points, const double c[2], double f, const ImageWarp &w) {
  if (points.empty()) return 0;
  const PreparedWarp warp(w, c, f);
  double sum = 0;
  for (const AlignmentPoint &p : points) {
    const double p0[2] = {p.x, p.y};
    double q[2];
    warp.apply(p0, q);
    sum += (q[0] - p0[0]) * (q[0] - p0[0]) + (q[1] - p0[1]) * (q[1] - p0[1]);
  }
  return std::sqrt(sum / double(points.size()));
}

} // namespace

AlignmentResult align_to_normal_map(const std::vector<AlignmentPoint> &points, const NormalMap &map, const double c[2],
                                    double f, const AlignmentSettings &settings) {
  AlignmentResult out;
  if (points.size() < kMinPoints || map.normals.empty() || settings.levels.empty() || !(f > 0)) return out;
  double radius = 0;
  for (const AlignmentPoint &p : points) radius += (p.x - c[0]) * (p.x - c[0]) + (p.y - c[1]) * (p.y - c[1]);
  radius = std::max(1.0, std::sqrt(radius / double(points.size())));
  const Problem pb{points, c, f, settings, radius};
  // The coarse levels only bring the shift into the finest level's basin: evenly strided points do.
  std::vector<AlignmentPoint> coarse_points;
  const bool thin = settings.max_coarse_points > 0 && points.size() > settings.max_coarse_points;
  if (thin) {
    const size_t stride = (points.size() + settings.max_coarse_points - 1) / settings.max_coarse_points;
    for (size_t i = 0; i < points.size(); i += stride) coarse_points.push_back(points[i]);
  }
  const Problem coarse{coarse_points.size() >= kMinPoints ? coarse_points : points, c, f, settings, radius};
  const std::vector<int> free = {0, 1};  // pitch and yaw: the shift
  ImageWarp w;
  Level finest;
  for (size_t i = 0; i < settings.levels.size(); ++i) {
    const Level l = blurred_level(map, settings.levels[i]);
    const bool last = i + 1 == settings.levels.size();
    if (last) {
      finest = l;
      size_t used = 0;
      out.cost_before = cost_of(pb, finest, ImageWarp(), used);
    }
    out.iterations += solve_level(last ? pb : coarse, l, free.data(), int(free.size()), w);
  }
  if (settings.solve_roll_and_scale) {
    // Roll and scale, kept only where determined: solve them with the rest, test each against its
    // sigma and its effect, solve again without the ones that fail.
    std::vector<int> all = free;
    all.insert(all.begin() + 2, {2, 3});
    ImageWarp full = w;
    out.iterations += solve_level(pb, finest, all.data(), int(all.size()), full);
    const Eigen::VectorXd sigma = parameter_sigma(pb, finest, full, all.data(), int(all.size()));
    out.roll_determined = std::fabs(full.roll) > settings.significance * sigma(2) &&
                          std::fabs(full.roll) * radius >= settings.min_effect_px;
    out.scale_determined = std::fabs(full.log_scale) > settings.significance * sigma(3) &&
                           std::fabs(full.log_scale) * radius >= std::max(settings.min_effect_px, settings.min_scale_effect_px);
    if (out.roll_determined && out.scale_determined) {
      w = full;
    } else if (out.roll_determined || out.scale_determined) {
      std::vector<int> some = free;
      some.insert(some.begin() + 2, out.roll_determined ? 2 : 3);
      ImageWarp partial = w;
      out.iterations += solve_level(pb, finest, some.data(), int(some.size()), partial);
      w = partial;
    }
  }
  out.warp = w;
  out.cost_after = cost_of(pb, finest, w, out.points_used);
  out.rms_px = rms_displacement(points, c, f, w);
  double moved[2];
  warp_point(w, c, f, c, moved);
  out.shift_x = moved[0] - c[0];
  out.shift_y = moved[1] - c[1];
  return out;
}

} // namespace vbrdf
