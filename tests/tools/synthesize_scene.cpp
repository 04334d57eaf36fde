// synthesize_scene: deterministic synthetic captures with KNOWN per-vertex Phong reflectance, as
// complete MeshLab projects (mesh + registered photos + light directions + ground truth).
//
// Scene: a bumpy ground plate with a sphere, a torus and an open box standing on it (one mesh,
// world +y up), spatially varying per-vertex parameters (diffuse-only and glossy regions).
// Photos: K viewpoints (vcg::Shot cameras), N directional lights per viewpoint; or, with
// --light-distance D, N isotropic point lights at D bounding-box half-diagonals from the scene's
// bounding-box centre, in the same directions (L = normalize(P - x), irradiance
// E * (D h / |P - x|)^2 with h the half-diagonal, shadow rays stop at P).
//
// Model, per colour channel c (linear RGB), at a surface point with unit normal N:
//
//   P_c = E * ( k_d * max(N.L, 0) * C_c + k_s * max(R.V, 0)^alpha ) * visible_from_light
//   (--coated-diffuse: the k_d term times t(N.L) t(N.V) / t(1)^2, t the Fresnel transmission into
//   index 1.5; --coated-glossy: the same only where k_s > 0)
//   R   = 2 (N.L) N - L
//
//   L  unit direction from the surface towards the light (directional light, world frame)
//   V  unit vector from the surface point to the camera centre (called E in max(R.E, 0)^alpha
//      by the specification; renamed here so that E is only the irradiance)
//   E  light irradiance (--irradiance, default 1.0, white)
//   C  colour, linear RGB with largest channel 1; albedo = k_d * C
//   visible_from_light = 1 when N.L > 0, the triangle's geometric normal faces the light and a
//      ray from the point towards the light hits no triangle (exact ray cast, BVH); else 0.
//
// Rendering: own CPU z-buffer rasteriser through vcg::Shot::Project (pixel centres at +0.5,
// image row 0 = top, image y = H - VCG y), ss x ss supersampling per pixel (box filter of the
// linear values), perspective-correct barycentric interpolation of position, normal (then
// renormalised), k_d, k_s, alpha and C; black background, no ambient light, no
// interreflections. Optional Gaussian noise (counter-based hash, fixed seed) added in linear
// units; then clip to [0, 1] and store round(255 * sRGB(P)) (8-bit) or round(65535 * P)
// (--linear16). Deterministic: the same options give the same bytes, whatever the thread count.
#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "synth_output.h"
#include "synth_render.h"

using namespace synth;

namespace {

struct Options {
  std::string out;
  std::string size = "small";
  int vertices = 0;  // 0: from --size
  int width = 640, height = 480;
  int views = 1, lights = 16, heldout = 4;
  bool linear16 = false;
  float noise = 0;
  uint64_t seed = 1;
  float irradiance = 1;
  bool coated_diffuse = false, coat_glossy_only = false;
  int ss = 2;
  float azimuth = 30, elevation = 35, fov = 40;
  float offset_x = 0, offset_y = 0;
  float light_elev_min = 15, light_elev_max = 80;
  float light_distance = 0;  // > 0: point lights, in bounding-box half-diagonals from its centre
  int threads = 0;
  bool quiet = false;
};

const char *kUsage =
    "usage: synthesize_scene --out DIR [options]\n"
    "  --size tiny|small|medium|large  vertex budget 2k | 5k | 20k | 100k (default small)\n"
    "  --vertices N           vertex budget (overrides --size)\n"
    "  --width W --height H   photo size in pixels (default 640 480)\n"
    "  --views K              viewpoints around the object (default 1)\n"
    "  --lights N             lights per viewpoint (default 16)\n"
    "  --heldout H            held-out lights per viewpoint, not in project.mlp (default 4)\n"
    "  --linear16             16-bit linear PNGs instead of 8-bit sRGB\n"
    "  --noise SIGMA          Gaussian noise std-dev, linear units (default 0)\n"
    "  --seed S               noise seed (default 1)\n"
    "  --irradiance E         light irradiance (default 1)\n"
    "  --coated-diffuse       diffuse term under a clear coat (index 1.5): times the Fresnel\n"
    "                         transmission in and out, t(N.L) t(N.V) / t(1)^2 (default: Lambert)\n"
    "  --coated-glossy        the same, only where k_s > 0 (a coated and a bare material)\n"
    "  --ss S                 supersampling per axis (default 2)\n"
    "  --azimuth DEG --elevation DEG   first camera (default 30 35); view k adds k*360/K to\n"
    "                         the azimuth and 12 degrees of elevation on odd k\n"
    "  --fov DEG              horizontal field of view (default 40)\n"
    "  --center-offset DX DY  principal point offset in pixels, x right, y up (default 0 0)\n"
    "  --light-elevation MIN MAX   light elevation range above the image plane (default 15 80)\n"
    "  --light-distance D     point lights at D bounding-box half-diagonals from the box centre,\n"
    "                         same directions, irradiance E at the centre (default 0: directional;\n"
    "                         the fit accepts D >= 2, lights at least a half-diagonal off the box)\n"
    "  --threads T            OpenMP threads (default: all)\n"
    "  --quiet\n";

int size_vertices(const std::string &size) {
  if (size == "tiny") return 2000;
  if (size == "small") return 5000;
  if (size == "medium") return 20000;
  if (size == "large") return 100000;
  throw std::runtime_error("unknown --size " + size);
}

Options parse_options(int argc, char **argv) {
  Options o;
  auto need = [&](int &i, int n) {
    if (i + n >= argc) throw std::runtime_error(std::string("missing value for ") + argv[i]);
    return argv + i + 1;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out") o.out = *need(i, 1), i += 1;
    else if (a == "--size") o.size = *need(i, 1), i += 1;
    else if (a == "--vertices") o.vertices = std::atoi(*need(i, 1)), i += 1;
    else if (a == "--width") o.width = std::atoi(*need(i, 1)), i += 1;
    else if (a == "--height") o.height = std::atoi(*need(i, 1)), i += 1;
    else if (a == "--views") o.views = std::atoi(*need(i, 1)), i += 1;
    else if (a == "--lights") o.lights = std::atoi(*need(i, 1)), i += 1;
    else if (a == "--heldout") o.heldout = std::atoi(*need(i, 1)), i += 1;
    else if (a == "--linear16") o.linear16 = true;
    else if (a == "--noise") o.noise = std::atof(*need(i, 1)), i += 1;
    else if (a == "--seed") o.seed = std::strtoull(*need(i, 1), nullptr, 10), i += 1;
    else if (a == "--irradiance") o.irradiance = std::atof(*need(i, 1)), i += 1;
    else if (a == "--ss") o.ss = std::atoi(*need(i, 1)), i += 1;
    else if (a == "--azimuth") o.azimuth = std::atof(*need(i, 1)), i += 1;
    else if (a == "--elevation") o.elevation = std::atof(*need(i, 1)), i += 1;
    else if (a == "--fov") o.fov = std::atof(*need(i, 1)), i += 1;
    else if (a == "--center-offset") {
      char **v = need(i, 2);
      o.offset_x = std::atof(v[0]), o.offset_y = std::atof(v[1]), i += 2;
    } else if (a == "--light-elevation") {
      char **v = need(i, 2);
      o.light_elev_min = std::atof(v[0]), o.light_elev_max = std::atof(v[1]), i += 2;
    } else if (a == "--light-distance") o.light_distance = std::atof(*need(i, 1)), i += 1;
    else if (a == "--threads") o.threads = std::atoi(*need(i, 1)), i += 1;
    else if (a == "--quiet") o.quiet = true;
    else if (a == "--coated-diffuse") o.coated_diffuse = true;
    else if (a == "--coated-glossy") o.coated_diffuse = o.coat_glossy_only = true;
    else if (a == "--help" || a == "-h") { std::cout << kUsage; std::exit(0); }
    else throw std::runtime_error("unknown option " + a);
  }
  if (o.out.empty()) throw std::runtime_error("--out is required");
  if (o.vertices <= 0) o.vertices = size_vertices(o.size);
  if (o.width < 16 || o.height < 16 || o.views < 1 || o.lights < 1 || o.heldout < 0 || o.ss < 1 ||
      o.noise < 0 || o.irradiance <= 0 || o.light_elev_min > o.light_elev_max ||
      !(o.light_distance >= 0 && o.light_distance < 1e6f))
    throw std::runtime_error("invalid option value\n" + std::string(kUsage));
  if (o.light_distance > 0 && o.light_distance <= 1)
    throw std::runtime_error("--light-distance must be above 1 (half-diagonals of the bounding box: "
                             "a light inside its bounding sphere may sit inside the object)");
  return o;
}

// Options that define the content (not --out/--threads/--quiet): recorded in the outputs.
std::string canonical_options(const Options &o) {
  std::ostringstream s;
  s << "--vertices " << o.vertices << " --width " << o.width << " --height " << o.height
    << " --views " << o.views << " --lights " << o.lights << " --heldout " << o.heldout
    << (o.linear16 ? " --linear16" : "") << " --noise " << o.noise << " --seed " << o.seed
    << " --irradiance " << o.irradiance << " --ss " << o.ss << " --azimuth " << o.azimuth
    << " --elevation " << o.elevation << " --fov " << o.fov << " --center-offset " << o.offset_x
    << " " << o.offset_y << " --light-elevation " << o.light_elev_min << " " << o.light_elev_max;
  if (o.light_distance > 0) s << " --light-distance " << o.light_distance;  // absent: directional
  if (o.coated_diffuse) s << (o.coat_glossy_only ? " --coated-glossy" : " --coated-diffuse");  // absent: Lambert
  return s.str();
}

std::string fmt(const char *f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::vector<View> make_views(const Options &o, const Scene &s) {
  std::vector<View> views(o.views);
  const float dist = framing_distance(s.frame_radius, o.width, o.height, o.fov);
  for (int k = 0; k < o.views; ++k) {
    View &v = views[k];
    v.azimuth_deg = o.azimuth + 360.0f * k / o.views;
    v.elevation_deg = o.elevation + (k % 2 ? 12.0f : 0.0f);
    v.spec = look_at(s.target, dist, v.azimuth_deg, v.elevation_deg, o.width, o.height, o.fov,
                     o.offset_x, o.offset_y);
    v.text = format_camera(v.spec);
    v.shot = shot_from_text(v.text);
  }
  return views;
}

// Light `i` of `n` on a spiral over the camera-facing hemisphere: elevation (above the image
// plane) from max down to min, golden-angle azimuth steps.
V3 spiral_direction(float i, int n, float el_min, float el_max, float az0) {
  const float t = n > 1 ? i / float(n - 1) : 0.5f;
  const float el = deg2rad(el_max - (el_max - el_min) * clampf(t, 0, 1));
  const float az = deg2rad(az0 + 137.50776f * i);
  return V3(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
}

// Point lights (--light-distance > 0) around the scene's bounding box; nullptr when directional.
std::unique_ptr<PointLightSetup> point_setup(const Options &o, const Scene &s) {
  if (!(o.light_distance > 0)) return nullptr;
  V3 lo = s.pos.at(0), hi = s.pos.at(0);
  for (const V3 &p : s.pos) {
    lo = V3(std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z));
    hi = V3(std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z));
  }
  std::unique_ptr<PointLightSetup> p(new PointLightSetup);
  p->centre = (lo + hi) * 0.5f;
  p->half_diagonal = 0.5f * length(hi - lo);
  p->distance = o.light_distance * p->half_diagonal;
  return p;
}

// The renderer's light of a photo: irradiance E at the bounding-box centre for a point light.
Light light_of(const Photo &p, const PointLightSetup *point) {
  Light l;
  l.direction = p.dir_world;
  if (p.point && point) {
    l.point = true;
    l.position = p.pos_world;
    l.reference_distance = point->distance;
  }
  return l;
}

Photo make_photo(const View &view, int view_index, V3 d, const std::string &file,
                 const PointLightSetup *point) {
  // Lights from below the plate would leave the scene dark: mirror them in the image plane,
  // which always brings them above the horizon (the camera looks down at the plate).
  if (camera_to_world(view.shot, d).y < 0.1f) d = V3(-d.x, -d.y, d.z);
  Photo p;
  p.file = file;
  p.view = view_index;
  p.dir_text = fmt("%.6f", d.x) + " " + fmt("%.6f", d.y) + " " + fmt("%.6f", d.z);
  // Render with what a reader of the .lp gets back.
  std::istringstream in(p.dir_text);
  in >> p.dir_cam.x >> p.dir_cam.y >> p.dir_cam.z;
  p.dir_cam = normalize(p.dir_cam);
  p.dir_world = camera_to_world(view.shot, p.dir_cam);
  if (point) {  // the .lp direction is the one from the bounding-box centre to the light
    p.point = true;
    p.pos_world = point->centre + p.dir_world * point->distance;
  }
  return p;
}

std::string photo_name(const Options &o, int view, const char *kind, int i) {
  char buf[64];
  if (o.views == 1) std::snprintf(buf, sizeof buf, "images/%s_%03d.png", kind, i);
  else std::snprintf(buf, sizeof buf, "images/view%d_%s_%03d.png", view, kind, i);
  return buf;
}

void make_photos(const Options &o, const std::vector<View> &views, const PointLightSetup *point,
                 std::vector<Photo> &train, std::vector<Photo> &heldout) {
  const float lo = o.light_elev_min, hi = o.light_elev_max;
  for (int k = 0; k < o.views; ++k) {
    const float az0 = 10.0f + 23.0f * k;  // each view gets its own set of lights
    for (int i = 0; i < o.lights; ++i)
      train.push_back(make_photo(views[k], k, spiral_direction(float(i), o.lights, lo, hi, az0),
                                 photo_name(o, k, "light", i), point));
    // Held-out lights: spread over the same elevations, azimuths off the training spiral, so
    // none coincides with a training light.
    for (int j = 0; j < o.heldout; ++j) {
      const float i = (j + 0.5f) * (o.lights - 1) / float(o.heldout);
      heldout.push_back(make_photo(views[k], k, spiral_direction(i, o.lights, lo, hi, az0 + 68.0f),
                                   photo_name(o, k, "heldout", j), point));
    }
  }
}

// Ground-truth pixel of each vertex per view (MeshLab's lookup: QImage pixel
// (int(x), int(H - y)) of Shot::Project), -1 outside the image or behind the camera.
std::vector<std::vector<int>> vertex_pixels(const Scene &s, const std::vector<View> &views) {
  std::vector<std::vector<int>> pix(views.size(), std::vector<int>(s.vertex_count(), -1));
  for (size_t k = 0; k < views.size(); ++k) {
    const Shot &shot = views[k].shot;
    const int W = shot.Intrinsics.ViewportPx[0], H = shot.Intrinsics.ViewportPx[1];
    for (size_t v = 0; v < s.vertex_count(); ++v) {
      const vcg::Point3f p(s.pos[v].x, s.pos[v].y, s.pos[v].z);
      if (!(shot.Depth(p) > 0)) continue;
      const vcg::Point2f q = shot.Project(p);
      const float fx = q[0], fy = H - q[1];
      if (fx < 0 || fy < 0 || fx >= W || fy >= H) continue;
      pix[k][v] = int(fy) * W + int(fx);
    }
  }
  return pix;
}

// Visible from a view: in the image, normal facing the camera, ray to the camera centre free.
std::vector<uint8_t> vertex_visibility(const RenderContext &ctx, const View &view,
                                       const std::vector<int> &pixel) {
  const Scene &s = ctx.scene;
  const V3 eye = shot_centre(view.shot);
  std::vector<uint8_t> vis(s.vertex_count(), 0);
#pragma omp parallel for schedule(dynamic, 256)
  for (long v = 0; v < long(s.vertex_count()); ++v) {
    if (pixel[v] < 0) continue;
    const V3 o = s.pos[v] + s.nrm[v] * ctx.ray_eps, d = eye - o;
    const float dist = length(d);
    if (dot(s.nrm[v], d) <= 0) continue;
    vis[v] = !ctx.bvh.occluded(o, d * (1.0f / dist), dist);
  }
  return vis;
}

// Per vertex: '0' N.L <= 0, 's' the ray towards the light (a point light: up to it) is blocked,
// '1' lit. Rays start ray_eps along the vertex normal.
std::vector<char> vertex_lit(const RenderContext &ctx, const Light &light) {
  const Scene &s = ctx.scene;
  std::vector<char> lit(s.vertex_count(), '0');
#pragma omp parallel for schedule(dynamic, 256)
  for (long v = 0; v < long(s.vertex_count()); ++v) {
    const LightAt in = light_at(light, s.pos[v]);
    if (in.falloff == 0 || dot(s.nrm[v], in.L) <= 0) continue;
    const V3 o = s.pos[v] + s.nrm[v] * ctx.ray_eps;
    bool blocked;
    if (!light.point) {
      blocked = ctx.bvh.occluded(o, in.L, INFINITY);
    } else {
      const V3 d = light.position - o;
      const float len = length(d);
      blocked = ctx.bvh.occluded(o, d * (1.0f / len), len);
    }
    lit[v] = blocked ? 's' : '1';
  }
  return lit;
}

struct Stats {
  PhotoStats pixels;                 // training photos
  uint64_t visible_samples = 0;      // (vertex visible in the photo's view, training photo)
  uint64_t lit_samples = 0;
  uint64_t saturated_samples = 0;    // ... whose pixel has a channel at the maximum code
  uint64_t black_lit_samples = 0;    // ... lit but stored as 0 in every channel
};

// Counts, for the visible vertices, what the pixel at their projection holds.
void sample_stats(const cv::Mat &img, const std::vector<int> &pixel, const std::vector<uint8_t> &vis,
                  const std::vector<char> &lit, Stats &st) {
  const bool wide = img.depth() == CV_16U;
  const int maxcode = wide ? 65535 : 255;
  for (size_t v = 0; v < vis.size(); ++v) {
    if (!vis[v]) continue;
    const int x = pixel[v] % img.cols, y = pixel[v] / img.cols;
    int hi = 0;
    for (int c = 0; c < 3; ++c)
      hi = std::max(hi, wide ? int(img.at<cv::Vec3w>(y, x)[c]) : int(img.at<cv::Vec3b>(y, x)[c]));
    st.visible_samples++;
    st.lit_samples += lit[v] == '1';
    st.saturated_samples += hi == maxcode;
    st.black_lit_samples += lit[v] == '1' && hi == 0;
  }
}

void write_png(const std::string &path, const cv::Mat &img) {
  if (!cv::imwrite(path, img, {cv::IMWRITE_PNG_COMPRESSION, 9}))
    throw std::runtime_error("cannot write " + path);
}

std::string fraction(uint64_t a, uint64_t b) { return fmt("%.4f", b ? double(a) / b : 0.0); }

std::string expected_text(const Options &o, const Scene &s, const VertexTruth &gt,
                          const Stats &st, size_t photos, size_t heldout,
                          const PointLightSetup *point) {
  size_t visible = 0, diffuse = 0, glossy_visible = 0, boundary = 0;
  for (size_t v = 0; v < s.vertex_count(); ++v) {
    visible += gt.visible_any[v];
    diffuse += s.ks[v] == 0;
    glossy_visible += gt.visible_any[v] && s.ks[v] > 0;
    boundary += s.boundary[v];
  }
  std::ostringstream e;
  e << "# Figures of this synthetic project computed by synthesize_scene (key: value).\n"
    << "# Samples = (vertex visible from the photo's camera, training photo) pairs; the pixel\n"
    << "# of a vertex is MeshLab's lookup (int(x), int(H - y)) of Shot::Project.\n"
    << "generator_options: " << canonical_options(o) << "\n"
    << "vertices: " << s.vertex_count() << "\n"
    << "faces: " << s.triangle_count() << "\n"
    << "views: " << o.views << "\n"
    << "lights_per_view: " << o.lights << "\n"
    << "photos: " << photos << "\n"
    << "heldout_photos: " << heldout << "\n"
    << "image_size: " << o.width << "x" << o.height << "\n"
    << "encoding: " << (o.linear16 ? "linear16" : "srgb8") << "\n"
    << "noise_sigma: " << o.noise << "\n"
    << "irradiance: " << o.irradiance << "\n";
  if (point)
    e << "light_model: point\n"
      << "light_distance_half_diagonals: " << o.light_distance << "\n"
      << "light_distance: " << fmt("%.6g", point->distance) << "\n"
      << "bounding_box_centre: " << fmt("%.6g", point->centre.x) << " " << fmt("%.6g", point->centre.y)
      << " " << fmt("%.6g", point->centre.z) << "\n";
  e << "visible_vertices: " << visible << "\n"
    << "visible_vertex_fraction: " << fraction(visible, s.vertex_count()) << "\n";
  for (size_t k = 0; k < gt.visible.size(); ++k) {
    size_t n = 0;
    for (uint8_t b : gt.visible[k]) n += b;
    e << "visible_vertex_fraction_view" << k << ": " << fraction(n, s.vertex_count()) << "\n";
  }
  e << "diffuse_only_vertex_fraction: " << fraction(diffuse, s.vertex_count()) << "\n"
    << "glossy_visible_vertices: " << glossy_visible << "\n"
    << "material_boundary_vertex_fraction: " << fraction(boundary, s.vertex_count()) << "\n"
    << "samples: " << st.visible_samples << "\n"
    << "lit_sample_fraction: " << fraction(st.lit_samples, st.visible_samples) << "\n"
    << "saturated_sample_fraction: " << fraction(st.saturated_samples, st.visible_samples) << "\n"
    << "# lit samples whose pixel is 0 in every channel: silhouette vertices read background\n"
    << "lit_black_sample_fraction: " << fraction(st.black_lit_samples, st.lit_samples) << "\n"
    << "saturated_pixel_fraction: "
    << fraction(st.pixels.saturated_pixels, st.pixels.covered_pixels) << "\n";
  return e.str();
}

std::string gt_readme(const Options &o, float ray_eps, const std::vector<View> &views,
                      const PointLightSetup *point) {
  std::ostringstream r;
  r << "# Ground truth of a synthetic capture (synthesize_scene)\n\n"
    << "Generated by `tests/tools/synthesize_scene` with `" << canonical_options(o) << "`.\n"
    << "Deterministic: the same options give the same bytes.\n\n"
    << "## Reflectance model (exactly what was rendered)\n\n"
    << "Per colour channel c (linear RGB), at a surface point with unit normal N:\n\n"
    << "    P_c = E * ( kd * max(N.L, 0) * C_c + ks * max(R.V, 0)^shininess ) * visible_from_light\n"
    << "    R   = 2 (N.L) N - L\n\n"
    << (point ? "* `L` = normalize(P - x): unit direction from the surface point x towards the point\n"
                "  light at P (`lights.json` / `lights_world.json`: `position_world`). `lights.lp` gives\n"
                "  the direction from the bounding-box centre to P, camera frame of the photo's view.\n"
              : "* `L`: unit direction from the surface towards the light (directional light; `lights.lp`\n"
                "  gives it in the camera frame of the photo's view, `lights_world.json` in the world frame).\n")
    << "* `V`: unit vector from the surface point to the camera centre (minus `TranslationVector`);\n"
    << "  the project specification writes it `E` (`max(R.E, 0)^alpha`): the same vector.\n"
    << (point ? "* `E` = " + fmt("%g", o.irradiance) + " * (d / |P - x|)^2: irradiance of an isotropic point light, white,\n"
                "  d = " + fmt("%.6g", point->distance) + " = " + fmt("%g", o.light_distance) +
                " bounding-box half-diagonals: every light's distance from the bounding-box\n  centre ("
                + fmt("%.6g", point->centre.x) + " " + fmt("%.6g", point->centre.y) + " " +
                fmt("%.6g", point->centre.z) + "), where E = " + fmt("%g", o.irradiance) + ".\n"
              : "* `E` = " + fmt("%g", o.irradiance) + ": light irradiance, white (same for every photo).\n")
    << "* `C`: colour, linear RGB, largest channel exactly 1; `albedo = kd * C`. The specular lobe is white.\n"
    << "* `visible_from_light` = 1 when N.L > 0, the triangle's geometric normal faces the light and\n"
    << "  an exact ray cast from the point towards the light hits no triangle"
    << (point ? " before the light" : "") << "; otherwise 0.\n"
    << "* Parameter ranges: kd in [0.05, 0.9], ks in [0, 0.8], shininess in [2, 200]. Where ks = 0\n"
    << "  (diffuse-only regions) shininess is stored as 2 and has no effect.\n"
    << "* No ambient light, no interreflections, black background.\n\n"
    << "## Image formation\n\n"
    << "* Own CPU rasteriser (z-buffer) through the `.mlp` shots (`vcg::Shot<float>::Project` of the\n"
    << "  values as written in the file), " << o.ss << "x" << o.ss << " samples per pixel at\n"
    << "  sub-pixel centres, averaged in linear radiance (box filter) before clipping.\n"
    << "* Position, normal (renormalised), kd, ks, shininess and C are interpolated per sample with\n"
    << "  perspective-correct barycentrics of the triangle's vertex values.\n"
    << "* Stored value: " << (o.linear16 ? "`round(65535 * clip(P + noise, 0, 1))`, 16-bit linear PNG"
                                         : "`round(255 * srgb_oetf(clip(P + noise, 0, 1)))`, 8-bit sRGB PNG")
    << "; noise: Gaussian, sigma = " << o.noise << " (linear units), per pixel and channel.\n"
    << "  Highlights may saturate (see `expected.txt`).\n\n"
    << "## Conventions\n\n"
    << "* World: right-handed, +y up. Plate ~[-1, 1] x [-1, 1] around y = 0.\n"
    << "* Camera frame (lights.lp): x right, y up in the image, z towards the viewer.\n"
    << "* `.mlp` `<VCGCamera>`: `TranslationVector` = minus the camera centre; `RotationMatrix` rows =\n"
    << "  camera right, up, back axes in world; `FocalMm = f_px * PixelSizeMm`; `CenterPx` in VCG\n"
    << "  pixels (origin bottom-left, y up); no lens distortion.\n"
    << "* Image pixels: origin top-left, y down, pixel centres at integer + 0.5; image y = H - VCG y.\n"
    << "  MeshLab reads the vertex colour from QImage pixel `(int(x), int(H - y))` of `Shot::Project`.\n"
    << "* Light elevation is measured above the image plane (z_cam = sin(elevation)); lights are on a\n"
    << "  spiral between " << o.light_elev_min << " and " << o.light_elev_max << " degrees; a light that\n"
    << "  would come from below the world horizon is mirrored in the image plane (x, y -> -x, -y).\n\n"
    << "## Views\n\n| view | azimuth | elevation | camera centre |\n|---|---|---|---|\n";
  for (size_t k = 0; k < views.size(); ++k) {
    const V3 c = shot_centre(views[k].shot);
    r << "| " << k << " | " << views[k].azimuth_deg << " | " << views[k].elevation_deg << " | "
      << fmt("%.4f", c.x) << " " << fmt("%.4f", c.y) << " " << fmt("%.4f", c.z) << " |\n";
  }
  r << "\n## Files\n\n"
    << "| file | content |\n|---|---|\n"
    << "| `gt_vertex.ply` | binary PLY: mesh + uchar `red green blue` (sRGB of the albedo, for "
       "viewing) + float `kd ks shininess color_r color_g color_b albedo_r albedo_g albedo_b "
       "visible_any region material_boundary` |\n"
    << "| `gt_vertex.csv` | the same per vertex (mesh.ply order) + `visible_view<k>` per view |\n"
    << "| `gt_lit.txt` | per vertex, one character per training photo: `1` lit, `s` cast shadow, `0` N.L <= 0 |\n"
    << "| `gt_lit_heldout.txt` | the same for the held-out photos (`heldout/lights.lp` order) |\n\n"
    << "* `visible_any` / `visible_view<k>`: the vertex projects inside the image of view k, its normal\n"
    << "  faces the camera and a ray from it (offset " << fmt("%.1e", ray_eps)
    << " along the normal) to the\n  camera centre hits no triangle. Lit flags at vertices use the "
       "vertex normal (same offset).\n"
    << "* `material_boundary` = 1: a mesh neighbour has another region; the photos blend parameters\n"
    << "  across such edges (barycentric interpolation), so expect larger fit errors there.\n"
    << "* Regions (id: name): ";
  for (int i = 0; i < kRegionCount; ++i) r << (i ? ", " : "") << i << ": " << region_name(i);
  r << ".\n  Diffuse-only (ks = 0): plate_matte, torus_matte, box_side. Glossy: the others (the sphere's\n"
    << "  ks varies with latitude 0.1..0.8 and its shininess with longitude 2..200).\n\n"
    << "## Figures\n\n`../expected.txt` (key: value): vertex / photo counts, visible fraction,\n"
    << "lit and saturated sample fractions of this capture.\n";
  return r.str();
}

std::string root_readme(const Options &o, size_t photos, const PointLightSetup *point) {
  std::ostringstream r;
  r << "# Synthetic capture (synthesize_scene)\n\n"
    << "Procedural object (bumpy plate, sphere, torus, open box; " << "one mesh) with known per-vertex\n"
    << "Phong reflectance, " << photos << " photos (" << o.views << " view(s) x " << o.lights
    << (point ? " point lights), " : " directional lights), ") << o.width << "x" << o.height << ", "
    << (o.linear16 ? "16-bit linear PNG" : "8-bit sRGB PNG") << ". Public domain (generated).\n\n"
    << "* `project.mlp`: MeshLab 2020.09 project (`mesh.ply` + one raster per photo).\n"
    << "* `mesh.ply`: binary PLY, positions + area-weighted vertex normals, nothing else.\n"
    << "* `images/`, `lights.lp` (N, then `images/x.png lx ly lz`, camera frame of the photo's view),\n"
    << "  `lights_world.json`" << (point ? "; `lights.json`: the light positions (world frame, mesh\n"
                                         "  units) in the form the fit reads (`vbrdf_fit --lp lights.json`).\n"
                                       : ".\n")
    << "* `heldout/`: extra photos under lights that are NOT in `project.mlp` (own `project.mlp`,\n"
    << "  `lights.lp`, `lights_world.json`" << (point ? ", `lights.json`" : "")
    << "; paths relative to `heldout/`).\n"
    << "* `ground_truth/`: model, conventions and per-vertex truth (`README.md`).\n"
    << "* `expected.txt`: figures of this capture (key: value).\n\n"
    << "Regenerate: `synthesize_scene " << canonical_options(o) << " --out <dir>`.\n";
  return r.str();
}

} // namespace

int main(int argc, char **argv) {
  try {
    const auto t0 = std::chrono::steady_clock::now();
    const Options o = parse_options(argc, argv);
    if (o.threads > 0) omp_set_num_threads(o.threads);
    const std::string out = o.out;

    const Scene s = make_scene(o.vertices);
    const RenderContext ctx(s);
    const std::vector<View> views = make_views(o, s);
    const std::unique_ptr<PointLightSetup> point = point_setup(o, s);
    std::vector<Photo> train, held;
    make_photos(o, views, point.get(), train, held);

    // Ground truth first: the sample statistics read the rendered pixels of visible vertices.
    VertexTruth gt;
    const std::vector<std::vector<int>> pixel = vertex_pixels(s, views);
    gt.visible_any.assign(s.vertex_count(), 0);
    for (size_t k = 0; k < views.size(); ++k) {
      gt.visible.push_back(vertex_visibility(ctx, views[k], pixel[k]));
      for (size_t v = 0; v < s.vertex_count(); ++v) gt.visible_any[v] |= gt.visible[k][v];
    }
    for (const Photo &p : train) gt.lit.push_back(vertex_lit(ctx, light_of(p, point.get())));
    for (const Photo &p : held) gt.lit_heldout.push_back(vertex_lit(ctx, light_of(p, point.get())));

    make_dirs(out + "/images");
    make_dirs(out + "/ground_truth");
    if (!held.empty()) make_dirs(out + "/heldout/images");
    ShadeSettings set;
    set.irradiance = o.irradiance;
    set.linear16 = o.linear16;
    set.noise_sigma = o.noise;
    set.seed = o.seed;
    set.coated_diffuse = o.coated_diffuse;
    set.coat_glossy_only = o.coat_glossy_only;
    // Photos of one view share its raster; each photo is shaded, checked and written by one
    // thread (PNG compression is the slow serial part otherwise).
    std::vector<Stats> photo_stats(train.size());
    for (size_t k = 0; k < views.size(); ++k) {
      const ViewRaster raster = rasterize(ctx, views[k].shot, o.ss);
      std::vector<const Photo *> todo;
      for (const Photo &p : train) if (p.view == int(k)) todo.push_back(&p);
      for (const Photo &p : held) if (p.view == int(k)) todo.push_back(&p);
#pragma omp parallel for schedule(dynamic, 1)
      for (long n = 0; n < long(todo.size()); ++n) {
        const Photo &p = *todo[n];
        const bool is_train = &p >= train.data() && &p < train.data() + train.size();
        const size_t i = is_train ? size_t(&p - train.data()) : size_t(&p - held.data());
        PhotoStats px;
        const cv::Mat img = render_photo(ctx, raster, views[k].shot, light_of(p, point.get()), set,
                                         is_train ? i : 100000 + i, px);
        if (is_train) {
          photo_stats[i].pixels = px;
          sample_stats(img, pixel[k], gt.visible[k], gt.lit[i], photo_stats[i]);
        }
        write_png(out + (is_train ? "/" : "/heldout/") + p.file, img);
      }
    }
    Stats st;
    for (const Stats &p : photo_stats) {
      st.pixels.covered_pixels += p.pixels.covered_pixels;
      st.pixels.saturated_pixels += p.pixels.saturated_pixels;
      st.visible_samples += p.visible_samples;
      st.lit_samples += p.lit_samples;
      st.saturated_samples += p.saturated_samples;
      st.black_lit_samples += p.black_lit_samples;
    }

    write_mesh_ply(out + "/mesh.ply", s);
    write_mlp(out + "/project.mlp", "mesh.ply", train, views);
    write_lp(out + "/lights.lp", train);
    write_lights_json(out + "/lights_world.json", train, o.irradiance, point.get());
    if (point) write_positions_json(out + "/lights.json", train);
    if (!held.empty()) {
      write_mlp(out + "/heldout/project.mlp", "../mesh.ply", held, views);
      write_lp(out + "/heldout/lights.lp", held);
      write_lights_json(out + "/heldout/lights_world.json", held, o.irradiance, point.get());
      if (point) write_positions_json(out + "/heldout/lights.json", held);
    }
    write_gt_ply(out + "/ground_truth/gt_vertex.ply", s, gt);
    write_gt_csv(out + "/ground_truth/gt_vertex.csv", s, gt);
    write_lit_table(out + "/ground_truth/gt_lit.txt", train, gt.lit, s.vertex_count());
    write_lit_table(out + "/ground_truth/gt_lit_heldout.txt", held, gt.lit_heldout, s.vertex_count());
    const std::string expected = expected_text(o, s, gt, st, train.size(), held.size(), point.get());
    write_text(out + "/expected.txt", expected);
    write_text(out + "/ground_truth/README.md", gt_readme(o, ctx.ray_eps, views, point.get()));
    write_text(out + "/README.md", root_readme(o, train.size(), point.get()));

    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!o.quiet)
      std::cout << "synthesize_scene: " << out << ": " << s.vertex_count() << " vertices, "
                << train.size() << " photos + " << held.size() << " held out, "
                << fmt("%.1f", secs) << " s\n"
                << expected;
    return 0;
  } catch (const std::exception &e) {
    std::cerr << "synthesize_scene: " << e.what() << "\n";
    return 1;
  }
}
