// Colour differences (CIEDE2000) and colour correction from a ColorChecker: model fitting with
// known answers, chart detection and measurement on synthetic charts, failure cases (no chart,
// two charts, too few patches), exposure normalisation, samples, real photos and the Mitsuba
// scenes' colour cast.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include <limits>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "calib_data.h"
#include "calibration/color_chart.h"
#include "samples/sample_colors.h"
#include "base/color_difference.h"
#include "base/errors.h"
#include "inputs/photo.h"
#include "test_paths.h"

using namespace vbrdf;

TEST(ColorDifference, Ciede2000MatchesSharmaWuDalalPairs) {
  // Sharma, Wu and Dalal (2005), "The CIEDE2000 color-difference formula", table 1.
  const float pairs[][7] = {
      {50, 2.6772f, -79.7751f, 50, 0, -82.7485f, 2.0425f},   {50, 3.1571f, -77.2803f, 50, 0, -82.7485f, 2.8615f},
      {50, 2.8361f, -74.0200f, 50, 0, -82.7485f, 3.4412f},   {50, -1.3802f, -84.2814f, 50, 0, -82.7485f, 1.0000f},
      {50, 0, 0, 50, -1, 2, 2.3669f},                        {50, 2.49f, -0.001f, 50, -2.49f, 0.0009f, 7.1792f},
      {50, 2.49f, -0.001f, 50, -2.49f, 0.0011f, 7.2195f},    {50, -0.001f, 2.49f, 50, 0.0009f, -2.49f, 4.8045f},
      {50, 2.5f, 0, 50, 0, -2.5f, 4.3065f},                  {50, 2.5f, 0, 73, 25, -18, 27.1492f},
      {50, 2.5f, 0, 61, -5, 29, 22.8977f},                   {50, 2.5f, 0, 56, -27, -3, 31.9030f},
      {50, 2.5f, 0, 58, 24, 15, 19.4535f},                   {50, 2.5f, 0, 50, 3.1736f, 0.5854f, 1.0000f},
      {60.2574f, -34.0099f, 36.2677f, 60.4626f, -34.1751f, 39.4387f, 1.2644f},
      {63.0109f, -31.0961f, -5.8663f, 62.8187f, -29.7946f, -4.0864f, 1.2630f},
      {61.2901f, 3.7196f, -5.3901f, 61.4292f, 2.2480f, -4.9620f, 1.8731f},
      {35.0831f, -44.1164f, 3.7933f, 35.0232f, -40.0716f, 1.5901f, 1.8645f},
      {22.7233f, 20.0904f, -46.6940f, 23.0331f, 14.9730f, -42.5619f, 2.0373f},
      {36.4612f, 47.8580f, 18.3852f, 36.2715f, 50.5065f, 21.2231f, 1.4146f},
      {90.8027f, -2.0831f, 1.4410f, 91.1528f, -1.6435f, 0.0447f, 1.4441f},
      {90.9257f, -0.5406f, -0.9208f, 88.6381f, -0.8985f, -0.7239f, 1.5381f},
      {6.7747f, -0.2908f, -2.4247f, 5.8714f, -0.0985f, -2.2286f, 0.6377f},
      {2.0776f, 0.0795f, -1.1350f, 0.9033f, -0.0636f, -0.5514f, 0.9082f},
  };
  for (const auto &p : pairs) {
    EXPECT_NEAR(ciede2000(p, p + 3), p[6], 1e-4) << p[0] << " " << p[1] << " " << p[2];
    EXPECT_NEAR(ciede2000(p + 3, p), p[6], 1e-4);
  }
  const float lab[3] = {52, 10, -30};
  EXPECT_EQ(ciede2000(lab, lab), 0);
}

TEST(ColorDifference, LinearSrgbToLabKnownColours) {
  float lab[3];
  const float white[3] = {1, 1, 1}, red[3] = {1, 0, 0}, green[3] = {0, 1, 0}, blue[3] = {0, 0, 1};
  linear_srgb_to_lab(white, lab);
  EXPECT_NEAR(lab[0], 100, 1e-3);
  EXPECT_NEAR(lab[1], 0, 1e-3);
  EXPECT_NEAR(lab[2], 0, 1e-3);
  linear_srgb_to_lab(red, lab);  // sRGB primaries in CIELAB (D65)
  EXPECT_NEAR(lab[0], 53.24, 0.02);
  EXPECT_NEAR(lab[1], 80.09, 0.05);
  EXPECT_NEAR(lab[2], 67.20, 0.05);
  linear_srgb_to_lab(green, lab);
  EXPECT_NEAR(lab[0], 87.73, 0.02);
  EXPECT_NEAR(lab[1], -86.18, 0.05);
  EXPECT_NEAR(lab[2], 83.18, 0.05);
  linear_srgb_to_lab(blue, lab);
  EXPECT_NEAR(lab[0], 32.30, 0.02);
  EXPECT_NEAR(lab[1], 79.19, 0.05);
  EXPECT_NEAR(lab[2], -107.86, 0.05);
  // A mid grey and its double differ only in lightness.
  const float g1[3] = {0.2f, 0.2f, 0.2f}, g2[3] = {0.4f, 0.4f, 0.4f};
  float l1[3], l2[3];
  linear_srgb_to_lab(g1, l1);
  linear_srgb_to_lab(g2, l2);
  EXPECT_NEAR(l1[1], 0, 1e-3);
  EXPECT_NEAR(l2[2], 0, 1e-3);
  EXPECT_GT(delta_e2000_linear_srgb(g1, g2), 10);
}

namespace {

const double kCast[3][3] = {{1.0148, 0.10, 0.032}, {0.0708, 0.88, 0.048}, {0.0354, 0.12, 0.68}};

std::array<float, 3> cast(const std::array<float, 3> &c, double gain, double gamma = 1) {
  std::array<float, 3> o;
  for (int i = 0; i < 3; ++i) {
    const double v = gain * (kCast[i][0] * c[0] + kCast[i][1] * c[1] + kCast[i][2] * c[2]);
    o[i] = float(std::pow(std::max(0.0, v), gamma));
  }
  return o;
}

PatchFlags all_usable() {
  PatchFlags f;
  f.fill(true);
  return f;
}

// A ColorChecker Classic drawn in a linear RGB float photo (RGB order): the chart's box (mcc's
// template, 16.75 x 11.25 units, patches 2.5 units at 1.5 + 2.75 k) mapped by a homography to
// `quad` (image corners of the box, dark skin corner first), colours through the camera cast.
void draw_chart(cv::Mat &img, const std::array<cv::Point2f, 4> &quad, double gain, double gamma = 1) {
  const cv::Point2f box[4] = {{0, 0}, {16.75f, 0}, {16.75f, 11.25f}, {0, 11.25f}};
  const cv::Matx33d h(cv::getPerspectiveTransform(box, quad.data()));
  auto to_img = [&](double x, double y) {
    const cv::Vec3d p = h * cv::Vec3d(x, y, 1);
    return cv::Point(int(std::lround(p[0] / p[2] * 16)), int(std::lround(p[1] / p[2] * 16)));  // 4 fractional bits
  };
  auto fill = [&](double x0, double y0, double x1, double y1, const std::array<float, 3> &c) {
    const cv::Point pts[4] = {to_img(x0, y0), to_img(x1, y0), to_img(x1, y1), to_img(x0, y1)};
    cv::fillConvexPoly(img, pts, 4, cv::Scalar(c[0], c[1], c[2]), cv::LINE_AA, 4);
  };
  fill(0, 0, 16.75, 11.25, cast({{0.03f, 0.03f, 0.03f}}, gain, gamma));
  const PatchColors &ref = colorchecker_classic_reference();
  for (int k = 0; k < kChartPatches; ++k) {
    const double cx = 1.5 + 2.75 * (k % 6), cy = 1.5 + 2.75 * (k / 6);
    std::array<float, 3> c = ref[k];
    for (float &v : c) v = std::max(v, 0.0f);
    fill(cx - 1.25, cy - 1.25, cx + 1.25, cy + 1.25, cast(c, gain, gamma));
  }
}

cv::Mat background(int w, int h, unsigned seed) {
  cv::Mat img(h, w, CV_32FC3);
  cv::RNG rng(seed);
  rng.fill(img, cv::RNG::UNIFORM, cv::Scalar::all(0.08), cv::Scalar::all(0.14));
  cv::GaussianBlur(img, img, cv::Size(0, 0), 3);
  return img;
}

const std::array<cv::Point2f, 4> kQuad = {{{120, 90}, {520, 110}, {510, 380}, {110, 360}}};

// Corner-patch centres of a chart drawn with draw_chart().
std::array<cv::Point2f, 4> corner_patch_centres(const std::array<cv::Point2f, 4> &quad) {
  const cv::Point2f box[4] = {{0, 0}, {16.75f, 0}, {16.75f, 11.25f}, {0, 11.25f}};
  const cv::Matx33d h(cv::getPerspectiveTransform(box, quad.data()));
  const cv::Point2f c[4] = {{1.5f, 1.5f}, {15.25f, 1.5f}, {15.25f, 9.75f}, {1.5f, 9.75f}};
  std::array<cv::Point2f, 4> out;
  for (int i = 0; i < 4; ++i) {
    const cv::Vec3d p = h * cv::Vec3d(c[i].x, c[i].y, 1);
    out[i] = cv::Point2f(float(p[0] / p[2]) + 0.5f, float(p[1] / p[2]) + 0.5f);  // drawn in index coordinates
  }
  return out;
}

} // namespace

TEST(ChartCorrection, MatrixRecoversAKnownCast) {
  const PatchColors &ref = colorchecker_classic_reference();
  PatchColors measured;
  for (int k = 0; k < kChartPatches; ++k) measured[k] = cast(ref[k], 1.0);
  const double s = neutral_scale(measured, ref, all_usable());
  for (auto &c : measured)
    for (float &v : c) v = float(v * s);
  const CorrectionFit f = fit_color_correction(measured, ref, all_usable());
  EXPECT_GT(f.before, 3.0);
  EXPECT_LT(f.after, 0.3);
  EXPECT_LT(f.heldout_matrix, 0.5);
  EXPECT_LT(f.heldout_matrix, f.heldout_polynomial);  // a per-channel curve cannot undo mixing
  EXPECT_NE(f.best.model, CorrectionModel::ChannelPolynomial);
  // The matrix inverts the cast: applying it to a cast colour gives the colour back.
  const std::array<float, 3> c = {{0.3f, 0.5f, 0.2f}};
  const std::array<float, 3> m = cast(c, s);
  float out[3];
  f.matrix.apply(m.data(), out);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(out[i], c[i], 0.01);
}

TEST(ChartCorrection, ToneCurveFromTheNeutralsUndoesANonSrgbCurve) {
  // A camera whose JPEG curve is not sRGB: decoded values are linear^0.8 after the cast.
  const PatchColors &ref = colorchecker_classic_reference();
  PatchColors measured;
  for (int k = 0; k < kChartPatches; ++k) measured[k] = cast(ref[k], 0.9, 0.8);
  const CorrectionFit f = fit_color_correction(measured, ref, all_usable());
  EXPECT_EQ(f.best.model, CorrectionModel::ToneCurveMatrix);
  EXPECT_LT(f.heldout_curve_matrix, 1.0);
  EXPECT_LT(f.after, 1.0);
  EXPECT_GT(f.heldout_matrix, f.heldout_curve_matrix);
}

TEST(ChartCorrection, TooFewUsablePatchesIsAnError) {
  const PatchColors &ref = colorchecker_classic_reference();
  PatchFlags usable{};
  for (int k = 18; k < 24; ++k) usable[k] = true;  // neutrals only: 6 < 8
  EXPECT_THROW(fit_color_correction(ref, ref, usable), ProcessingError);
}

// The detector's 8-bit image taken from an 8-bit sRGB photo's own codes (photo_srgb8_bgr, the
// fit's chart search) is the image the linear round trip gives, for every code in every channel
// and for the channel orders a Photo may have (OpenCV's BGR, a host's RGBA, grey); 16-bit and
// linear-encoded photos have none (the search then converts them as before).
TEST(ChartDetection, EightBitPhotosGiveTheDetectorTheirOwnCodes) {
  const std::vector<std::pair<int, std::array<int, 3>>> layouts = {{3, {{2, 1, 0}}}, {4, {{0, 1, 2}}}, {1, {{0, 0, 0}}}};
  for (const auto &layout : layouts) {
    const int n = layout.first;
    cv::Mat codes(3, 256, CV_8UC(n));
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 256; ++x)
        for (int c = 0; c < n; ++c) codes.ptr<uint8_t>(y)[n * x + c] = uint8_t((x + 85 * (c + y)) % 256);
    HostPixels host;
    host.pixels = codes;
    host.rgb = layout.second;
    const Photo photo = photo_from_host("codes.png", host, PhotoEncoding::SRGB);
    const cv::Mat direct = photo_srgb8_bgr(photo), round_trip = srgb8_bgr_image(photo_linear_rgb(photo));
    ASSERT_EQ(direct.type(), CV_8UC3) << n << " channels";
    EXPECT_EQ(cv::norm(direct, round_trip, cv::NORM_INF), 0.0) << n << " channels";
    EXPECT_GT(cv::norm(direct, cv::NORM_INF), 250.0);  // every code is there
    if (n == 3) EXPECT_EQ(direct.at<cv::Vec3b>(0, 7), cv::Vec3b(codes.at<cv::Vec3b>(0, 7)));  // BGR in, BGR out
    EXPECT_TRUE(photo_srgb8_bgr(photo_from_host("codes.png", host, PhotoEncoding::Linear)).empty());
  }
  HostPixels wide;
  wide.pixels = cv::Mat(2, 2, CV_16UC3, cv::Scalar(1000, 2000, 3000));
  EXPECT_TRUE(photo_srgb8_bgr(photo_from_host("wide.png", wide, PhotoEncoding::Auto)).empty());
}

TEST(ChartDetection, EncodingForTheDetectorRoundsAsTheSrgbCurve) {
  // srgb8_bgr_image's table must give the codes of rounding 255 * linear_to_srgb(v) to the nearest
  // integer (floor(x + 0.5); saturate_cast would round x + 0.5 once more, one code too high for
  // half of all values, as this function did before its table): values on a
  // fine ramp, just below and above every code's rounding bound, out of range and NaN.
  std::vector<float> values;
  for (int i = 0; i <= 200000; ++i) values.push_back(float(i) / 200000.0f);
  for (int k = 1; k <= 255; ++k) {
    const float b = srgb_to_linear((float(k) - 0.5f) / 255.0f);
    values.push_back(std::nextafter(b, 0.0f));
    values.push_back(std::nextafter(b, 1.0f));
  }
  values.insert(values.end(), {-0.5f, 0.0f, 1.0f, 1.5f, std::numeric_limits<float>::quiet_NaN()});
  cv::Mat img(1, int(values.size()), CV_32FC3);
  for (size_t i = 0; i < values.size(); ++i) img.at<cv::Vec3f>(0, int(i)) = cv::Vec3f(values[i], 0.5f, 0.0f);
  const cv::Mat out = srgb8_bgr_image(img);
  int differ = 0;
  for (size_t i = 0; i < values.size(); ++i) {
    const int expected = int(std::floor(255 * linear_to_srgb(values[i]) + 0.5f));
    const int got = out.at<cv::Vec3b>(0, int(i))[2];  // BGR: red last
    if (i <= 200000) differ += got != expected ? 1 : 0;
    // One float step either side of a bound: the two computations may round either way.
    ASSERT_LE(std::abs(got - expected), 1) << values[i];
  }
  EXPECT_LE(differ, 8);  // of the ramp's 200 001 values
  EXPECT_EQ(int(out.at<cv::Vec3b>(0, 0)[1]), int(std::floor(255 * linear_to_srgb(0.5f) + 0.5f)));
}

TEST(ChartDetection, SyntheticChartIsFoundAndMeasured) {
  cv::Mat img = background(640, 480, 1);
  draw_chart(img, kQuad, 0.9);
  std::vector<std::string> log;
  const std::vector<ChartLocation> found = detect_charts(srgb8_bgr_image(img), 1, log);
  ASSERT_EQ(found.size(), 1u);
  const auto truth = corner_patch_centres(kQuad);
  // The detector's box is good to a few pixels: a tenth of the patch pitch (65 px here).
  for (int i = 0; i < 4; ++i) EXPECT_LT(cv::norm(found[0].corners[i] - truth[i]), 6.5) << i;
  // Manual corners measure the same patches.
  float xy[8];
  for (int i = 0; i < 4; ++i) {
    xy[2 * i] = truth[i].x;
    xy[2 * i + 1] = truth[i].y;
  }
  const PatchMeasurement m = measure_chart(img, chart_from_corners(xy));
  const PatchColors &ref = colorchecker_classic_reference();
  for (int k = 0; k < kChartPatches; ++k) {
    ASSERT_TRUE(m.usable[k]) << k;
    std::array<float, 3> r = ref[k];
    for (float &v : r) v = std::max(v, 0.0f);
    const auto expected = cast(r, 0.9);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.rgb[k][c], expected[c], 0.004 + 0.01 * expected[c]) << k;
  }
}

TEST(ChartDetection, LargePhotosAreSearchedReducedAndLocatedAtFullSize) {
  // A 4200 x 2800 photo (searched at 1/3 of its size) with a chart of 60-pixel patches off centre:
  // found, and its corners as precise as in a small photo (the full-size pass around the spot),
  // not the reduced search's 3-pixel steps. The corners of an unrefined 1/3 search would also pass
  // 3 x 6.5 px, so the bound here is the small photo's.
  const std::array<cv::Point2f, 4> quad = {{{2300, 1500}, {2700, 1520}, {2690, 1790}, {2290, 1770}}};
  cv::Mat img = background(4200, 2800, 5);
  draw_chart(img, quad, 0.9);
  std::vector<std::string> log;
  const std::vector<ChartLocation> found = detect_charts(srgb8_bgr_image(img), 1, log);
  ASSERT_EQ(found.size(), 1u);
  const auto truth = corner_patch_centres(quad);
  for (int i = 0; i < 4; ++i) EXPECT_LT(cv::norm(found[0].corners[i] - truth[i]), 6.5) << i;
  for (const std::string &line : log)
    EXPECT_EQ(line.find("not found again at full size"), std::string::npos) << line;
  // The same photo without the chart: nothing found.
  log.clear();
  EXPECT_TRUE(detect_charts(srgb8_bgr_image(background(4200, 2800, 5)), 1, log).empty());
}

TEST(ChartDetection, UpsideDownChartIsTurned) {
  cv::Mat img = background(640, 480, 2);
  const std::array<cv::Point2f, 4> turned = {{kQuad[2], kQuad[3], kQuad[0], kQuad[1]}};
  draw_chart(img, turned, 0.9);
  std::vector<std::string> log;
  const std::vector<ChartLocation> found = detect_charts(srgb8_bgr_image(img), 1, log);
  ASSERT_EQ(found.size(), 1u);
  const auto truth = corner_patch_centres(turned);
  EXPECT_LT(cv::norm(found[0].corners[0] - truth[0]), 6.5);  // dark skin where it really is
}

namespace {
ColorCalibration run(const std::vector<cv::Mat> &photos, const ColorSettings &s,
                     const std::vector<std::array<double, 3>> *lights = nullptr) {
  return calibrate_colors(photos.size(), [&](size_t i) { return photos[i]; }, s, lights);
}
bool log_has(const ColorCalibration &c, const std::string &what) {
  for (const auto &l : c.log)
    if (l.find(what) != std::string::npos) return true;
  return false;
}
} // namespace

TEST(ChartCalibration, NoChartProceedsUncorrectedUnlessRequired) {
  const std::vector<cv::Mat> photos = {background(320, 240, 3), background(320, 240, 4)};
  ColorSettings s;
  const ColorCalibration c = run(photos, s);
  EXPECT_FALSE(c.corrected);
  EXPECT_TRUE(log_has(c, "NOT colour-corrected"));
  float rgb[3] = {0.2f, 0.3f, 0.4f};
  apply_color_calibration(c, 0, rgb);
  EXPECT_FLOAT_EQ(rgb[1], 0.3f);  // untouched
  s.require_chart = true;
  EXPECT_THROW(run(photos, s), InputError);
}

TEST(ChartCalibration, TwoChartsUseTheLargerOneAndSaySo) {
  cv::Mat img = background(800, 600, 5);
  draw_chart(img, {{{40, 60}, {240, 60}, {240, 195}, {40, 195}}}, 0.9);       // small
  draw_chart(img, {{{330, 200}, {770, 210}, {760, 500}, {320, 490}}}, 0.9);  // large
  ColorSettings s;
  const ColorCalibration c = run({img}, s);
  ASSERT_TRUE(c.corrected);
  EXPECT_TRUE(log_has(c, "2 charts found"));
  EXPECT_GT(c.chart.corners[0].x, 300);  // the larger chart
  EXPECT_LT(c.fit.after, 1.0);
}

// Measuring the chart on the chart's part of each photo (the fit's load_region: no float copy of
// the whole photo) gives the very numbers the whole photos give, for a chart inside the frame and
// one cut by its right and bottom edges (patches off the photo unusable either way).
TEST(ChartCalibration, ChartRegionsMeasureAsTheWholePhotos) {
  const std::array<cv::Point2f, 4> cut = {{{300, 250}, {700, 270}, {690, 540}, {290, 520}}};
  for (const auto &quad : {kQuad, cut}) {
    std::vector<cv::Mat> photos;
    for (int p = 0; p < 4; ++p) {
      cv::Mat img = background(640, 480, unsigned(30 + p));
      draw_chart(img, quad, 0.5 + 0.15 * p);
      for (int y = 0; y < img.rows; ++y)  // a pixel-scale texture: a shifted sampling would show
        for (int x = 0; x < img.cols; ++x) img.at<cv::Vec3f>(y, x) *= 1.0f + 0.02f * float((7 * x + 13 * y) % 5);
      photos.push_back(img);
    }
    ColorSettings s;
    s.manual = true;  // the cut chart is given by hand, as a user would
    const auto centres = corner_patch_centres(quad);
    for (int k = 0; k < 4; ++k) s.corners[2 * k] = centres[size_t(k)].x, s.corners[2 * k + 1] = centres[size_t(k)].y;
    std::vector<cv::Rect> asked;
    const RgbLoader whole = [&](size_t i) { return photos[i]; };
    const RgbRegionLoader part = [&](size_t i, const cv::Rect &r) {
      asked.push_back(r);
      return cv::Mat(photos[i](r & cv::Rect(0, 0, photos[i].cols, photos[i].rows))).clone();
    };
    const ColorCalibration a = calibrate_colors(photos.size(), whole, s);
    const ColorCalibration b = calibrate_colors(photos.size(), whole, s, nullptr, {}, {}, part);
    ASSERT_EQ(a.patches.size(), photos.size());
    ASSERT_EQ(b.patches.size(), photos.size());
    ASSERT_EQ(asked.size(), photos.size());
    EXPECT_LT(asked[0].area(), 640 * 480 * 3 / 4);  // a part, not the photo
    int usable = 0;
    for (size_t p = 0; p < photos.size(); ++p)
      for (int k = 0; k < kChartPatches; ++k) {
        EXPECT_EQ(a.patches[p].usable[k], b.patches[p].usable[k]) << p << " " << k;
        for (int c = 0; c < 3; ++c) EXPECT_EQ(a.patches[p].rgb[k][c], b.patches[p].rgb[k][c]) << p << " " << k;
        usable += a.patches[p].usable[k];
      }
    EXPECT_GT(usable, 20);
    if (quad == cut) EXPECT_LT(usable, 4 * kChartPatches);  // the cut chart loses patches
    EXPECT_EQ(a.corrected, b.corrected);
  }
}

TEST(ChartCalibration, ConstantAndVaryingLightIntensity) {
  // Eight photos of a chart facing n under lights L_p spread as in an RTI capture (20 to 70 deg
  // from the chart's normal); the chart's brightness is E_p (n . L_p). With a hand-held flash E_p
  // varies (here by up to 15 %); the chart's normal is then fitted to the lights.
  const double n[3] = {0.0, 0.2, 0.98};
  std::vector<std::array<double, 3>> lights;
  const double e_var[8] = {1.0, 0.9, 1.12, 0.95, 1.05, 0.88, 1.15, 1.0};
  for (int p = 0; p < 8; ++p) {
    const double tilt = (20 + 50 * (p % 4) / 3.0) * CV_PI / 180, az = p * 2 * CV_PI / 8;
    // Light at `tilt` from n: rotate n towards an axis perpendicular to it.
    const double u[3] = {std::cos(az), std::sin(az) * 0.98, -std::sin(az) * 0.2};
    std::array<double, 3> l;
    for (int k = 0; k < 3; ++k) l[k] = std::cos(tilt) * n[k] + std::sin(tilt) * u[k];
    const double len = std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
    for (double &v : l) v /= len;
    lights.push_back(l);
  }
  for (int varying = 0; varying < 2; ++varying) {
    std::vector<cv::Mat> photos;
    std::vector<double> e;
    for (size_t p = 0; p < lights.size(); ++p) {
      const auto &l = lights[p];
      const double cosine = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
      e.push_back(varying ? e_var[p] : 1.0);
      cv::Mat img = background(640, 480, unsigned(10 + p));
      draw_chart(img, kQuad, 0.9 * e.back() * cosine);
      photos.push_back(img);
    }
    ColorSettings s;
    const ColorCalibration c = run(photos, s, &lights);
    ASSERT_TRUE(c.corrected);
    EXPECT_EQ(c.exposure_normalised, bool(varying));
    EXPECT_TRUE(log_has(c, varying ? "varies between photos" : "constant between photos"));
    for (size_t p = 0; p < photos.size(); ++p)
      EXPECT_NEAR(c.divisor[p] / c.divisor[0], e[p] / e[0], 0.05) << "photo " << p << " varying " << varying;
    // A white surface facing the light reads its reflectance after correction, in every photo.
    for (size_t p = 0; p < photos.size(); ++p) {
      const auto white = cast({{0.9f, 0.9f, 0.9f}}, 0.9 * e[p]);
      float rgb[3] = {white[0], white[1], white[2]};
      apply_color_calibration(c, p, rgb);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(rgb[k], 0.9, 0.05) << p;
    }
  }
  // Without light directions a varying brightness is left alone, and the log says why.
  std::vector<cv::Mat> photos;
  for (int p = 0; p < 3; ++p) {
    cv::Mat img = background(640, 480, unsigned(30 + p));
    draw_chart(img, kQuad, 0.5 + 0.2 * p);
    photos.push_back(img);
  }
  const ColorCalibration c = run(photos, ColorSettings{});
  EXPECT_FALSE(c.exposure_normalised);
  EXPECT_TRUE(log_has(c, "without light directions"));
  ColorSettings on;
  on.exposure = ExposureMode::On;
  const ColorCalibration c_on = run(photos, on);
  EXPECT_TRUE(c_on.exposure_normalised);
  EXPECT_NEAR(c_on.divisor[2] / c_on.divisor[0], 0.9 / 0.5, 0.05);
}

TEST(ChartCalibration, SamplesAreCorrectedPerPhoto) {
  ColorCalibration c;
  c.corrected = true;
  c.correction.model = CorrectionModel::Matrix3x3;
  c.correction.matrix[0][0] = 2;  // R doubled
  c.divisor = {1.0, 0.5};
  Sample s[2] = {};
  for (int i = 0; i < 2; ++i) {
    s[i].rgb[0] = 0.1f;
    s[i].rgb[1] = 0.2f;
    s[i].rgb[2] = 0.3f;
    s[i].raster = uint16_t(i);
  }
  apply_color_calibration(c, s, 2);
  EXPECT_FLOAT_EQ(s[0].rgb[0], 0.2f);
  EXPECT_FLOAT_EQ(s[0].rgb[1], 0.2f);
  EXPECT_FLOAT_EQ(s[1].rgb[0], 0.4f);  // photo 1: exposure divisor 0.5
  EXPECT_FLOAT_EQ(s[1].rgb[2], 0.6f);
}

TEST(ChartRealPhotos, ColorCheckerClassicPhotosAreDetectedAndCorrected) {
  VBRDF_REQUIRE_SHARED("real/colorchecker");
  const std::string d = test::shared_dir() + "/real/colorchecker/";
  const char *files[] = {"plantcv/classic.png", "plantcv/nano.jpeg", "mindvision_luimoli/d65_colorchecker.jpg"};
  for (const char *f : files) {
    const cv::Mat lin = linear_rgb_image(cv::imread(d + f, cv::IMREAD_UNCHANGED), true);
    ASSERT_FALSE(lin.empty()) << f;
    const ColorCalibration c = run({lin}, ColorSettings{});
    ASSERT_TRUE(c.corrected) << f;
    EXPECT_EQ(c.fit.patches, 24) << f;
    EXPECT_LT(c.fit.after, c.fit.before / 2) << f;
    EXPECT_LT(c.fit.after, 3.5) << f;
    EXPECT_LT(std::min({c.fit.heldout_matrix, c.fit.heldout_curve_matrix, c.fit.heldout_polynomial}), 4.5) << f;
  }
}

TEST(ChartScenes, SpotColourCastIsRemoved) {
  VBRDF_REQUIRE_SHARED("scenes/spot_dir24");
  const calib::SceneSet sc = calib::load_scene(test::shared_dir(), "spot_dir24");
  std::vector<cv::Mat> photos;
  for (const auto &p : sc.images) photos.push_back(linear_rgb_image(cv::imread(p, cv::IMREAD_UNCHANGED), true));
  PatchColors ref;
  for (int k = 0; k < kChartPatches; ++k) ref[k] = sc.patch_reference[k];
  ColorSettings s;
  s.reference = &ref;
  const ColorCalibration c = run(photos, s, &sc.lights_cam);
  ASSERT_TRUE(c.corrected);
  const std::vector<cv::Point2f> centres = chart_patch_centres(c.chart);
  for (int k = 0; k < kChartPatches; ++k)
    EXPECT_LT(std::hypot(centres[k].x - sc.patch_centres[k][0], centres[k].y - sc.patch_centres[k][1]), 4.0) << k;
  EXPECT_GT(c.fit.before, 3.0);
  EXPECT_LT(c.fit.after, 0.5);
  EXPECT_LT(std::min(c.fit.heldout_matrix, c.fit.heldout_curve_matrix), 0.5);
  EXPECT_FALSE(c.exposure_normalised);  // equal light intensities: one exposure
  // The exposure found is the renderer's: exposure 0.7 times the cast's gain on grey.
  EXPECT_NEAR(c.divisor[0], 0.7 * 1.0184, 0.02);
}
