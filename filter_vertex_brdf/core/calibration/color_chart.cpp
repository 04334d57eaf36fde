#include "calibration/color_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>

#include <omp.h>

#include <opencv2/imgproc.hpp>
#include <opencv2/mcc.hpp>

#include "base/clip_level.h"
#include "base/color_difference.h"
#include "base/errors.h"
#include "base/number_format.h"
#include "base/luminance.h"
#include "inputs/photo.h"

namespace vbrdf {

namespace {

// mcc's ColorChecker Classic template: the detector's box is 16.75 x 11.25 units (CChartModel
// MCC24); patch centres at 1.5 + 2.75 k in it (checked within 4 px on the Mitsuba scenes' charts).
// Photos longer than this are searched for a chart at a reduced size first (detect_charts).
constexpr int kDetectSide = 2048;
constexpr float kBoxW = 16.75f, kBoxH = 11.25f, kFirstCentre = 1.5f, kPitch = 2.75f;


std::string photo_name(const std::vector<std::string> &names, size_t i) {
  if (i < names.size() && !names[i].empty()) return "'" + names[i] + "'";
  return "photo " + std::to_string(i + 1);
}

double median_of(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Homography from the patch grid (column j, row i: corner patches at (0,0), (5,0), (5,3), (0,3))
// to the image.
cv::Matx33d grid_to_image(const ChartLocation &chart) {
  const cv::Point2f grid[4] = {{0, 0}, {5, 0}, {5, 3}, {0, 3}};
  const cv::Point2f img[4] = {chart.corners[0], chart.corners[1], chart.corners[2], chart.corners[3]};
  return cv::Matx33d(cv::getPerspectiveTransform(grid, img));
}

cv::Point2d map_point(const cv::Matx33d &h, double x, double y) {
  const cv::Vec3d p = h * cv::Vec3d(x, y, 1);
  return {p[0] / p[2], p[1] / p[2]};
}

bool sample_rgb(const cv::Mat &img, double x, double y, cv::Vec3f &out) {
  const double fx = x - 0.5, fy = y - 0.5;
  const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= img.cols || y0 + 1 >= img.rows) return false;
  const float ax = float(fx - x0), ay = float(fy - y0);
  const cv::Vec3f *r0 = img.ptr<cv::Vec3f>(y0), *r1 = img.ptr<cv::Vec3f>(y0 + 1);
  out = (1 - ay) * ((1 - ax) * r0[x0] + ax * r0[x0 + 1]) + ay * ((1 - ax) * r1[x0] + ax * r1[x0 + 1]);
  return true;
}

// The neutral row must darken from white to black; a chart read upside down has it reversed.
bool neutral_row_reversed(const PatchMeasurement &m) {
  int forward = 0, backward = 0;
  for (int k = kFirstNeutralPatch; k + 1 < kChartPatches; ++k)
    forward += luminance_double(m.rgb[k].data()) > luminance_double(m.rgb[k + 1].data());
  for (int k = 5; k > 0; --k) backward += luminance_double(m.rgb[k].data()) > luminance_double(m.rgb[k - 1].data());
  return backward == 5 && forward < 4;
}

double quad_area(const ChartLocation &c) {
  std::vector<cv::Point2f> q(c.corners.begin(), c.corners.end());
  return std::fabs(cv::contourArea(q));
}

// ---- model fitting ----

void fit_matrix(const std::vector<int> &idx, const PatchColors &measured, const PatchColors &reference,
                ColorCorrection &out) {
  cv::Mat src(int(idx.size()), 1, CV_64FC3), dst(int(idx.size()), 1, CV_64FC3);
  double top = 0;
  for (size_t n = 0; n < idx.size(); ++n)
    for (int c = 0; c < 3; ++c) top = std::max(top, double(measured[idx[n]][c]));
  // The model wants values in [0, 1]; a 3x3 matrix does not change when both sides scale.
  const double s = top > 1 ? 1 / top : 1;
  for (size_t n = 0; n < idx.size(); ++n) {
    const auto &m = measured[idx[n]];
    const auto &r = reference[idx[n]];
    src.at<cv::Vec3d>(int(n)) = cv::Vec3d(m[0] * s, m[1] * s, m[2] * s);
    dst.at<cv::Vec3d>(int(n)) = cv::Vec3d(r[0] * s, r[1] * s, r[2] * s);
  }
  out.model = CorrectionModel::Matrix3x3;
  try {
    cv::ccm::ColorCorrectionModel model(src, dst, cv::ccm::COLOR_SPACE_sRGBL);
    model.setColorSpace(cv::ccm::COLOR_SPACE_sRGB);
    model.setLinear(cv::ccm::LINEARIZATION_IDENTITY);  // the measurements are linear already
    model.setCCM_TYPE(cv::ccm::CCM_3x3);
    model.setDistance(cv::ccm::DISTANCE_CIE2000);
    model.setSaturatedThreshold(0, 1);
    model.run();
    const cv::Mat ccm = model.getCCM();  // row vector convention: out = in * ccm
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) out.matrix[c][k] = ccm.at<double>(k, c);
    return;
  } catch (const cv::Exception &) {
    // Fall through to plain least squares (degenerate patch sets).
  }
  cv::Mat a(int(idx.size()), 3, CV_64F), b(int(idx.size()), 3, CV_64F), x;
  for (size_t n = 0; n < idx.size(); ++n)
    for (int c = 0; c < 3; ++c) {
      a.at<double>(int(n), c) = measured[idx[n]][c];
      b.at<double>(int(n), c) = reference[idx[n]][c];
    }
  cv::solve(a, b, x, cv::DECOMP_SVD);
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k) out.matrix[c][k] = x.at<double>(k, c);
}

void fit_polynomial(const std::vector<int> &idx, const PatchColors &measured, const PatchColors &reference,
                    ColorCorrection &out) {
  out.model = CorrectionModel::ChannelPolynomial;
  for (int c = 0; c < 3; ++c) {
    cv::Mat a(int(idx.size()), 4, CV_64F), b(int(idx.size()), 1, CV_64F), x;
    for (size_t n = 0; n < idx.size(); ++n) {
      const double v = measured[idx[n]][c];
      for (int d = 0; d < 4; ++d) a.at<double>(int(n), d) = std::pow(v, d);
      b.at<double>(int(n)) = reference[idx[n]][c];
    }
    cv::solve(a, b, x, cv::DECOMP_SVD);
    for (int d = 0; d < 4; ++d) out.poly[c][d] = x.at<double>(d);
  }
}

// Quadratic in log-log through the usable neutral patches: measured luminance -> reference
// luminance (straight when fewer than 5 neutrals, or when the quadratic would not be monotonic).
void fit_tone_curve(const std::vector<int> &idx, const PatchColors &measured, const PatchColors &reference,
                    ColorCorrection &out) {
  std::vector<double> xs, ys;
  for (int k : idx) {
    const double x = luminance_double(measured[k].data()), y = luminance_double(reference[k].data());
    if (k >= kFirstNeutralPatch && x > 0 && y > 0) {
      xs.push_back(std::log(x));
      ys.push_back(std::log(y));
    }
  }
  out.curve[0] = 0;
  out.curve[1] = 1;
  out.curve[2] = 0;
  if (xs.size() < 2) return;
  const double lo = *std::min_element(xs.begin(), xs.end()), hi = *std::max_element(xs.begin(), xs.end());
  for (int degree = xs.size() >= 5 ? 2 : 1; degree >= 1; --degree) {
    cv::Mat a(int(xs.size()), degree + 1, CV_64F), b(int(xs.size()), 1, CV_64F), c;
    for (size_t n = 0; n < xs.size(); ++n) {
      for (int d = 0; d <= degree; ++d) a.at<double>(int(n), d) = std::pow(xs[n], d);
      b.at<double>(int(n)) = ys[n];
    }
    cv::solve(a, b, c, cv::DECOMP_SVD);
    const double c2 = degree == 2 ? c.at<double>(2) : 0;
    if (c.at<double>(1) + 2 * c2 * lo > 0 && c.at<double>(1) + 2 * c2 * hi > 0) {
      out.curve[0] = c.at<double>(0);
      out.curve[1] = c.at<double>(1);
      out.curve[2] = c2;
      break;
    }
  }
  out.curve_lo = std::exp(lo);
  out.curve_hi = std::exp(hi);
}

double tone(const ColorCorrection &m, double v) {
  if (!(v > 0)) return 0;
  const double x = std::log(v), lo = std::log(m.curve_lo), hi = std::log(m.curve_hi);
  const double xc = std::min(hi, std::max(lo, x));
  const double y = m.curve[0] + xc * (m.curve[1] + xc * m.curve[2]);
  const double slope = m.curve[1] + 2 * m.curve[2] * xc;  // straight beyond the neutrals' range
  return std::exp(y + slope * (x - xc));
}

void fit_curve_matrix(const std::vector<int> &idx, const PatchColors &measured, const PatchColors &reference,
                      ColorCorrection &out) {
  fit_tone_curve(idx, measured, reference, out);
  PatchColors lin = measured;
  for (auto &c : lin)
    for (auto &v : c) v = float(tone(out, v));
  ColorCorrection m;
  fit_matrix(idx, lin, reference, m);
  std::copy(&m.matrix[0][0], &m.matrix[0][0] + 9, &out.matrix[0][0]);
  out.model = CorrectionModel::ToneCurveMatrix;
}

using Fitter = void (*)(const std::vector<int> &, const PatchColors &, const PatchColors &, ColorCorrection &);

double corrected_de(const ColorCorrection &m, const PatchColors &measured, const PatchColors &reference, int k) {
  float out[3];
  m.apply(measured[k].data(), out);
  return delta_e2000_linear_srgb(out, reference[k].data());
}

// Mean CIEDE2000 of each patch predicted by a model fitted without it.
double leave_one_out(Fitter fit, const std::vector<int> &idx, const PatchColors &measured,
                     const PatchColors &reference) {
  double sum = 0;
  for (size_t n = 0; n < idx.size(); ++n) {
    std::vector<int> rest;
    for (size_t m = 0; m < idx.size(); ++m)
      if (m != n) rest.push_back(idx[m]);
    ColorCorrection model;
    fit(rest, measured, reference, model);
    sum += corrected_de(model, measured, reference, idx[n]);
  }
  return sum / double(idx.size());
}

// ---- calibration steps ----

// Tries the detector on up to `tries` evenly spaced photos; keeps the lowest-cost detection.
bool locate_chart(size_t count, const RgbLoader &load, const RgbLoader &detector_image, const ColorSettings &s,
                  const std::vector<std::string> &names, ChartLocation &chart, std::vector<std::string> &log) {
  if (s.manual) {
    chart = chart_from_corners(s.corners);
    log.push_back("ColorChecker: corner patches given by the user.");
    return true;
  }
  const size_t tries = std::min(count, size_t(std::max(1, s.detect_photos)));
  std::vector<ChartLocation> best;
  size_t best_photo = 0;
  std::vector<std::string> det_log;
  // On photos up to kDetectSide the detector runs on one core, so the photos it tries are searched
  // side by side, as many at a time as there are threads (their 8-bit copies are held that long).
  // Larger photos go one at a time: their reduction and refinement already use OpenCV's threads,
  // and side by side they were no faster (1 M x 24 at 4000x3000: 1.9-3.0 s against 1.5-2.9 s) while
  // holding more memory. Compared in the order tried, so the choice does not depend on the timing.
  const size_t batch = size_t(std::max(1, omp_get_max_threads()));
  std::vector<size_t> photo;
  std::vector<cv::Mat> bgr;
  const auto search_pending = [&]() {
    const size_t n = bgr.size();
    std::vector<std::vector<ChartLocation>> found(n);
    std::vector<std::vector<std::string>> lines(n);
    std::vector<std::exception_ptr> failure(n);
#pragma omp parallel for schedule(dynamic, 1) if (n > 1)
    for (long long b = 0; b < (long long)n; ++b) {
      try {
        found[size_t(b)] = detect_charts(bgr[size_t(b)], 2, lines[size_t(b)]);
      } catch (...) {
        failure[size_t(b)] = std::current_exception();
      }
    }
    for (size_t b = 0; b < n; ++b) {
      if (failure[b]) std::rethrow_exception(failure[b]);
      if (!found[b].empty() && (best.empty() || found[b][0].cost < best[0].cost)) {
        best = found[b];
        best_photo = photo[b];
        det_log = lines[b];
      }
    }
    photo.clear();
    bgr.clear();
  };
  for (size_t t = 0; t < tries; ++t) {  // the loader is not assumed to be thread-safe
    const size_t i = tries > 1 ? t * (count - 1) / (tries - 1) : 0;
    cv::Mat bgr8 = detector_image ? detector_image(i) : cv::Mat();
    if (bgr8.empty()) {
      const cv::Mat img = load(i);
      if (img.empty()) continue;
      bgr8 = srgb8_bgr_image(img);
    }
    photo.push_back(i);
    bgr.push_back(bgr8);
    if (bgr.size() >= batch || std::max(bgr.back().cols, bgr.back().rows) > kDetectSide) search_pending();
  }
  search_pending();
  if (best.empty()) return false;
  // Two charts: the larger one (nearer, more pixels per patch); the camera is fixed, so the
  // same chart is measured in every photo.
  size_t pick = 0;
  for (size_t k = 1; k < best.size(); ++k)
    if (quad_area(best[k]) > quad_area(best[pick])) pick = k;
  chart = best[pick];
  log.push_back("ColorChecker found by the mcc detector in " + photo_name(names, best_photo) + ": " +
                formatted("corner patches at (%.1f, %.1f) and (%.1f, %.1f)", chart.corners[0].x, chart.corners[0].y,
                    chart.corners[2].x, chart.corners[2].y) +
                formatted(", detector cost %.3f.", chart.cost));
  if (best.size() > 1)
    log.push_back(formatted("Warning: %.0f charts found; using the larger one. Give the corner patches manually to "
                      "choose another.",
                      double(best.size())));
  return true;
}

// Per photo: the neutral patches' luminance relative to the reference (0: none usable).
std::vector<double> chart_brightness(const std::vector<PatchMeasurement> &patches, const PatchColors &ref) {
  std::vector<double> b;
  for (const auto &m : patches) {
    const double s = neutral_scale(m.rgb, ref, m.usable);
    b.push_back(s > 0 ? 1 / s : 0);
  }
  return b;
}

// Each patch over the photos, relative to the photo's chart brightness: the ratio of sums over
// the photos that agree with the median (bright photos weigh more, their 8-bit steps are finer;
// a patch shadowed or glinting in one photo is left out).
PatchColors pooled_patches(const std::vector<PatchMeasurement> &patches, const std::vector<double> &brightness,
                           PatchFlags &usable) {
  PatchColors out{};
  for (int k = 0; k < kChartPatches; ++k) {
    std::vector<size_t> photos;
    std::vector<double> lum;
    for (size_t p = 0; p < patches.size(); ++p)
      if (brightness[p] > 0 && patches[p].usable[k]) {
        photos.push_back(p);
        lum.push_back(luminance_double(patches[p].rgb[k].data()) / brightness[p]);
      }
    usable[k] = !photos.empty();
    if (!usable[k]) continue;
    const double med = median_of(lum);
    double sum[3] = {0, 0, 0}, weight = 0;
    for (size_t n = 0; n < photos.size(); ++n) {
      if (std::fabs(lum[n] - med) > 0.1 * med + 1e-4) continue;
      for (int c = 0; c < 3; ++c) sum[c] += patches[photos[n]].rgb[k][c];
      weight += brightness[photos[n]];
    }
    for (int c = 0; c < 3; ++c) out[k][c] = float(sum[c] / weight);
  }
  return out;
}

struct LightFit {
  bool ok = false;
  double g[3] = {0, 0, 0};  // E * chart normal
  double residual = 0;      // RMS relative to the mean brightness
};

// Chart brightness b_p = L_p . g over the photos with a light and a brightness.
LightFit fit_chart_normal(const std::vector<double> &b, const std::vector<std::array<double, 3>> &lights) {
  LightFit f;
  cv::Matx33d a = cv::Matx33d::zeros();
  cv::Vec3d rhs(0, 0, 0);
  int n = 0;
  double mean = 0;
  for (size_t p = 0; p < b.size() && p < lights.size(); ++p) {
    const cv::Vec3d l(lights[p][0], lights[p][1], lights[p][2]);
    if (b[p] <= 0 || cv::norm(l) < 0.5) continue;
    a += l * l.t();
    rhs += l * b[p];
    mean += b[p];
    ++n;
  }
  if (n < 4) return f;
  mean /= n;
  const cv::Vec3d g = a.solve(rhs, cv::DECOMP_SVD);
  double ss = 0;
  for (size_t p = 0; p < b.size() && p < lights.size(); ++p) {
    const cv::Vec3d l(lights[p][0], lights[p][1], lights[p][2]);
    if (b[p] <= 0 || cv::norm(l) < 0.5) continue;
    ss += (b[p] - l.dot(g)) * (b[p] - l.dot(g));
  }
  f.ok = cv::norm(g) > 0;
  for (int k = 0; k < 3; ++k) f.g[k] = g[k];
  f.residual = std::sqrt(ss / n) / mean;
  return f;
}

// Per-photo divisors (see ColorCalibration) and the log lines explaining them.
std::vector<double> exposure_divisors(const std::vector<double> &b, const std::vector<std::array<double, 3>> *lights,
                                      const ColorSettings &s, bool &normalised, std::vector<std::string> &log) {
  std::vector<double> known;
  for (double v : b)
    if (v > 0) known.push_back(v);
  const double bmax = known.empty() ? 1 : *std::max_element(known.begin(), known.end());
  const double bmed = median_of(known);
  double spread = 0;
  for (double v : known) spread = std::max(spread, std::fabs(v - bmed) / bmed);
  std::vector<double> d(b.size(), bmax);
  normalised = false;
  if (s.exposure == ExposureMode::Off) {
    log.push_back("Exposure normalisation off: one exposure for all photos.");
    return d;
  }
  LightFit fit;
  if (lights) fit = fit_chart_normal(b, *lights);
  if (fit.ok) {
    const double e = std::sqrt(fit.g[0] * fit.g[0] + fit.g[1] * fit.g[1] + fit.g[2] * fit.g[2]);
    const double n[3] = {fit.g[0] / e, fit.g[1] / e, fit.g[2] / e};
    if (s.exposure == ExposureMode::Auto && fit.residual < s.constant_light_tolerance) {
      log.push_back(formatted("Light intensity constant between photos: the chart's brightness follows its angle to "
                        "the light (residual %.1f %%); one exposure for all photos.",
                        100 * fit.residual));
      return std::vector<double>(b.size(), e);
    }
    // E_p = b_p / (n . L_p); photos where the chart barely faces the light keep the median.
    std::vector<double> es;
    for (size_t p = 0; p < b.size(); ++p) {
      const std::array<double, 3> l = p < lights->size() ? (*lights)[p] : std::array<double, 3>{{0, 0, 0}};
      const double cosine = l[0] * n[0] + l[1] * n[1] + l[2] * n[2];
      d[p] = b[p] > 0 && cosine > 0.2 ? b[p] / cosine : 0;
      if (d[p] > 0) es.push_back(d[p]);
    }
    const double emed = median_of(es);
    for (double &v : d)
      if (v <= 0) v = emed;
    normalised = true;
    log.push_back(formatted("Light intensity varies between photos (chart brightness departs from its angle to the light "
                      "by %.1f %%, hand-held flash?): each photo's exposure is normalised by the chart's neutral "
                      "patches, with the chart normal fitted to the sphere lights.",
                      100 * fit.residual));
    return d;
  }
  if (s.exposure == ExposureMode::On) {
    for (size_t p = 0; p < b.size(); ++p) d[p] = b[p] > 0 ? b[p] : bmed;
    normalised = true;
    log.push_back(formatted("Exposure normalisation on: each photo is normalised by the chart's neutral patches (their "
                      "brightness varies by up to %.1f %%; without light directions this includes the chart's angle "
                      "to the light).",
                      100 * spread));
    return d;
  }
  log.push_back(formatted("Chart brightness varies by up to %.1f %% between photos; without light directions this cannot "
                    "be told from the chart's angle to the light, so photos are not normalised (turn exposure "
                    "normalisation on for a light of varying intensity).",
                    100 * spread));
  return d;
}

} // namespace

const PatchColors &colorchecker_classic_reference() {
  static const PatchColors ref = {{{{0.173032f, 0.082110f, 0.056727f}}, {{0.568320f, 0.292695f, 0.218355f}},
                                   {{0.103650f, 0.195884f, 0.331405f}}, {{0.101597f, 0.148922f, 0.051883f}},
                                   {{0.221596f, 0.215845f, 0.434612f}}, {{0.108064f, 0.514372f, 0.412642f}},
                                   {{0.747364f, 0.200629f, 0.028080f}}, {{0.057579f, 0.105168f, 0.402961f}},
                                   {{0.566762f, 0.084248f, 0.119695f}}, {{0.110995f, 0.042308f, 0.142926f}},
                                   {{0.345469f, 0.508720f, 0.049442f}}, {{0.794613f, 0.359425f, 0.020520f}},
                                   {{0.017104f, 0.050220f, 0.292207f}}, {{0.055980f, 0.300211f, 0.068712f}},
                                   {{0.455855f, 0.030337f, 0.040857f}}, {{0.857376f, 0.567573f, 0.006850f}},
                                   {{0.533486f, 0.088611f, 0.307504f}}, {{-0.037406f, 0.246995f, 0.400412f}},
                                   {{0.912627f, 0.914939f, 0.893670f}}, {{0.579819f, 0.592004f, 0.593289f}},
                                   {{0.354906f, 0.365448f, 0.367554f}}, {{0.190074f, 0.191866f, 0.193084f}},
                                   {{0.085292f, 0.088880f, 0.092576f}}, {{0.030319f, 0.031138f, 0.032748f}}}};
  return ref;
}

std::vector<cv::Point2f> chart_patch_centres(const ChartLocation &chart) {
  const cv::Matx33d h = grid_to_image(chart);
  std::vector<cv::Point2f> out;
  for (int k = 0; k < kChartPatches; ++k) {
    const cv::Point2d p = map_point(h, k % 6, k / 6);
    out.emplace_back(float(p.x), float(p.y));
  }
  return out;
}

ChartLocation chart_from_corners(const float xy[8]) {
  ChartLocation c;
  for (int i = 0; i < 4; ++i) c.corners[i] = cv::Point2f(xy[2 * i], xy[2 * i + 1]);
  return c;
}

cv::Mat srgb8_bgr_image(const cv::Mat &linear_rgb) {
  CV_Assert(linear_rgb.type() == CV_32FC3);
  // Code k is the largest whose lower rounding bound srgb_to_linear((k - 0.5) / 255) the value
  // reaches: 255 * linear_to_srgb(v) rounded to the nearest code, without a pow() per channel
  // (the chart search converts 12-50 MP photos). A 65536-bucket table gives the code at a
  // bucket's low end; the bounds are further apart than a bucket (>= 1.5e-4 > 1.5e-5), so at most
  // one lies inside it: one comparison finishes the job.
  struct Encoder {
    std::array<float, 256> bound{};      // bound[k]: lowest value of code k (bound[0] = 0)
    std::array<uint8_t, 65537> code{};   // code at i / 65536
    Encoder() {
      for (int k = 1; k <= 255; ++k) bound[size_t(k)] = srgb_to_linear((float(k) - 0.5f) / 255.0f);
      int k = 0;
      for (size_t i = 0; i < code.size(); ++i) {
        const float v = float(i) / 65536.0f;
        while (k < 255 && v >= bound[size_t(k + 1)]) ++k;
        code[i] = uint8_t(k);
      }
    }
    uint8_t operator()(float v) const {
      if (!(v > 0)) return 0;  // also NaN
      if (v >= 1) return 255;
      const uint8_t k = code[size_t(v * 65536.0f)];
      return k < 255 && v >= bound[size_t(k) + 1] ? uint8_t(k + 1) : k;
    }
  };
  static const Encoder encode;
  cv::Mat out(linear_rgb.size(), CV_8UC3);
#pragma omp parallel for schedule(static)
  for (int y = 0; y < linear_rgb.rows; ++y) {
    const cv::Vec3f *in = linear_rgb.ptr<cv::Vec3f>(y);
    cv::Vec3b *o = out.ptr<cv::Vec3b>(y);
    for (int x = 0; x < linear_rgb.cols; ++x)
      for (int c = 0; c < 3; ++c) o[x][2 - c] = encode(in[x][c]);
  }
  return out;
}

cv::Mat linear_rgb_image(const cv::Mat &image, bool bgr, bool decode_srgb) {
  if (image.empty()) return cv::Mat();
  cv::Mat c3;
  if (image.channels() == 1) cv::cvtColor(image, c3, cv::COLOR_GRAY2BGR);
  else if (image.channels() == 4) cv::cvtColor(image, c3, bgr ? cv::COLOR_BGRA2BGR : cv::COLOR_RGBA2RGB);
  else c3 = image;
  if (bgr) cv::cvtColor(c3, c3, cv::COLOR_BGR2RGB);
  try {
    return decode_to_linear(c3, decode_srgb);
  } catch (const InputError &e) {
    throw InputError(std::string("Colour chart: ") + e.what());
  }
}

namespace {
std::vector<ChartLocation> detect_charts_at_full_size(const cv::Mat &bgr8, int max_charts, std::vector<std::string> &log) {
  std::vector<ChartLocation> out;
  CV_Assert(bgr8.type() == CV_8UC3);
  cv::Ptr<cv::mcc::CCheckerDetector> det = cv::mcc::CCheckerDetector::create();
  if (!det->process(bgr8, cv::mcc::MCC24, std::max(1, max_charts))) return out;
  const cv::Point2f model[4] = {{0, 0}, {kBoxW, 0}, {kBoxW, kBoxH}, {0, kBoxH}};
  const cv::Point2f centres[4] = {{kFirstCentre, kFirstCentre},
                                  {kFirstCentre + 5 * kPitch, kFirstCentre},
                                  {kFirstCentre + 5 * kPitch, kFirstCentre + 3 * kPitch},
                                  {kFirstCentre, kFirstCentre + 3 * kPitch}};
  cv::Mat linear;  // for the orientation check
  for (const cv::Ptr<cv::mcc::CChecker> &c : det->getListColorChecker()) {
    const std::vector<cv::Point2f> box = c->getBox();
    if (box.size() != 4) continue;
    // Detector pixels have integer centres; ours are at +0.5.
    cv::Point2f img[4];
    for (int i = 0; i < 4; ++i) img[i] = box[i] + cv::Point2f(0.5f, 0.5f);
    const cv::Matx33d h(cv::getPerspectiveTransform(model, img));
    ChartLocation loc;
    loc.detected = true;
    loc.cost = c->getCost();
    for (int i = 0; i < 4; ++i) {
      const cv::Point2d p = map_point(h, centres[i].x, centres[i].y);
      loc.corners[i] = cv::Point2f(float(p.x), float(p.y));
    }
    if (linear.empty()) linear = linear_rgb_image(bgr8, true);
    if (neutral_row_reversed(measure_chart(linear, loc))) {
      std::swap(loc.corners[0], loc.corners[2]);
      std::swap(loc.corners[1], loc.corners[3]);
      log.push_back("ColorChecker read upside down by the detector: turned by 180 degrees (neutral row).");
    }
    out.push_back(loc);
    if (int(out.size()) >= max_charts) break;
  }
  std::sort(out.begin(), out.end(), [](const ChartLocation &a, const ChartLocation &b) { return a.cost < b.cost; });
  return out;
}

// The chart `coarse` (found in the photo reduced by `scale`) located again at full resolution in
// a window around it; the coarse location, scaled, when the detector misses it there.
ChartLocation refine_chart(const cv::Mat &bgr8, const ChartLocation &coarse, cv::Point2f scale, int factor,
                           std::vector<std::string> &log) {
  ChartLocation scaled = coarse;
  for (cv::Point2f &p : scaled.corners) p = cv::Point2f(p.x * scale.x, p.y * scale.y);  // continuous pixel coordinates
  cv::Rect2f box = cv::boundingRect(std::vector<cv::Point2f>(scaled.corners.begin(), scaled.corners.end()));
  // The corner patches' centres span 5 x 3 pitches; the chart's frame lies within a pitch of them.
  const float margin = 0.5f * std::max(box.width, box.height);
  const cv::Rect window = cv::Rect(cv::Point(int(box.x - margin), int(box.y - margin)),
                                   cv::Point(int(box.x + box.width + margin) + 1, int(box.y + box.height + margin) + 1)) &
                          cv::Rect(0, 0, bgr8.cols, bgr8.rows);
  std::vector<std::string> lines;
  std::vector<ChartLocation> found = detect_charts_at_full_size(bgr8(window).clone(), 1, lines);
  if (found.empty()) {
    log.push_back(formatted("ColorChecker: located at 1/%.0f of the photo's size only (not found again at full size).", factor));
    return scaled;
  }
  ChartLocation fine = found.front();
  for (cv::Point2f &p : fine.corners) p += cv::Point2f(float(window.x), float(window.y));
  log.insert(log.end(), lines.begin(), lines.end());
  return fine;
}
} // namespace

std::vector<ChartLocation> detect_charts(const cv::Mat &bgr8, int max_charts, std::vector<std::string> &log) {
  // The detector's time grows with the pixel count, and a chart needs far fewer pixels than a
  // 12-50 MP photo has: larger photos are searched at a reduced size first (a photo without a
  // chart, the common case, costs only that), then each chart found is located again at full
  // resolution in a window around it, so its corners keep full-resolution precision. (Reduced
  // from the 8-bit encoded photo: averaged in linear light, the dark gaps between patches fade
  // and the detector misses charts it finds here.)
  CV_Assert(bgr8.type() == CV_8UC3);
  const int longer = std::max(bgr8.cols, bgr8.rows);
  if (longer <= kDetectSide) return detect_charts_at_full_size(bgr8, max_charts, log);
  const int factor = (longer + kDetectSide - 1) / kDetectSide;
  cv::Mat reduced;
  cv::resize(bgr8, reduced, cv::Size(bgr8.cols / factor, bgr8.rows / factor), 0, 0, cv::INTER_AREA);
  std::vector<ChartLocation> out = detect_charts_at_full_size(reduced, max_charts, log);
  const cv::Point2f scale(float(bgr8.cols) / float(reduced.cols), float(bgr8.rows) / float(reduced.rows));
  for (ChartLocation &chart : out) chart = refine_chart(bgr8, chart, scale, factor, log);
  std::sort(out.begin(), out.end(), [](const ChartLocation &a, const ChartLocation &b) { return a.cost < b.cost; });
  return out;
}

namespace {
// The pixels measure_chart reads: the chart's grid (corner patch centres at 0..5 x 0..3, patches
// +-0.5 around them) mapped into the photo, 2 pixels wider for the bilinear footprints, x, y >= 0.
cv::Rect chart_region(const ChartLocation &chart) {
  const cv::Matx33d h = grid_to_image(chart);
  double x0 = 1e30, y0 = 1e30, x1 = -1e30, y1 = -1e30;
  for (const cv::Point2d g : {cv::Point2d(-0.5, -0.5), cv::Point2d(5.5, -0.5), cv::Point2d(5.5, 3.5), cv::Point2d(-0.5, 3.5)}) {
    const cv::Point2d p = map_point(h, g.x, g.y);
    x0 = std::min(x0, p.x), y0 = std::min(y0, p.y), x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
  }
  if (!(x1 > x0 && y1 > y0 && x1 - x0 < 1e6 && y1 - y0 < 1e6)) return cv::Rect();  // degenerate: whole photo
  const int left = std::max(0, int(std::floor(x0)) - 2), top = std::max(0, int(std::floor(y0)) - 2);
  return cv::Rect(left, top, std::max(1, int(std::ceil(x1)) + 3 - left), std::max(1, int(std::ceil(y1)) + 3 - top));
}

// measure_chart on `img`, whose pixel (0, 0) is the photo's pixel `origin` (integer offsets keep
// every sampling position and weight exactly those of the whole photo).
PatchMeasurement measure_chart_at(const cv::Mat &img, const ChartLocation &chart, cv::Point origin) {
  CV_Assert(img.type() == CV_32FC3);
  PatchMeasurement m;
  const cv::Matx33d h = grid_to_image(chart);
  const int n = 9;
  for (int k = 0; k < kChartPatches; ++k) {
    const double cx = k % 6, cy = k / 6;
    std::vector<std::pair<double, cv::Vec3f>> s;
    bool inside = true;
    int clipped = 0;
    for (int a = 0; a < n && inside; ++a)
      for (int b = 0; b < n; ++b) {
        const cv::Point2d p = map_point(h, cx - 0.3 + 0.6 * (b + 0.5) / n, cy - 0.3 + 0.6 * (a + 0.5) / n);
        cv::Vec3f v;
        if (!sample_rgb(img, p.x - origin.x, p.y - origin.y, v)) {
          inside = false;
          break;
        }
        clipped += v[0] >= kClippedLinearValue || v[1] >= kClippedLinearValue || v[2] >= kClippedLinearValue;
        s.emplace_back(luminance_double(&v[0]), v);
      }
    if (!inside) continue;
    // Trimmed mean: specks of dust, a glint or the patch edge do not move it.
    std::sort(s.begin(), s.end(), [](const std::pair<double, cv::Vec3f> &x, const std::pair<double, cv::Vec3f> &y) {
      return x.first < y.first;
    });
    const size_t lo = s.size() / 10, hi = s.size() - s.size() / 10;
    cv::Vec3d sum(0, 0, 0);
    for (size_t i = lo; i < hi; ++i) sum += cv::Vec3d(s[i].second);
    sum /= double(hi - lo);
    for (int c = 0; c < 3; ++c) m.rgb[k][c] = float(sum[c]);
    m.clipped[k] = float(clipped) / float(s.size());
    m.usable[k] = m.clipped[k] < 0.02f && luminance_double(m.rgb[k].data()) > 1e-3;
  }
  return m;
}
} // namespace

PatchMeasurement measure_chart(const cv::Mat &img, const ChartLocation &chart) {
  return measure_chart_at(img, chart, cv::Point(0, 0));
}

const char *correction_model_name(CorrectionModel m) {
  switch (m) {
  case CorrectionModel::None: return "none";
  case CorrectionModel::Matrix3x3: return "3x3 colour correction matrix (cv::ccm, CIEDE2000 loss)";
  case CorrectionModel::ChannelPolynomial: return "per-channel cubic polynomial (thesis 4.2)";
  case CorrectionModel::ToneCurveMatrix: return "neutral tone curve + 3x3 matrix (cv::ccm)";
  }
  return "?";
}

void ColorCorrection::apply(const float in_raw[3], float out[3]) const {
  float r[3], in[3] = {in_raw[0], in_raw[1], in_raw[2]};
  if (model == CorrectionModel::ToneCurveMatrix)
    for (int c = 0; c < 3; ++c) in[c] = float(tone(*this, in_raw[c]));
  for (int c = 0; c < 3; ++c) {
    if (model == CorrectionModel::Matrix3x3 || model == CorrectionModel::ToneCurveMatrix) {
      r[c] = float(matrix[c][0] * in[0] + matrix[c][1] * in[1] + matrix[c][2] * in[2]);
    } else if (model == CorrectionModel::ChannelPolynomial) {
      const double v = in[c];
      r[c] = float(poly[c][0] + v * (poly[c][1] + v * (poly[c][2] + v * poly[c][3])));
    } else {
      r[c] = in[c];
    }
  }
  for (int c = 0; c < 3; ++c) out[c] = r[c];
}

double neutral_scale(const PatchColors &measured, const PatchColors &reference, const PatchFlags &usable) {
  std::vector<double> ratios;
  for (int k = kFirstNeutralPatch; k < kChartPatches; ++k) {
    const double y = luminance_double(measured[k].data());
    if (usable[k] && y > 0) ratios.push_back(luminance_double(reference[k].data()) / y);
  }
  return median_of(ratios);
}

CorrectionFit fit_color_correction(const PatchColors &measured, const PatchColors &reference,
                                   const PatchFlags &usable) {
  std::vector<int> idx;
  int neutrals = 0;
  for (int k = 0; k < kChartPatches; ++k)
    if (usable[k]) {
      idx.push_back(k);
      neutrals += k >= kFirstNeutralPatch;
    }
  if (idx.size() < 8 || neutrals < 3)
    throw ProcessingError(formatted("Colour correction: only %.0f usable chart patches (%.0f neutral); at least 8 with "
                              "3 neutral are needed. Check the chart's exposure (no clipped white) and position.",
                              double(idx.size()), double(neutrals)));
  CorrectionFit f;
  f.patches = int(idx.size());
  fit_matrix(idx, measured, reference, f.matrix);
  fit_polynomial(idx, measured, reference, f.polynomial);
  fit_curve_matrix(idx, measured, reference, f.curve_matrix);
  f.heldout_matrix = leave_one_out(fit_matrix, idx, measured, reference);
  f.heldout_polynomial = leave_one_out(fit_polynomial, idx, measured, reference);
  f.heldout_curve_matrix = leave_one_out(fit_curve_matrix, idx, measured, reference);
  f.best = f.matrix;
  double best = f.heldout_matrix;
  if (f.heldout_curve_matrix < best) {
    best = f.heldout_curve_matrix;
    f.best = f.curve_matrix;
  }
  if (f.heldout_polynomial < best) f.best = f.polynomial;
  for (int k : idx) {
    const double before = delta_e2000_linear_srgb(measured[k].data(), reference[k].data());
    const double after = corrected_de(f.best, measured, reference, k);
    f.before += before / double(idx.size());
    f.after += after / double(idx.size());
    f.before_max = std::max(f.before_max, before);
    f.after_max = std::max(f.after_max, after);
  }
  return f;
}

ColorCalibration calibrate_colors(size_t count, const RgbLoader &load, const ColorSettings &s,
                                  const std::vector<std::array<double, 3>> *lights,
                                  const std::vector<std::string> &names, const RgbLoader &detector_image,
                                  const RgbRegionLoader &load_region) {
  ColorCalibration cal;
  cal.divisor.assign(count, 1.0);
  const PatchColors &ref = s.reference ? *s.reference : colorchecker_classic_reference();
  if (count == 0) return cal;
  if (!locate_chart(count, load, detector_image, s, names, cal.chart, cal.log)) {
    const std::string msg = "No ColorChecker found in the photos of this viewpoint";
    if (s.require_chart)
      throw InputError(msg + " and colour correction is required: give the centres of the chart's corner patches "
                             "(dark skin, bluish green, black, white) manually, or check that the whole chart is in "
                             "the frame and lit.");
    cal.log.push_back(msg + ": the samples are NOT colour-corrected.");
    return cal;
  }
  const cv::Rect region = load_region ? chart_region(cal.chart) : cv::Rect();
  for (size_t i = 0; i < count; ++i) {
    const cv::Mat img = region.empty() ? load(i) : load_region(i, region);
    cal.patches.push_back(img.empty() ? PatchMeasurement{} : measure_chart_at(img, cal.chart, region.tl()));
  }
  const std::vector<double> b = chart_brightness(cal.patches, ref);
  for (size_t i = 0; i < count; ++i)
    if (b[i] <= 0)
      cal.log.push_back("Warning: " + photo_name(names, i) +
                        ": no usable neutral patch on the chart (shadowed or clipped); its exposure is taken "
                        "from the other photos.");
  PatchFlags usable{};
  const PatchColors pooled = pooled_patches(cal.patches, b, usable);
  try {
    cal.fit = fit_color_correction(pooled, ref, usable);
  } catch (const ProcessingError &e) {
    if (s.require_chart) throw InputError(e.what());
    cal.log.push_back(std::string(e.what()) + " The samples are NOT colour-corrected.");
    return cal;
  }
  cal.correction = cal.fit.best;
  cal.corrected = true;
  cal.log.push_back(formatted("Colour correction: %.0f patches; held-out CIEDE2000 %.2f (3x3 matrix), %.2f (tone curve + "
                        "matrix), %.2f (per-channel polynomial): ",
                        cal.fit.patches, cal.fit.heldout_matrix, cal.fit.heldout_curve_matrix,
                        cal.fit.heldout_polynomial) +
                    correction_model_name(cal.correction.model) +
                    formatted(" chosen. Patch CIEDE2000 mean %.2f (max %.2f) before, %.2f (max %.2f) after.", cal.fit.before,
                        cal.fit.before_max, cal.fit.after, cal.fit.after_max));
  cal.divisor = exposure_divisors(b, lights, s, cal.exposure_normalised, cal.log);
  return cal;
}

void apply_color_calibration(const ColorCalibration &cal, size_t photo, float rgb[3]) {
  if (!cal.corrected || photo >= cal.divisor.size()) return;
  const float d = float(cal.divisor[photo]);
  const float in[3] = {rgb[0] / d, rgb[1] / d, rgb[2] / d};
  cal.correction.apply(in, rgb);
}

cv::Mat apply_color_calibration(const ColorCalibration &cal, size_t photo, const cv::Mat &linear_rgb) {
  CV_Assert(linear_rgb.type() == CV_32FC3);
  cv::Mat out = linear_rgb.clone();
  for (int y = 0; y < out.rows; ++y) {
    cv::Vec3f *row = out.ptr<cv::Vec3f>(y);
    for (int x = 0; x < out.cols; ++x) apply_color_calibration(cal, photo, &row[x][0]);
  }
  return out;
}

} // namespace vbrdf
