// vbrdf-lights: light directions from photos of one or two mirror spheres, as an RTI .lp, without
// a MeshLab project (the installed counterpart of the filter "Vertex BRDF: estimate light
// directions from a reflective sphere"). Run with --help for the usage; docs/parameters.md#vbrdf-lights-command-line.
//
// The work is the core's (calibration/sphere_lights.h): detection or a given circle, checked
// against the photos (check_sphere_circle), highlights and their mirror reflection, photos whose
// sphere shows several highlights (highlight_blobs, moving_highlight_counts). This file only parses, reports and writes.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "base/errors.h"
#include "calibration/sphere_lights.h"
#include "inputs/light_file.h"
#include "inputs/project.h"

using namespace vbrdf;

namespace {

const char *const kUsage =
    "usage: vbrdf-lights --out LIGHTS.lp [options] PHOTO...\n"
    "\n"
    "Writes the direction towards the light of every photo (RTI .lp: image name, then x y z in the\n"
    "camera frame: x right, y up, z towards the camera) from the highlight on a mirror sphere.\n"
    "\n"
    "  --out FILE            the .lp to write (replaced atomically)\n"
    "  --spheres N           spheres to find automatically: 1 (default) or 2\n"
    "  --circle X Y R        the sphere's outline instead of finding it (repeat for a second sphere);\n"
    "                        needs --origin. Pixels: x from the left edge of the photo; R its radius.\n"
    "  --origin top-left     y counts down from the top edge (an image viewer, OpenCV, GIMP)\n"
    "  --origin bottom-left  y counts up from the bottom edge (e.g. the Harvard photometric-stereo\n"
    "                        sets' circle_data.txt); converted with y_top = height - y_bottom\n"
    "  --project P.mlp       take the camera (focal length, principal point) from the project's first\n"
    "                        raster; without it the view is orthographic (a distant camera)\n"
    "  --sphere-radius-world R  two spheres: their radius in world units, for the light positions\n"
    "  --keep-flagged        keep photos whose sphere shows several highlights (left out by default:\n"
    "                        a room-lit reference photo or a second lamp gives no single direction)\n"
    "\n"
    "A given circle is checked against the photos (outline and highlights inside, as for a detected\n"
    "sphere): when it does not fit, nothing is written and the exit status is 1. Exit status 0: the\n"
    "file was written; 1: bad input or no photo got a light; 2: bad usage.\n";

[[noreturn]] void usage(const std::string &why) {
  std::fprintf(stderr, "vbrdf-lights: %s\n\n%s", why.c_str(), kUsage);
  std::exit(2);
}

double number(const std::string &s) {
  char *end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end == nullptr || *end != '\0') usage("not a number: '" + s + "'");
  return v;
}

struct Args {
  std::vector<std::string> photos;
  std::string out, project, origin;
  std::vector<SphereCircle> circles;
  int spheres = 1;
  double sphere_radius_world = 0;
  bool keep_flagged = false;
};

Args parse(int argc, char **argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    const auto value = [&](int n) {
      if (i + n >= argc) usage("missing value after " + k);
    };
    if (k == "--help" || k == "-h") {
      std::printf("%s", kUsage);
      std::exit(0);
    } else if (k == "--out") {
      value(1), a.out = argv[++i];
    } else if (k == "--project") {
      value(1), a.project = argv[++i];
    } else if (k == "--origin") {
      value(1), a.origin = argv[++i];
      if (a.origin != "top-left" && a.origin != "bottom-left") usage("--origin is top-left or bottom-left");
    } else if (k == "--circle") {
      value(3);
      const double x = number(argv[i + 1]), y = number(argv[i + 2]), r = number(argv[i + 3]);
      i += 3;
      if (!(r > 0)) usage("--circle: the radius must be positive");
      a.circles.push_back(SphereCircle{x, y, r});
    } else if (k == "--spheres") {
      value(1), a.spheres = int(number(argv[++i]));
      if (a.spheres < 1 || a.spheres > 2) usage("--spheres is 1 or 2");
    } else if (k == "--sphere-radius-world") {
      value(1), a.sphere_radius_world = number(argv[++i]);
    } else if (k == "--keep-flagged") {
      a.keep_flagged = true;
    } else if (!k.empty() && k[0] == '-') {
      usage("unknown option " + k);
    } else {
      a.photos.push_back(k);
    }
  }
  if (a.out.empty()) usage("--out is needed");
  if (a.photos.empty()) usage("no photos given");
  if (!a.circles.empty() && a.origin.empty())
    usage("--circle needs --origin top-left or --origin bottom-left: say where y = 0 is (a circle in the other "
          "convention gives wrong lights)");
  if (a.circles.size() > 2) usage("at most two --circle");
  return a;
}

std::string base_name(const std::string &p) {
  const size_t s = p.find_last_of('/');
  return s == std::string::npos ? p : p.substr(s + 1);
}

cv::Mat read_gray(const std::string &path) {
  const cv::Mat m = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (m.empty()) throw InputError("Cannot read photo '" + path + "' (missing, or not an image OpenCV reads).");
  return gray_image(m);
}

int run(const Args &a) {
  const size_t n = a.photos.size();
  const GrayLoader load = [&a](size_t i) { return read_gray(a.photos[i]); };
  SphereCamera camera;
  if (!a.project.empty()) {
    const Project p = read_project(a.project);
    if (p.rasters.empty()) throw InputError("Project '" + a.project + "' has no raster to take the camera from.");
    camera = camera_from_shot(p.rasters[0].shot);
  }
  std::printf("camera: %s\n", camera.perspective ? ("perspective, from " + a.project).c_str()
                                                 : "orthographic (no --project)");

  LightSettings settings;
  settings.search.max_spheres = a.spheres;
  settings.sphere_radius_world = a.sphere_radius_world;
  if (!a.circles.empty()) {
    const cv::Mat first = load(0);
    for (SphereCircle c : a.circles) {
      if (a.origin == "bottom-left") c.y = double(first.rows) - c.y;
      std::printf("given circle: centre (%.1f, %.1f) from the top-left corner (x right, y down), radius %.1f px\n",
                  c.x, c.y, c.r);
      const CircleCheck check = check_sphere_circle(n, load, camera, c, settings.search);
      std::printf("check: %s\n", check.description.c_str());
      if (!check.plausible)
        throw InputError("The given circle (" + std::to_string(c.x) + ", " + std::to_string(c.y) + ", r " +
                         std::to_string(c.r) + " px from the top-left corner) is not a sphere in these photos: " +
                         check.description + ". Check --origin (top-left: y down from the top edge; bottom-left: y "
                         "up from the bottom edge) and that the circle belongs to these photos, or leave --circle out "
                         "to find the sphere automatically. Nothing was written.");
      settings.manual_spheres.push_back(c);
    }
  }

  std::vector<std::string> names;
  for (const std::string &p : a.photos) names.push_back(base_name(p));
  const LightCalibration cal = calibrate_lights(n, load, camera, settings, names);
  for (const std::string &line : cal.log) std::printf("%s\n", line.c_str());

  // Highlights that move with the light, per photo (the most over the spheres).
  std::vector<int> highlights(n, 0);
  for (const DetectedSphere &sphere : cal.spheres) {
    std::vector<std::vector<HighlightBlob>> blobs(n);
    for (size_t i = 0; i < n; ++i) blobs[i] = highlight_blobs(load(i), sphere.model.circle);
    const std::vector<int> moving = moving_highlight_counts(blobs, sphere.model.circle.r);
    for (size_t i = 0; i < n; ++i) highlights[i] = std::max(highlights[i], moving[i]);
  }
  std::vector<LightEntry> entries;
  size_t flagged = 0, left_out = 0;
  for (size_t i = 0; i < n; ++i) {
    const PhotoLight &p = cal.photos[i];
    const bool several = highlights[i] > 1;
    flagged += several;
    if (several)
      std::printf("FLAGGED %s: the sphere shows %d separate highlights (a room-lit reference photo, a second lamp "
                  "or a window?): %s\n",
                  names[i].c_str(), highlights[i],
                  a.keep_flagged ? "kept (--keep-flagged)" : "left out of the .lp (--keep-flagged keeps it)");
    if (!p.valid) {
      std::printf("no light: %s%s\n", names[i].c_str(), p.warning.empty() ? "" : (": " + p.warning).c_str());
      ++left_out;
      continue;
    }
    if (several && !a.keep_flagged) {
      ++left_out;
      continue;
    }
    LightEntry e;
    e.image = names[i];
    for (int k = 0; k < 3; ++k) e.dir_cam[k] = float(p.dir[k]);
    entries.push_back(e);
    std::printf("%s %.6f %.6f %.6f", names[i].c_str(), p.dir[0], p.dir[1], p.dir[2]);
    if (cal.spheres.size() > 1) std::printf("  (spheres disagree by %.2f deg)", p.disagreement_deg);
    std::printf("\n");
  }
  if (entries.empty()) throw InputError("No photo got a light: nothing was written.");
  write_light_file(a.out, entries);
  std::printf("Wrote %s: %zu of %zu photos (%zu left out, %zu flagged for several highlights).\n", a.out.c_str(),
              entries.size(), n, left_out, flagged);
  return 0;
}

} // namespace

int main(int argc, char **argv) {
  const Args a = parse(argc, argv);
  try {
    return run(a);
  } catch (const InputError &e) {
    std::fprintf(stderr, "vbrdf-lights: %s\n", e.what());
  } catch (const std::exception &e) {
    std::fprintf(stderr, "vbrdf-lights: failed: %s\n", e.what());
  }
  return 1;
}
