#pragma once
// Light directions from reflective (mirror) spheres photographed in every photo of a viewpoint
// (thesis 4.1, with the errata of THESIS_NOTES.md).
//
// Conventions:
//  - Image pixels: top-left origin, x right, y down, pixel centres at integer + 0.5 (as camera.h).
//  - Camera frame: x right, y up, z towards the viewer (the RTI .lp convention). Every direction
//    returned here is a unit vector in this frame pointing TOWARDS the light.
//  - Grey images: CV_32FC1, 0 = black, 1 = the format's full scale (see gray_image()).
//
// Geometry: with a perspective camera the sphere's outline is the cone of rays tangent to it; its
// axis is the ray through the sphere's centre. Light directions do not depend on the sphere's
// distance, so the sphere is placed at distance 1 on its axis (radius sin(half_angle)). The light
// is the mirror reflection of the true camera ray through the highlight:
// L = 2 (N.V) N - V, V = unit vector from the surface point to the camera. Without a camera (the
// real sets of ../shared/real) the orthographic model is used: V = (0, 0, 1) for every pixel and
// N = ((x - cx) / r, -(y - cy) / r, sqrt(1 - nx^2 - ny^2)).
//
// Triangulated (near) light positions: with perspective they are in the camera frame in units of
// the physical sphere radius (all spheres are assumed to have the same radius), multiplied by
// LightSettings::sphere_radius_world when it is set (then they are in world units, since a
// MeshLab shot is rigid); orthographic positions are in pixels.
#include <array>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "inputs/camera.h"
#include "inputs/light_file.h"

namespace vbrdf {

// How image pixels become camera rays.
struct SphereCamera {
  bool perspective = false;  // false: orthographic, every ray is (0, 0, -1)
  double fx = 0, fy = 0;     // focal length in pixels
  double px = 0, py = 0;     // principal point in image pixels (top-left origin, y down)
};

// Perspective camera of a MeshLab shot (FocalMm / PixelSizeMm, CenterPx flipped to y down).
// Lens distortion is ignored (MeshLab reads only k1 and expects undistorted photos).
SphereCamera camera_from_shot(const Shot &shot);

// Unit ray from the camera through image point (x, y), camera frame. Orthographic: (0, 0, -1).
void pixel_ray(const SphereCamera &cam, double x, double y, double ray[3]);

// Image point of a camera-frame direction (perspective; needs dir[2] < 0). Returns false when the
// direction does not point in front of the camera.
bool project_direction(const SphereCamera &cam, const double dir[3], double &x, double &y);

// A sphere's outline as the user sees it: centre and (mean) radius in image pixels.
struct SphereCircle {
  double x = 0, y = 0, r = 0;
};

// A sphere located in a viewpoint.
struct SphereModel {
  SphereCircle circle;           // outline: centre of the projected contour (an ellipse) and the
                                 // geometric mean of its semi-axes
  double axis[3] = {0, 0, -1};   // perspective: unit ray to the sphere's centre
  double half_angle = 0;         // perspective: angle between the axis and a tangent ray (rad)
  double centre_x = 0, centre_y = 0;  // image of the sphere's centre (== circle centre if orthographic)
};

// Sphere whose outline best matches `circle` (perspective: cone fitted to the rays through points
// of the circle, so an ellipse-like outline measured as a circle is handled). Returns a model with
// circle.r == 0 when the circle is not in front of a perspective camera.
SphereModel sphere_from_circle(const SphereCamera &cam, const SphereCircle &circle);

// Sphere from the image of its centre and (perspective) its angular radius in radians; for an
// orthographic camera `radius` is the radius in pixels.
SphereModel sphere_from_centre(const SphereCamera &cam, double centre_x, double centre_y, double radius);

// `n` points of the sphere's projected outline (image pixels), evenly spaced in angle.
std::vector<cv::Point2d> sphere_outline(const SphereCamera &cam, const SphereModel &sphere, int n);

// Light direction from a highlight at image point (hx, hy). Returns false (light untouched) when
// the camera ray through the point misses the sphere. `normal` (optional) receives the sphere's
// normal at the highlight, `point` (optional) the surface point (camera frame; perspective: in
// units of the distance to the sphere's centre, orthographic: pixels with the centre at z = 0).
bool highlight_to_light(const SphereCamera &cam, const SphereModel &sphere, double hx, double hy, double light[3],
                        double normal[3] = nullptr, double point[3] = nullptr);

// Inverse: image point where the sphere mirrors a distant light in direction `light` (unit,
// towards the light). Returns false when that point is not visible.
bool light_to_highlight(const SphereCamera &cam, const SphereModel &sphere, const double light[3], double &hx,
                        double &hy);

// Angle in degrees between two directions (need not be normalised).
double angle_deg(const double a[3], const double b[3]);

// Grey image for sphere work: mean of the colour channels as CV_32FC1 in [0, 1], linear in light
// when `decode_srgb` (8-bit photos are sRGB-encoded, as photo.h assumes; 16-bit / 65535 and
// float are taken as linear). Accepts 1, 3 or 4 channels (alpha ignored). Empty in, empty out.
cv::Mat gray_image(const cv::Mat &image, bool decode_srgb = true);

struct HighlightSettings {
  double rim_margin = 0.06;    // outer fraction of the radius not searched (grazing reflections)
  double start_level = 0.98;   // first threshold (fraction of full scale): near white
  double level_step = 0.02;    // threshold decrement, as a fraction of the peak
  double min_area_px = 6;      // descend until the highlight blob has at least this area
  double min_area_fraction = 2e-4;  // ... or this fraction of the sphere's area if larger
  double min_peak = 0.2;       // brightest smoothed value below this: no highlight (shadow)
  double min_contrast = 0.12;  // peak minus the sphere's median below this: no highlight
};

struct Highlight {
  bool found = false;
  double x = 0, y = 0;     // intensity-weighted centroid of the blob (image pixels)
  double peak = 0;         // brightest smoothed value in the search disc
  double background = 0;   // median of the search disc
  double threshold = 0;    // final blob threshold
  int area = 0;            // blob area in pixels at that threshold
  bool saturated = false;  // the blob contains clipped pixels (>= kClippedLinearValue of full scale)
  std::string problem;     // why no highlight was found (empty when found)
};

// Highlight of a light on a sphere: not the brightest pixel but the centroid of the blob around
// the brightest (smoothed) point, thresholded from near white downwards until it reaches the
// minimum area, weighted by intensity above the threshold (robust to saturation). Searched
// inside the circle shrunk by rim_margin; the part of the circle outside the image is ignored.
Highlight find_highlight(const cv::Mat &gray, const SphereCircle &circle, const HighlightSettings &settings = {});

enum class SphereMethod { Manual = 0, Hough = 1, HighlightTrack = 2 };
const char *sphere_method_name(SphereMethod m);

struct DetectedSphere {
  SphereModel model;
  SphereMethod method = SphereMethod::Manual;
  double edge_score = 0;      // outline contrast (mean radial gradient / median gradient)
  int highlights_inside = 0;  // photos whose brightest blob lies inside this sphere
  std::string description;    // one log line: where, how found, support
};

struct SphereSearch {
  int max_spheres = 1;         // spheres to return (the best-supported first)
  double min_radius_px = 8;
  double max_radius_px = 0;    // 0: half of the smaller image side
  double min_edge_score = 0.8; // without a highlight track: weakest outline accepted
  int max_median_photos = 31;  // photos used for the median image (evenly spaced)
  int detect_size = 512;       // larger photos are searched at this size, then refined in full
};

// Loads photo `index` as a linear grey image (see gray_image()). Detection calls it once per photo
// (twice for photos larger than SphereSearch::detect_size); the highlights need one more pass.
using GrayLoader = std::function<cv::Mat(size_t index)>;

// Finds up to search.max_spheres spheres in the photos of one viewpoint. Candidates: HoughCircles
// on the median and on the max image of all photos (power-stretched so that a dark sphere's faint
// glow shows), HoughCircles in the neighbourhood of the highlight track, and the outermost
// circular edge around the track (a black or mirror sphere in a dark room barely shows an
// outline, but the brightest spots of all photos stay inside it). A candidate is kept when it
// holds a bright spot in at least 70 % of the photos that have one (or, with no spots at all,
// when its outline scores min_edge_score), when its outline is round all around, and when it is
// fully inside the image; it is refined to the strongest outline (centre) and to the half-way
// crossing of the linear intensities (radius). Appends what it did to `log`, including candidates
// rejected because the image border cuts them. Returns an empty vector when nothing is found.
std::vector<DetectedSphere> detect_spheres(size_t photo_count, const GrayLoader &load, const SphereCamera &cam,
                                           const SphereSearch &search, std::vector<std::string> &log);

// Whether a given outline (a user's circle) is a sphere in these photos, by the rules detection
// applies to its candidates: the outline shows on at least half its length, and the circle holds a
// bright spot in 70 % of the photos that have one (or, with fewer than 3 such photos, the outline
// scores search.min_edge_score), and the strongest outline near it (within 15 % of the radius)
// lies within max(3 px, 3 % of the radius) of it. A circle in another pixel convention (y from the
// bottom) or of another photo fails.
struct CircleCheck {
  bool plausible = false;
  double outline_coverage = 0;  // fraction of the outline where an edge shows
  double outline_score = 0;     // outline contrast (as DetectedSphere::edge_score)
  size_t photos_with_spot = 0;  // photos holding a bright spot anywhere
  size_t spots_inside = 0;      // ... inside the circle
  SphereCircle refined;         // the strongest outline near the circle
  double offset_px = 0;         // how far it is from the given circle (centre or radius)
  std::string description;      // one line for the user: the figures and the verdict
};
CircleCheck check_sphere_circle(size_t photo_count, const GrayLoader &load, const SphereCamera &cam,
                                const SphereCircle &circle, const SphereSearch &search = {});

// Bright blobs on a sphere in one photo: inside `circle` (shrunk by the rim margin), above half-way
// between the sphere's median and its brightest point, each at least 0.8 times as bright as the
// brightest and at least 5 % of the largest one's area (fragments of one highlight are not blobs).
struct HighlightBlob {
  double x = 0, y = 0;  // centroid (image pixels)
  int area = 0;         // pixels
  double peak = 0;      // brightest smoothed value
};
std::vector<HighlightBlob> highlight_blobs(const cv::Mat &gray, const SphereCircle &circle,
                                           const HighlightSettings &settings = {});

// Per photo, how many of its blobs move with the light: blobs found at the same place (within 10 %
// of `radius`) in at least half of the photos (and 3) are reflections of something that stays
// lit whatever the light (a lamp, a window, the camera) and do not count. One light: 1; a photo
// with a second lamp on or lit by the room: 2 or more; no highlight: 0.
std::vector<int> moving_highlight_counts(const std::vector<std::vector<HighlightBlob>> &blobs, double radius);

// Refines a sphere in a linear grey image within +-max_shift pixels: the centre to the strongest
// outline of the square-root image (its edge shift is the same all around, so it does not move
// the centre), then the radius to where the intensity crosses half-way between inside and
// outside (exact for an anti-aliased edge under any symmetric blur). `score` (optional) receives
// minus the relative crossing mismatch (0 is perfect).
SphereModel refine_sphere(const cv::Mat &gray, const SphereCamera &cam, const SphereModel &start, double max_shift,
                          double *score = nullptr);

struct LightSettings {
  std::vector<SphereCircle> manual_spheres;  // non-empty: use these outlines, no detection
  SphereSearch search;
  HighlightSettings highlight;
  double sphere_radius_world = 0;  // > 0: triangulated positions scaled to world units
  double min_triangulation_deg = 1.0;  // spheres agreeing better than this: distant light, no position
  bool decode_srgb = true;          // photos given as cv::Mat: 8-bit ones are sRGB-encoded
};

struct SphereLight {
  bool valid = false;
  double dir[3] = {0, 0, 0};
  Highlight highlight;
};

struct PhotoLight {
  bool valid = false;               // at least one sphere gave a light
  double dir[3] = {0, 0, 0};        // unit, camera frame: normalised mean over the spheres
  std::vector<SphereLight> spheres; // one per sphere, in LightCalibration::spheres order
  double disagreement_deg = 0;      // largest angle between two spheres' directions
  bool has_position = false;        // triangulated near light (two or more spheres that disagree)
  double position[3] = {0, 0, 0};   // camera frame (units: see the header comment)
  double position_rms = 0;          // RMS distance of the reflected rays from the position
  std::string warning;              // per-photo problem, empty when all spheres gave a light
};

struct LightCalibration {
  std::vector<DetectedSphere> spheres;
  std::vector<PhotoLight> photos;
  std::vector<std::string> log;  // what was done and found, one line per item, for the user
  size_t valid_count() const;
};

// Full light calibration of one viewpoint: spheres from settings.manual_spheres or
// detect_spheres(), then per photo and sphere the highlight and its light direction, the
// disagreement between spheres, and the triangulated light position with two or more spheres.
// `names[i]` names photo i in messages (may be empty). A photo without any highlight gets
// valid == false and a warning; it does not stop the others. Throws InputError when no sphere
// is found (the message says to set centre and radius) or when a manual circle is empty.
LightCalibration calibrate_lights(size_t photo_count, const GrayLoader &load, const SphereCamera &cam,
                                  const LightSettings &settings, const std::vector<std::string> &names = {});

// Convenience for photos already in memory (any type accepted by gray_image()).
LightCalibration calibrate_lights(const std::vector<cv::Mat> &photos, const SphereCamera &cam,
                                  const LightSettings &settings, const std::vector<std::string> &names = {});

// .lp entries for the photos that got a light (file names as given), in photo order.
std::vector<LightEntry> light_entries(const LightCalibration &calibration, const std::vector<std::string> &image_names);

// Least-squares point closest to rays origin[i] + t dir[i], t > 0 (dir need not be normalised).
// Returns false for fewer than two rays, (nearly) parallel rays, or a point behind a ray's
// origin. `rms` receives the RMS distance of the rays from the point.
bool closest_point_to_rays(const std::vector<std::array<double, 3>> &origins,
                           const std::vector<std::array<double, 3>> &dirs, double point[3], double *rms = nullptr);

} // namespace vbrdf
