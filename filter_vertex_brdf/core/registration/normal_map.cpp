#include "registration/normal_map.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

namespace vbrdf {

namespace {

struct PixelNormal {
  Eigen::Vector3d b = Eigen::Vector3d::Zero();  // albedo times normal
  bool determined = false;
};

// Whether the symmetric 3 x 3 matrix (a00 a01 a02; . a11 a12; . . a22) has its smallest eigenvalue
// above `floor`: A - floor I positive definite, by its leading principal minors (Sylvester).
bool smallest_eigenvalue_above(const Eigen::Matrix3d &a, double floor) {
  const double m00 = a(0, 0) - floor, m11 = a(1, 1) - floor, m22 = a(2, 2) - floor;
  const double m01 = a(0, 1), m02 = a(0, 2), m12 = a(1, 2);
  const double minor2 = m00 * m11 - m01 * m01;
  const double det = m00 * (m11 * m22 - m12 * m12) - m01 * (m01 * m22 - m12 * m02) + m02 * (m01 * m12 - m11 * m02);
  return m00 > 0 && minor2 > 0 && det > 0;
}

// Least squares b over the samples with use[k]; not determined when fewer than min_samples or the
// lights' spread is below min_light_spread (an ill-posed 3 x 3 system is never solved). LLt[k]:
// the light's outer product L_k L_k^T.
PixelNormal solve_pixel(const std::vector<float> &I, const std::vector<Eigen::Vector3d> &L,
                        const std::vector<Eigen::Matrix3d> &LLt, const std::vector<char> &use, const NormalMapSettings &s) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d y = Eigen::Vector3d::Zero();
  int n = 0;
  for (size_t k = 0; k < I.size(); ++k) {
    if (!use[k]) continue;
    A += LLt[k];
    y += double(I[k]) * L[k];
    ++n;
  }
  PixelNormal out;
  if (n < s.min_samples) return out;
  if (!smallest_eigenvalue_above(A / n, s.min_light_spread)) return out;
  out.b = A.llt().solve(y);
  out.determined = out.b.allFinite();
  return out;
}

PixelNormal robust_pixel(std::vector<float> &I, const std::vector<Eigen::Vector3d> &L,
                         const std::vector<Eigen::Matrix3d> &LLt, std::vector<char> &use, std::vector<float> &scratch,
                         const NormalMapSettings &s) {
  const size_t K = I.size();
  float brightest = 0;
  scratch.clear();
  for (size_t k = 0; k < K; ++k)
    if (std::isfinite(I[k])) {
      brightest = std::max(brightest, I[k]);
      scratch.push_back(I[k]);
    }
  if (scratch.size() < size_t(s.min_samples) || !(brightest > 0)) return PixelNormal();
  const size_t drop = size_t(std::floor(s.highlight_fraction * float(scratch.size())));
  float highlight_above = brightest;
  if (drop > 0) {
    std::nth_element(scratch.begin(), scratch.end() - 1 - std::ptrdiff_t(drop), scratch.end());
    highlight_above = scratch[scratch.size() - 1 - drop];
  }
  for (size_t k = 0; k < K; ++k)
    use[k] = std::isfinite(I[k]) && I[k] >= s.shadow_floor * brightest && (drop == 0 || I[k] < highlight_above);
  PixelNormal p = solve_pixel(I, L, LLt, use, s);
  for (int it = 0; it < s.iterations && p.determined; ++it) {
    const double norm_b = p.b.norm();
    scratch.clear();
    for (size_t k = 0; k < K; ++k)
      if (use[k]) scratch.push_back(std::fabs(I[k] - float(L[k].dot(p.b))));
    std::nth_element(scratch.begin(), scratch.begin() + std::ptrdiff_t(scratch.size() / 2), scratch.end());
    // 3 robust sigmas (1.4826 MAD), never below 1 % of |b| (noise-free data would drop everything).
    const double limit = std::max(3.0 * 1.4826 * scratch[scratch.size() / 2], 0.01 * norm_b);
    bool changed = false;
    for (size_t k = 0; k < K; ++k) {
      const double predicted = L[k].dot(p.b);
      const char keep = std::isfinite(I[k]) && I[k] > 0 && predicted > 0.05 * norm_b && std::fabs(I[k] - predicted) <= limit;
      changed |= keep != use[k];
      use[k] = keep;
    }
    if (!changed) break;  // the same samples give the same solution: converged
    const PixelNormal next = solve_pixel(I, L, LLt, use, s);
    if (!next.determined) break;
    p = next;
  }
  return p;
}

} // namespace

NormalMap photometric_normal_map(const std::vector<cv::Mat> &luminance, const std::vector<std::array<float, 3>> &lights,
                                 const cv::Rect &roi, const NormalMapSettings &settings) {
  if (luminance.size() != lights.size()) throw std::invalid_argument("photometric_normal_map: one light per photo");
  for (const cv::Mat &m : luminance)
    if (m.type() != CV_32F || m.rows != roi.height || m.cols != roi.width)
      throw std::invalid_argument("photometric_normal_map: luminance images must be CV_32F of the roi's size");
  NormalMap map;
  map.roi = roi;
  map.normals = cv::Mat(roi.size(), CV_32FC3, cv::Scalar::all(0));
  map.weight = cv::Mat(roi.size(), CV_32F, cv::Scalar(0));
  cv::Mat albedo(roi.size(), CV_32F, cv::Scalar(0));
  std::vector<Eigen::Vector3d> L(lights.size());
  std::vector<Eigen::Matrix3d> LLt(lights.size());
  for (size_t k = 0; k < lights.size(); ++k) {
    L[k] = Eigen::Vector3d(lights[k][0], lights[k][1], lights[k][2]).normalized();
    LLt[k] = L[k] * L[k].transpose();
  }

#pragma omp parallel
  {
    std::vector<float> I(lights.size()), scratch;
    std::vector<char> use(lights.size());
#pragma omp for schedule(dynamic, 8)
    for (int y = 0; y < roi.height; ++y) {
      cv::Vec3f *n_row = map.normals.ptr<cv::Vec3f>(y);
      float *w_row = map.weight.ptr<float>(y), *a_row = albedo.ptr<float>(y);
      for (int x = 0; x < roi.width; ++x) {
        for (size_t k = 0; k < luminance.size(); ++k) I[k] = luminance[k].ptr<float>(y)[x];
        const PixelNormal p = robust_pixel(I, L, LLt, use, scratch, settings);
        if (!p.determined) continue;
        const double norm_b = p.b.norm();
        if (!(norm_b > 0)) continue;
        const Eigen::Vector3d n = p.b / norm_b;
        n_row[x] = cv::Vec3f(float(n.x()), float(n.y()), float(n.z()));
        w_row[x] = 1;
        a_row[x] = float(norm_b);
      }
    }
  }
  // Background: pixels whose albedo is a small fraction of the object's (median of the determined
  // ones) read as "no surface" (normal 0), as do pixels where nothing was lit at all.
  std::vector<float> albedos;
  for (int y = 0; y < roi.height; ++y)
    for (int x = 0; x < roi.width; ++x)
      if (map.weight.at<float>(y, x) > 0) albedos.push_back(albedo.at<float>(y, x));
  float median = 0;
  if (!albedos.empty()) {
    std::nth_element(albedos.begin(), albedos.begin() + std::ptrdiff_t(albedos.size() / 2), albedos.end());
    median = albedos[albedos.size() / 2];
  }
  const float floor = settings.background_level * median;
  for (int y = 0; y < roi.height; ++y)
    for (int x = 0; x < roi.width; ++x) {
      bool dark = true;  // every finite sample at most the background level (or none finite)
      for (const cv::Mat &m : luminance) {
        const float v = m.ptr<float>(y)[x];
        if (!std::isfinite(v) || v > floor) { dark = false; break; }
      }
      float &w = map.weight.at<float>(y, x);
      if ((w > 0 && albedo.at<float>(y, x) < floor) || (w == 0 && dark && median > 0)) {
        map.normals.at<cv::Vec3f>(y, x) = cv::Vec3f(0, 0, 0);
        w = 1;
        ++map.background;
      }
      if (w > 0) ++map.determined;
    }
  return map;
}

} // namespace vbrdf
