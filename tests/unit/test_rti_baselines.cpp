// Per-pixel RTI baselines: PTM (biquadratic) and Relight-style RBF.
#include <cmath>
#include <gtest/gtest.h>
#include <vector>

#include "tools/rti_baselines.h"

using namespace vbrdf;

namespace {
// Unit directions on the upper hemisphere: rings of elevation, as in a light dome.
std::vector<float> dome(int rings, int per_ring) {
  std::vector<float> d;
  for (int r = 0; r < rings; ++r) {
    const float elev = 0.35f + 1.0f * float(r) / float(rings);
    for (int k = 0; k < per_ring; ++k) {
      const float az = 6.2831853f * (float(k) + 0.5f * float(r)) / float(per_ring);
      d.push_back(std::cos(elev) * std::cos(az));
      d.push_back(std::cos(elev) * std::sin(az));
      d.push_back(std::sin(elev));
    }
  }
  return d;
}

float biquadratic(const float a[6], float u, float v) {
  return a[0] * u * u + a[1] * v * v + a[2] * u * v + a[3] * u + a[4] * v + a[5];
}

bool all_finite(const float *v, size_t n) {
  for (size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}
} // namespace

TEST(RtiBaselines, PtmReproducesBiquadraticData) {
  const std::vector<float> dirs = dome(3, 8);
  const size_t n = dirs.size() / 3;
  const float truth[3][6] = {{0.3f, -0.2f, 0.1f, 0.25f, -0.05f, 0.4f},
                             {-0.1f, 0.05f, 0.2f, 0.0f, 0.3f, 0.2f},
                             {0.0f, 0.0f, 0.0f, 0.1f, 0.1f, 0.1f}};
  std::vector<float> uv, rgb;
  for (size_t i = 0; i < n; ++i) {
    uv.push_back(dirs[3 * i]);
    uv.push_back(dirs[3 * i + 1]);
    for (int c = 0; c < 3; ++c) rgb.push_back(biquadratic(truth[c], dirs[3 * i], dirs[3 * i + 1]));
  }
  float coeffs[18];
  fit_ptm(uv.data(), rgb.data(), n, coeffs);
  for (int c = 0; c < 3; ++c)
    for (int j = 0; j < 6; ++j) EXPECT_NEAR(coeffs[6 * c + j], truth[c][j], 1e-4f) << "channel " << c << " a" << j;
  // ... and predicts it at a light that was not in the fit.
  float out[3];
  evaluate_ptm(coeffs, 0.12f, -0.33f, out);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[c], biquadratic(truth[c], 0.12f, -0.33f), 1e-4f);
}

TEST(RtiBaselines, RbfReproducesTrainingValuesAndIsSmoothBetween) {
  const std::vector<float> dirs = dome(3, 8);
  const size_t n = dirs.size() / 3;
  // A smooth Lambertian-like signal of the light direction.
  std::vector<float> rgb;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) rgb.push_back((0.2f + 0.2f * float(c)) * (0.3f + 0.7f * dirs[3 * i + 2]));
  const float sigma = rbf_sigma(dirs.data(), n);
  ASSERT_GT(sigma, 0.1f);
  ASSERT_LT(sigma, 1.0f);
  // Largest miss at the training lights of an RBF fitted with `ridge`.
  const auto max_training_error = [&](float ridge, std::vector<float> &weights) {
    weights.assign(3 * n, 0.0f);
    fit_rbf(dirs.data(), rgb.data(), n, sigma, ridge, weights.data());
    double worst = 0;
    for (size_t i = 0; i < n; ++i) {
      float o[3];
      evaluate_rbf(dirs.data(), weights.data(), n, sigma, &dirs[3 * i], o);
      for (int c = 0; c < 3; ++c) worst = std::max(worst, double(std::fabs(o[c] - rgb[3 * i + c])));
    }
    return worst;
  };
  std::vector<float> w;
  EXPECT_LT(max_training_error(1e-3f, w), 0.02);  // the ridge 1e-3 lets the fit miss the data by a little, not more
  // Between two neighbouring training lights the prediction stays between nearby values (no
  // ringing): take the midpoint of lights 0 and 1 of the lowest ring.
  float mid[3];
  for (int k = 0; k < 3; ++k) mid[k] = 0.5f * (dirs[k] + dirs[3 + k]);
  float out[3];
  evaluate_rbf(dirs.data(), w.data(), n, sigma, mid, out);
  const float expected = 0.2f * (0.3f + 0.7f * mid[2] / std::sqrt(mid[0] * mid[0] + mid[1] * mid[1] + mid[2] * mid[2]));
  EXPECT_NEAR(out[0], expected, 0.25f * expected);
  // With a smaller ridge the training values are matched more closely.
  std::vector<float> w_small;
  EXPECT_LT(max_training_error(1e-7f, w_small), 1e-3);
}

TEST(RtiBaselines, SigmaIsMeanNearestNeighbourAngle) {
  // Three directions in a plane: 0, 0.2 and 0.5 rad from the first -> nearest angles 0.2, 0.2, 0.3.
  const float d[9] = {1, 0, 0, std::cos(0.2f), std::sin(0.2f), 0, std::cos(0.5f), std::sin(0.5f), 0};
  EXPECT_NEAR(rbf_sigma(d, 3), (0.2f + 0.2f + 0.3f) / 3.0f, 1e-5f);
  EXPECT_NEAR(light_angle(d, d + 6), 0.5f, 1e-5f);
}

TEST(RtiBaselines, DegenerateInputsGiveFiniteResults) {
  // One sample.
  const float l1[3] = {0, 0, 1}, uv1[2] = {0, 0}, v1[3] = {0.5f, 0.4f, 0.3f};
  float coeffs[18], out[3];
  fit_ptm(uv1, v1, 1, coeffs);
  ASSERT_TRUE(all_finite(coeffs, 18));
  evaluate_ptm(coeffs, 0, 0, out);
  EXPECT_NEAR(out[0], 0.5f, 0.01f);  // at its own light it reproduces the sample
  evaluate_ptm(coeffs, 0.5f, -0.5f, out);
  EXPECT_TRUE(all_finite(out, 3));
  float w1[3];
  fit_rbf(l1, v1, 1, rbf_sigma(l1, 1), 1e-3f, w1);
  ASSERT_TRUE(all_finite(w1, 3));
  evaluate_rbf(l1, w1, 1, rbf_sigma(l1, 1), l1, out);
  EXPECT_NEAR(out[1], 0.4f, 0.01f);
  // Identical lights, different values: sigma stays positive, solutions finite, the mean is predicted.
  const float l3[9] = {0, 0.6f, 0.8f, 0, 0.6f, 0.8f, 0, 0.6f, 0.8f};
  const float uv3[6] = {0, 0.6f, 0, 0.6f, 0, 0.6f};
  const float v3[9] = {0.2f, 0.2f, 0.2f, 0.4f, 0.4f, 0.4f, 0.3f, 0.3f, 0.3f};
  const float s3 = rbf_sigma(l3, 3);
  EXPECT_GT(s3, 0.0f);
  float w3[9];
  fit_rbf(l3, v3, 3, s3, 1e-3f, w3);
  ASSERT_TRUE(all_finite(w3, 9));
  evaluate_rbf(l3, w3, 3, s3, l3, out);
  EXPECT_NEAR(out[0], 0.3f, 0.01f);
  fit_ptm(uv3, v3, 3, coeffs);
  ASSERT_TRUE(all_finite(coeffs, 18));
  evaluate_ptm(coeffs, 0, 0.6f, out);
  EXPECT_NEAR(out[0], 0.3f, 0.01f);
  // Zero values: zero predictions everywhere.
  const float zeros[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  fit_ptm(uv3, zeros, 3, coeffs);
  evaluate_ptm(coeffs, 0.3f, 0.1f, out);
  EXPECT_EQ(out[0], 0.0f);
  fit_rbf(l3, zeros, 3, s3, 1e-3f, w3);
  evaluate_rbf(l3, w3, 3, s3, l1, out);
  EXPECT_EQ(out[2], 0.0f);
  // No samples at all: black; non-finite samples are ignored.
  fit_ptm(uv1, v1, 0, coeffs);
  evaluate_ptm(coeffs, 0.1f, 0.1f, out);
  EXPECT_EQ(out[0], 0.0f);
  evaluate_rbf(l1, w1, 0, 0.5f, l1, out);
  EXPECT_EQ(out[0], 0.0f);
  const float bad_uv[4] = {NAN, 0, 0, 0};
  const float bad_v[6] = {1, 1, 1, 0.5f, 0.5f, 0.5f};
  fit_ptm(bad_uv, bad_v, 2, coeffs);
  ASSERT_TRUE(all_finite(coeffs, 18));
  evaluate_ptm(coeffs, 0, 0, out);
  EXPECT_NEAR(out[0], 0.5f, 0.01f);
}
