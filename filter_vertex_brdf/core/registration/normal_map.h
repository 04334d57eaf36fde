#pragma once
// The light-normalised image of one viewpoint: per pixel, the surface normal that photometric stereo
// reads from the photos of that viewpoint (they differ only in light). It changes neither with the
// light nor with the albedo, so it is what the mesh's own normals can be registered against
// (registration.h). Lambertian model, robust per pixel: attached shadows, cast shadows, highlights
// and clipped pixels are left out by the model's own residuals.
#include <array>
#include <vector>

#include <opencv2/core.hpp>

namespace vbrdf {

struct NormalMap {
  cv::Rect roi;     // the part of the photos it covers (image pixels, top-left origin)
  cv::Mat normals;  // CV_32FC3 over roi: unit normal in the lights' (world) frame; (0, 0, 0) where
                    // the photos show nothing lit (background: scaled albedo below background_level)
  cv::Mat weight;   // CV_32F over roi: 1 where the normal is determined, 0 where not (too few lit
                    // samples, lights of those samples all in one plane, or no finite value)
  size_t determined = 0, background = 0;  // pixels with weight 1, of which background
};

struct NormalMapSettings {
  // Samples darker than this fraction of the pixel's brightest unclipped sample start out as
  // shadowed (left out); the residual test then decides.
  float shadow_floor = 0.03f;
  // The brightest fraction of each pixel's samples starts out as possible highlight (left out).
  float highlight_fraction = 0.1f;
  int min_samples = 4;   // lit samples a determined pixel needs
  // Smallest eigenvalue of the used lights' mean outer product L L^T (1/3 for lights spread over
  // the sphere, 0 for lights in one plane): below it the normal is not determined.
  float min_light_spread = 0.02f;
  // A pixel whose scaled albedo |b| is below this fraction of the median over determined pixels is
  // background (normal 0, determined): silhouettes then register too.
  float background_level = 0.05f;
  int iterations = 3;  // reweighting rounds after the first solve, at most (it stops when the kept samples repeat)
};

// Photometric stereo over `luminance` (one CV_32F image per photo, all the size of `roi`, linear
// luminance; NaN marks a clipped or missing value) lit from `lights` (unit vectors towards the
// light, one per photo, in the frame the normals should be given in). Per pixel: least squares
// I_k = L_k . b on the samples kept, then samples whose residual exceeds 3 robust sigmas or whose
// predicted shading is below 5 % of |b| (attached shadow) are dropped and b solved again.
// OpenMP-parallel over rows. Throws std::invalid_argument when the sizes disagree.
NormalMap photometric_normal_map(const std::vector<cv::Mat> &luminance, const std::vector<std::array<float, 3>> &lights,
                                 const cv::Rect &roi, const NormalMapSettings &settings = NormalMapSettings());

} // namespace vbrdf
