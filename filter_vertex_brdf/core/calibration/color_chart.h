#pragma once
// Colour correction from a 24-patch ColorChecker photographed in every photo of a viewpoint
// (thesis 4.2): chart detection (OpenCV contrib mcc, or four corners given by the user), patch
// colours in linear space, a colour correction fitted to the chart's reference values
// (cv::ccm::ColorCorrectionModel 3x3 matrix, the same after a tone curve fitted on the neutral
// patches, or the thesis's per-channel polynomial, whichever has the lowest CIEDE2000 on
// held-out patches), and per-photo exposure normalisation from the
// neutral patches when the light intensity varies between photos.
//
// Conventions: colours are linear RGB with sRGB primaries (the photos' space once decoded, see
// photo.h), in [0, 1] of the format's full scale; reference values are linear sRGB reflectances
// (D65). Patches are numbered 0..23 row-major as the chart is read: row 0 dark skin .. bluish
// green, row 3 white .. black (18..23 are the neutrals).
//
// A correction maps a photo's linear RGB to reflectance-like linear sRGB:
//   corrected = M(rgb / divisor[photo])
// where M is the fitted model and divisor[photo] the photo's exposure (see ColorCalibration).
#include <array>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include <cstddef>

namespace vbrdf {

constexpr int kChartPatches = 24;
constexpr int kFirstNeutralPatch = 18;
using PatchColors = std::array<std::array<float, 3>, kChartPatches>;
using PatchFlags = std::array<bool, kChartPatches>;

// ColorChecker Classic reference: the ColorChecker 2005 Lab (D50) table of OpenCV's ccm module
// (COLORCHECKER_Macbeth), converted by OpenCV to linear sRGB (D65). Cyan's red is slightly
// negative (outside the sRGB gamut).
const PatchColors &colorchecker_classic_reference();

// Where a chart is in a photo: image pixels (top-left origin, y down, pixel centres at +0.5) of
// the centres of its four corner patches, in the order dark skin (0), bluish green (5),
// black (23), white (18).
struct ChartLocation {
  std::array<cv::Point2f, 4> corners;
  bool detected = false;  // found by the mcc detector (false: given by the user)
  double cost = 0;        // the detector's fit cost (lower is better)
};

// Centres of the 24 patches (perspective interpolation of the corner patches), in patch order.
std::vector<cv::Point2f> chart_patch_centres(const ChartLocation &chart);

// Location from user input: x, y of the corner patches' centres in the order above.
ChartLocation chart_from_corners(const float xy[8]);

// ColorChecker Classic charts found by cv::mcc::CCheckerDetector in an 8-bit BGR photo (as from
// cv::imread; other depths/orders: see srgb8_bgr_image()), best first, at most `max_charts`.
// Each chart's orientation is checked on its neutral row. Appends one log line per chart.
// Photos longer than 2048 pixels are searched at 1/k of their size (k the smallest integer that
// brings them to 2048) and each chart found is located again at full size around that spot.
std::vector<ChartLocation> detect_charts(const cv::Mat &bgr8, int max_charts, std::vector<std::string> &log);

// 8-bit sRGB-encoded BGR image (what the detector wants) from a linear RGB float image.
cv::Mat srgb8_bgr_image(const cv::Mat &linear_rgb);

// Linear RGB float image (CV_32FC3, RGB order) from a photo: 8-bit is sRGB-decoded (unless
// decode_srgb is false), 16-bit / 65535 and float are taken as linear; `bgr` says the channel
// order of `image` (true for cv::imread). Alpha is dropped, grey is replicated.
cv::Mat linear_rgb_image(const cv::Mat &image, bool bgr, bool decode_srgb = true);

struct PatchMeasurement {
  PatchColors rgb{};          // linear RGB: trimmed mean of the patch's central area
  std::array<float, kChartPatches> clipped{};  // fraction of clipped samples (a channel >= kClippedLinearValue)
  PatchFlags usable{};        // inside the photo, not clipped, above the noise floor
};

// Measures the patches of `chart` in a linear RGB float photo (CV_32FC3, RGB order): the central
// 60 % of each patch's pitch, 10 % of samples trimmed at either end of the luminance range.
PatchMeasurement measure_chart(const cv::Mat &linear_rgb, const ChartLocation &chart);

enum class CorrectionModel { None = 0, Matrix3x3 = 1, ChannelPolynomial = 2, ToneCurveMatrix = 3 };
const char *correction_model_name(CorrectionModel m);

// A fitted colour correction of linear RGB.
struct ColorCorrection {
  CorrectionModel model = CorrectionModel::None;
  double matrix[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // out_c = sum_k matrix[c][k] in_k
  double poly[3][4] = {};  // ChannelPolynomial: out_c = sum_d poly[c][d] in_c^d (d = 0..3)
  // ToneCurveMatrix: each channel first goes through ln v' = curve[0] + curve[1] ln v +
  // curve[2] ln^2 v (fitted on the neutral patches; straight in log-log outside [lo, hi]), then
  // the matrix: a camera tone curve that is not the sRGB one (JPEG picture styles) is undone.
  double curve[3] = {0, 1, 0};
  double curve_lo = 0, curve_hi = 1;
  void apply(const float in[3], float out[3]) const;
};

struct CorrectionFit {
  ColorCorrection best;       // the model with the lowest held-out CIEDE2000
  ColorCorrection matrix;     // cv::ccm::ColorCorrectionModel, 3x3, CIEDE2000 loss
  ColorCorrection polynomial; // thesis: cubic per channel, least squares
  ColorCorrection curve_matrix;  // neutral tone curve, then cv::ccm 3x3 (like ccm's GRAYLOGPOLYFIT)
  double heldout_matrix = 0, heldout_polynomial = 0, heldout_curve_matrix = 0;  // mean dE2000, leave-one-patch-out
  double before = 0, before_max = 0;  // mean / max dE2000 of the measured patches (exposure-matched)
  double after = 0, after_max = 0;    // mean / max dE2000 of the corrected patches (best model)
  int patches = 0;                    // patches used
};

// Fits the three models to `measured` -> `reference` on the usable patches (at least 8, including
// three neutrals) and keeps the one with the lowest leave-one-patch-out mean CIEDE2000. The
// measured colours should be exposure-matched (the neutral patches' luminance equal to the
// reference's): see normalise_to_reference(). Throws ProcessingError when too few patches.
CorrectionFit fit_color_correction(const PatchColors &measured, const PatchColors &reference, const PatchFlags &usable);

// Scale making the luminance of the usable neutral patches match the reference (median of the
// ratios). Returns 0 when no neutral patch is usable.
double neutral_scale(const PatchColors &measured, const PatchColors &reference, const PatchFlags &usable);

enum class ExposureMode { Auto = 0, Off = 1, On = 2 };

struct ColorSettings {
  bool require_chart = false;       // no chart found: throw instead of proceeding uncorrected
  bool manual = false;              // use `corners` instead of the detector
  float corners[8] = {};            // see chart_from_corners()
  ExposureMode exposure = ExposureMode::Auto;
  const PatchColors *reference = nullptr;  // null: colorchecker_classic_reference()
  int detect_photos = 5;            // photos tried by the detector (evenly spaced)
  double constant_light_tolerance = 0.05;  // Auto: relative residual below which the intensity is constant
};

struct ColorCalibration {
  bool corrected = false;           // false: no chart, samples stay as they are
  ColorCorrection correction;
  CorrectionFit fit;
  ChartLocation chart;
  // Per photo: the camera value of a perfect white facing the light (camera gain x light
  // intensity at the chart); corrected = M(rgb / divisor). The same for all photos unless
  // exposure_normalised.
  std::vector<double> divisor;
  bool exposure_normalised = false; // divisors differ per photo (varying light intensity)
  std::vector<PatchMeasurement> patches;  // per photo
  std::vector<std::string> log;     // for the user: what was found and done
};

// Loads photo `index` as linear RGB float (see linear_rgb_image()).
using RgbLoader = std::function<cv::Mat(size_t index)>;
// Loads the part of photo `index` inside `region` (x, y >= 0) as linear RGB float: the region's
// intersection with the photo, its top-left pixel at (region.x, region.y); empty when unreadable.
using RgbRegionLoader = std::function<cv::Mat(size_t index, const cv::Rect &region)>;

// Colour calibration of one viewpoint. `lights` (optional, one per photo, camera frame, zero
// vector = unknown) lets Auto tell a varying light intensity from the chart's changing angle to
// the light: the chart's brightness b = E (n . L) is fitted for the chart normal n; when it fits
// (relative residual below constant_light_tolerance) the intensity is constant and one divisor
// serves all photos, otherwise each photo is normalised by E = b / (n . L). Without lights, Auto
// does not normalise (On normalises by the neutral patches alone). No chart: returns
// corrected == false with a log line, or throws InputError when settings.require_chart.
// `detector_image` (optional): photo `index` as the 8-bit sRGB BGR image the detector searches,
// where the caller has it cheaper than from `load` (inputs/photo.h photo_srgb8_bgr); an empty
// image (or no function) means srgb8_bgr_image(load(index)). `load_region` (optional): the
// chart's patches are then measured on the chart's part of each photo only (the same numbers,
// without a float copy of every whole photo: 144 MB at 12 MP).
ColorCalibration calibrate_colors(size_t photo_count, const RgbLoader &load, const ColorSettings &settings,
                                  const std::vector<std::array<double, 3>> *lights = nullptr,
                                  const std::vector<std::string> &names = {}, const RgbLoader &detector_image = {},
                                  const RgbRegionLoader &load_region = {});

// Corrects one linear RGB triple of photo `photo` in place (no-op when !corrected).
void apply_color_calibration(const ColorCalibration &cal, size_t photo, float rgb[3]);
// Corrected copy of a linear RGB float photo.
cv::Mat apply_color_calibration(const ColorCalibration &cal, size_t photo, const cv::Mat &linear_rgb);

} // namespace vbrdf
