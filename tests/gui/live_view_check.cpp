// The acceptance check of the live view in MeshLab: a screenshot of MeshLab's 3-D view
// drawn by the render plugin "Vertex BRDF: relight" against the relight renderer's image of the
// same view and light (OSMesa), from the fit's result PLY and the view the plugin logged
// (live_view_file.h).
//
//   vbrdf_live_view_check <result.ply> <view.txt> <view.png> <diff.png> [<x,y,w,h>]
//   vbrdf_live_view_check --fallback <meshlab_view.png> <view.png> [<x,y,w,h> [<diff.png>]]
//     (no model: MeshLab's rendering; the rectangle, the panel over the view, is not compared)
//
// The logged GL matrices become a vcg::Shot (the trackball's uniform scale divided out: a
// perspective image does not change when the world and the camera distance scale together), the
// eye-space light a world direction (the modelview's rotation transposed). Compared: pixels that
// the relight renderer draws lit with all 8 neighbours lit (no silhouettes, no cast shadows: the
// live view has none) outside the rectangle x,y,w,h (view pixels, row 0 = top: the plugin's
// panel floating over the view), the reference clipped at 1, times the logged exposure, sRGB-encoded to
// 8 bits. Passes when at least kMinPixels are compared, kMinWithin of them are within kLevels
// 8-bit levels on every channel (MeshLab may draw overlays), and the median difference is at
// most 1 level. Exit status 0 pass, 1 fail, 2 bad input.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "osmesa_context.h"
#include "io/result_ply.h"
#include "relight/live_view_file.h"
#include "relight/relight_render.h"
#include "thesis_settings.h"

namespace {

constexpr int kLevels = 3;
constexpr double kMinWithin = 0.98;
constexpr size_t kMinPixels = 2000;

float srgb8(float c) {
  c = std::min(std::max(c, 0.0f), 1.0f);
  c = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return std::round(c * 255.0f);
}

// Camera of the logged GL view. Row r of the modelview's 3x3 is s times the camera's axis r.
vbrdf::Shot shot_of(const vbrdf::LiveViewRecord &r, std::array<float, 3> &light_world) {
  const double *mv = r.view.modelview, *p = r.view.projection;
  double rows[3][3], scale = 0;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) rows[i][k] = mv[k * 4 + i];
  for (int k = 0; k < 3; ++k) scale += rows[0][k] * rows[0][k];
  scale = std::sqrt(scale);
  vcg::Matrix44f rot;
  rot.SetIdentity();
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) rot[i][k] = float(rows[i][k] / scale);
  // Eye coordinates x_e = s R x + t: the camera centre is -R^T t / s.
  vcg::Point3f centre;
  for (int k = 0; k < 3; ++k) {
    double c = 0;
    for (int i = 0; i < 3; ++i) c -= rows[i][k] / scale * mv[12 + i] / scale;
    centre[k] = float(c);
  }
  double l[3] = {0, 0, 0}, len = 0;
  for (int k = 0; k < 3; ++k) {
    for (int i = 0; i < 3; ++i) l[k] += rows[i][k] / scale * r.view.light_eye[i];
    len += l[k] * l[k];
  }
  for (int k = 0; k < 3; ++k) light_world[size_t(k)] = float(l[k] / std::sqrt(len));
  const int w = r.viewport[2], h = r.viewport[3];
  const double fx = p[0] * w / 2, fy = p[5] * h / 2;
  vbrdf::Shot shot;
  shot.Intrinsics.cameraType = 0;
  shot.Intrinsics.FocalMm = float(fx * 0.01);
  shot.Intrinsics.PixelSizeMm = vcg::Point2f(0.01f, float(fx * 0.01 / fy));
  shot.Intrinsics.ViewportPx = vcg::Point2i(w, h);
  shot.Intrinsics.CenterPx = vcg::Point2f(float((1 - p[8]) * w / 2), float((1 - p[9]) * h / 2));
  shot.Intrinsics.k[0] = shot.Intrinsics.k[1] = 0;
  shot.Extrinsics.SetRot(rot);
  shot.Extrinsics.SetTra(centre);
  return shot;
}

// --fallback: without a model the plugin must draw what MeshLab draws. Passes when the two
// screenshots agree: at least 99 % of the pixels within kLevels on every channel.
// Pixels inside `skip` (the plugin's panel floating over the view) are not compared.
int run_fallback(const char *before_path, const char *after_path, const cv::Rect &skip, const char *diff_path) {
  const cv::Mat before = cv::imread(before_path, cv::IMREAD_COLOR), after = cv::imread(after_path, cv::IMREAD_COLOR);
  if (before.empty() || after.empty() || before.size() != after.size()) {
    std::fprintf(stderr, "cannot read %s and %s as images of one size\n", before_path, after_path);
    return 2;
  }
  size_t within = 0, compared = 0;
  cv::Mat diff(before.size(), CV_8UC3, cv::Scalar(0, 0, 0));
  for (int y = 0; y < before.rows; ++y)
    for (int x = 0; x < before.cols; ++x) {
      if (skip.contains(cv::Point(x, y))) continue;
      const cv::Vec3b a = before.at<cv::Vec3b>(y, x), b = after.at<cv::Vec3b>(y, x);
      int d = 0;
      for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a[c]) - int(b[c])));
      within += d <= kLevels;
      ++compared;
      if (d > kLevels) diff.at<cv::Vec3b>(y, x) = cv::Vec3b(0, 0, 255);
    }
  if (diff_path) cv::imwrite(diff_path, diff);
  const double fraction = compared ? double(within) / double(compared) : 0.0;
  std::printf("fallback check: %.2f %% of %zu pixels (outside the panel) within %d levels of MeshLab's own rendering\n%s\n",
              100.0 * fraction, compared, kLevels, fraction >= 0.99 ? "PASS" : "FAIL");
  return fraction >= 0.99 ? 0 : 1;
}

int run(int argc, char **argv) {
  if (argc >= 4 && std::string(argv[1]) == "--fallback") {
    cv::Rect skip;
    if (argc >= 5 && std::sscanf(argv[4], "%d,%d,%d,%d", &skip.x, &skip.y, &skip.width, &skip.height) != 4) return 2;
    return run_fallback(argv[2], argv[3], skip, argc >= 6 ? argv[5] : nullptr);
  }
  cv::Rect skip;
  if (argc < 5 || (argc > 5 && std::sscanf(argv[5], "%d,%d,%d,%d", &skip.x, &skip.y, &skip.width, &skip.height) != 4)) {
    std::fprintf(stderr, "usage: vbrdf_live_view_check <result.ply> <view.txt> <view.png> <diff.png> [<x,y,w,h>]\n");
    return 2;
  }
  const vbrdf::ResultPly result = vbrdf::read_result_ply(argv[1]);
  vbrdf::RelightRenderSettings settings = vbrdf::test::thesis_render_settings();
  const std::vector<vbrdf::VertexFit> fits = vbrdf::fits_from_result(result, argv[1], &settings.lobe, &settings.diffuse);
  const vbrdf::LiveViewRecord record = vbrdf::read_live_view(argv[2]);
  if (record.view.display != vbrdf::LiveDisplay::Full || std::fabs(record.view.projection[11]) < 1e-12) {
    std::fprintf(stderr, "%s: the check needs the full model in a perspective view\n", argv[2]);
    return 2;
  }
  const cv::Mat shot_image = cv::imread(argv[3], cv::IMREAD_COLOR);  // BGR, row 0 = top
  if (shot_image.empty()) {
    std::fprintf(stderr, "cannot read %s\n", argv[3]);
    return 2;
  }
  std::array<float, 3> light{};
  const vbrdf::Shot shot = shot_of(record, light);
  // The GL viewport's origin is the view's bottom-left corner; the screenshot's row 0 its top.
  const int w = record.viewport[2], h = record.viewport[3], x0 = record.viewport[0];
  const int y_top = shot_image.rows - (record.viewport[1] + h);
  if (x0 < 0 || y_top < 0 || x0 + w > shot_image.cols || y_top + h > shot_image.rows) {
    std::fprintf(stderr, "the viewport %dx%d+%d+%d is not inside the %dx%d screenshot\n", w, h, x0, record.viewport[1],
                 shot_image.cols, shot_image.rows);
    return 2;
  }
  vbrdf::test::OsMesaContext context;
  vbrdf::RelightRenderer renderer(result.mesh.view(), fits, context.get_proc_address(), settings);
  const vbrdf::RelitImage ref = renderer.render(shot, vbrdf::LightSource::directional(light));
  auto lit = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < w && y < h && ref.pixel_class[size_t(y) * size_t(w) + size_t(x)] == vbrdf::kRelitLit;
  };
  std::vector<int> worst;
  cv::Mat diff(h, w, CV_8UC3, cv::Scalar(0, 0, 0));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool interior = true;
      for (int dy = -1; dy <= 1 && interior; ++dy)
        for (int dx = -1; dx <= 1; ++dx) interior = interior && lit(x + dx, y + dy);
      if (!interior || skip.contains(cv::Point(x, y))) continue;
      const cv::Vec3b got = shot_image.at<cv::Vec3b>(y_top + y, x0 + x);
      int d = 0;
      for (int c = 0; c < 3; ++c) {
        const float expected = srgb8(record.view.exposure * ref.rgb[3 * (size_t(y) * size_t(w) + size_t(x)) + size_t(c)]);
        d = std::max(d, int(std::fabs(float(got[2 - c]) - expected)));
      }
      worst.push_back(d);
      diff.at<cv::Vec3b>(y, x) = cv::Vec3b(0, uchar(std::min(255, d * 40)), uchar(d > kLevels ? 255 : 0));
    }
  cv::imwrite(argv[4], diff);
  const size_t n = worst.size();
  const size_t within = size_t(std::count_if(worst.begin(), worst.end(), [](int d) { return d <= kLevels; }));
  std::vector<int> sorted = worst;
  std::sort(sorted.begin(), sorted.end());
  const int median = n ? sorted[n / 2] : 999, largest = n ? sorted.back() : 999;
  const double fraction = n ? double(within) / double(n) : 0.0;
  std::printf("live view check: %zu lit interior pixels compared (%s), %.2f %% within %d levels, median %d, "
              "largest %d levels; light (world) %.3f %.3f %.3f; renderer %s\n",
              n, argv[3], 100.0 * fraction, kLevels, median, largest, light[0], light[1], light[2], context.renderer().c_str());
  const bool pass = n >= kMinPixels && fraction >= kMinWithin && median <= 1;
  std::printf("%s\n", pass ? "PASS" : "FAIL");
  return pass ? 0 : 1;
}

} // namespace

int main(int argc, char **argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "vbrdf_live_view_check: %s\n", e.what());
    return 2;
  }
}
