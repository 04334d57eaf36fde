#include "tools/rti_baselines.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

namespace vbrdf {

namespace {
constexpr float kSigmaFloor = 1e-3f;
constexpr float kSigmaSingle = 0.78539816f;  // pi/4

bool finite_n(const float *v, int n) {
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

void ptm_row(float lu, float lv, double row[kPtmCoefficients]) {
  row[0] = double(lu) * lu;
  row[1] = double(lv) * lv;
  row[2] = double(lu) * lv;
  row[3] = lu;
  row[4] = lv;
  row[5] = 1.0;
}

double kernel(float angle, float sigma) {
  const double t = double(angle) / double(sigma);
  return std::exp(-t * t);
}
} // namespace

void fit_ptm(const float *light_uv, const float *rgb, size_t count, float out_coefficients[3 * kPtmCoefficients]) {
  std::fill(out_coefficients, out_coefficients + 3 * kPtmCoefficients, 0.0f);
  std::vector<size_t> used;
  for (size_t i = 0; i < count; ++i)
    if (finite_n(light_uv + 2 * i, 2) && finite_n(rgb + 3 * i, 3)) used.push_back(i);
  if (used.empty()) return;
  Eigen::MatrixXd a(long(used.size()), kPtmCoefficients);
  Eigen::MatrixXd y(long(used.size()), 3);
  for (size_t k = 0; k < used.size(); ++k) {
    double row[kPtmCoefficients];
    ptm_row(light_uv[2 * used[k]], light_uv[2 * used[k] + 1], row);
    for (int j = 0; j < kPtmCoefficients; ++j) a(long(k), j) = row[j];
    for (int c = 0; c < 3; ++c) y(long(k), c) = rgb[3 * used[k] + c];
  }
  Eigen::MatrixXd x;
  bool solved = false;
  if (used.size() >= size_t(kPtmCoefficients)) {
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
    qr.setThreshold(1e-9);
    if (qr.rank() == kPtmCoefficients) {
      x = qr.solve(y);
      solved = x.allFinite();
    }
  }
  if (!solved) {
    const Eigen::MatrixXd ata = a.transpose() * a;
    const double lambda = 1e-3 * (ata.trace() / kPtmCoefficients + 1e-12);
    const Eigen::MatrixXd m = ata + lambda * Eigen::MatrixXd::Identity(kPtmCoefficients, kPtmCoefficients);
    x = m.ldlt().solve(a.transpose() * y);
    solved = x.allFinite();
  }
  if (!solved) return;
  for (int c = 0; c < 3; ++c)
    for (int j = 0; j < kPtmCoefficients; ++j) out_coefficients[kPtmCoefficients * c + j] = float(x(j, c));
  if (!finite_n(out_coefficients, 3 * kPtmCoefficients))
    std::fill(out_coefficients, out_coefficients + 3 * kPtmCoefficients, 0.0f);
}

void evaluate_ptm(const float coefficients[3 * kPtmCoefficients], float lu, float lv, float out_rgb[3]) {
  double row[kPtmCoefficients];
  ptm_row(lu, lv, row);
  for (int c = 0; c < 3; ++c) {
    double v = 0;
    for (int j = 0; j < kPtmCoefficients; ++j) v += double(coefficients[kPtmCoefficients * c + j]) * row[j];
    out_rgb[c] = std::isfinite(v) ? float(v) : 0.0f;
  }
}

float light_angle(const float a[3], const float b[3]) {
  const double na = std::sqrt(double(a[0]) * a[0] + double(a[1]) * a[1] + double(a[2]) * a[2]);
  const double nb = std::sqrt(double(b[0]) * b[0] + double(b[1]) * b[1] + double(b[2]) * b[2]);
  if (!(na > 0) || !(nb > 0) || !std::isfinite(na * nb)) return 0.0f;
  // atan2 of |a x b| and a.b: accurate for small and near-opposite angles alike.
  const double cx = double(a[1]) * b[2] - double(a[2]) * b[1];
  const double cy = double(a[2]) * b[0] - double(a[0]) * b[2];
  const double cz = double(a[0]) * b[1] - double(a[1]) * b[0];
  const double dot = double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2];
  return float(std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), dot));
}

float rbf_sigma(const float *light_dirs, size_t count) {
  if (count < 2) return kSigmaSingle;
  double sum = 0;
  for (size_t i = 0; i < count; ++i) {
    float nearest = 4.0f;  // > pi
    for (size_t j = 0; j < count; ++j)
      if (j != i) nearest = std::min(nearest, light_angle(light_dirs + 3 * i, light_dirs + 3 * j));
    sum += nearest;
  }
  const float sigma = float(sum / double(count));
  return std::isfinite(sigma) ? std::max(sigma, kSigmaFloor) : kSigmaSingle;
}

void fit_rbf(const float *light_dirs, const float *rgb, size_t count, float sigma, float ridge, float *out_weights) {
  std::fill(out_weights, out_weights + 3 * count, 0.0f);
  if (count == 0) return;
  if (!(sigma > 0) || !std::isfinite(sigma)) sigma = kSigmaFloor;
  if (!(ridge > 0) || !std::isfinite(ridge)) ridge = 1e-6f;
  const long n = long(count);
  Eigen::MatrixXd k(n, n);
  Eigen::MatrixXd y(n, 3);
  for (long i = 0; i < n; ++i) {
    for (long j = i; j < n; ++j) k(i, j) = k(j, i) = kernel(light_angle(light_dirs + 3 * i, light_dirs + 3 * j), sigma);
    k(i, i) += double(ridge);
    for (int c = 0; c < 3; ++c) y(i, c) = std::isfinite(rgb[3 * i + c]) ? double(rgb[3 * i + c]) : 0.0;
  }
  Eigen::LDLT<Eigen::MatrixXd> ldlt(k);
  Eigen::MatrixXd w;
  if (ldlt.info() == Eigen::Success) w = ldlt.solve(y);
  if (w.size() == 0 || !w.allFinite() || !(k * w).isApprox(y, 1e-6)) w = k.completeOrthogonalDecomposition().solve(y);
  if (!w.allFinite()) return;
  for (long i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) out_weights[3 * i + c] = float(w(i, c));
  if (!finite_n(out_weights, int(3 * count))) std::fill(out_weights, out_weights + 3 * count, 0.0f);
}

void evaluate_rbf(const float *light_dirs, const float *weights, size_t count, float sigma, const float dir[3],
                  float out_rgb[3]) {
  if (!(sigma > 0) || !std::isfinite(sigma)) sigma = kSigmaFloor;
  double acc[3] = {0, 0, 0};
  for (size_t i = 0; i < count; ++i) {
    const double kv = kernel(light_angle(dir, light_dirs + 3 * i), sigma);
    for (int c = 0; c < 3; ++c) acc[c] += kv * double(weights[3 * i + c]);
  }
  for (int c = 0; c < 3; ++c) out_rgb[c] = std::isfinite(acc[c]) ? float(acc[c]) : 0.0f;
}

} // namespace vbrdf
