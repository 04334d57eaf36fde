// vbrdf_calibrate: calibration from the photos of one viewpoint, from the command line.
//
//   vbrdf_calibrate lights --images IMG... [--project P.mlp] [--centre X Y --radius R]...
//                          [--spheres N] [--sphere-radius-world R] [--out lights.lp]
//   vbrdf_calibrate chart  --images IMG... [--corners X1 Y1 X2 Y2 X3 Y3 X4 Y4] [--lights L.lp]
//                          [--require] [--exposure auto|on|off] [--out correction.yml]
//   vbrdf_calibrate report [--shared DIR] [--check]
//
// `lights` writes an RTI .lp (camera frame) and prints the log; without --project the view is
// taken as orthographic (no intrinsics), with it the first raster's shot gives the camera and,
// when --images is not given, the photos. `chart` fits the colour correction and prints the
// patch CIEDE2000 before and after. `report` prints the accuracy figures of RESULTS.md;
// `--check` makes it fail when a target is missed. Its data folder is --shared, else the shared
// test data (VBRDF_SHARED_DIR, tests/support/test_paths.h); when a set it needs is absent it
// exits 77 (ctest's skip code) saying which.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>
#include <unistd.h>

#include <opencv2/core.hpp>

#include "calib_data.h"
#include "calib_chart.h"
#include "base/errors.h"
#include "inputs/light_file.h"
#include "inputs/project.h"
#include "calibration/sphere_lights.h"
#include "test_paths.h"

using namespace vbrdf;

namespace {

struct Args {
  std::vector<std::string> images;
  std::string project, out, lights, shared = test::shared_dir(), exposure = "auto";
  std::vector<SphereCircle> spheres;
  std::vector<float> corners;
  int sphere_count = 1;
  double sphere_radius_world = 0;
  bool require = false, check = false;
};

[[noreturn]] void usage(const char *why) {
  std::fprintf(stderr, "vbrdf_calibrate: %s\n", why);
  std::fprintf(stderr,
               "usage: vbrdf_calibrate lights --images IMG... [--project P.mlp] [--centre X Y --radius R]...\n"
               "                              [--spheres N] [--sphere-radius-world R] [--out lights.lp]\n"
               "       vbrdf_calibrate chart  --images IMG... [--corners X1 Y1 X2 Y2 X3 Y3 X4 Y4]\n"
               "                              [--lights L.lp] [--require] [--exposure auto|on|off] [--out C.yml]\n"
               "       vbrdf_calibrate report [--shared DIR] [--check]\n");
  std::exit(2);
}

double number(const char *s) {
  char *end = nullptr;
  const double v = std::strtod(s, &end);
  if (!end || *end) usage((std::string("not a number: ") + s).c_str());
  return v;
}

Args parse(int argc, char **argv) {
  Args a;
  double cx = 0, cy = 0;
  bool have_centre = false;
  for (int i = 2; i < argc; ++i) {
    const std::string k = argv[i];
    auto need = [&](int n) {
      if (i + n >= argc) usage(("missing value after " + k).c_str());
    };
    if (k == "--images") {
      while (i + 1 < argc && argv[i + 1][0] != '-') a.images.push_back(argv[++i]);
    } else if (k == "--project") {
      need(1);
      a.project = argv[++i];
    } else if (k == "--out") {
      need(1);
      a.out = argv[++i];
    } else if (k == "--lights") {
      need(1);
      a.lights = argv[++i];
    } else if (k == "--shared") {
      need(1);
      a.shared = argv[++i];
    } else if (k == "--centre" || k == "--center") {
      need(2);
      cx = number(argv[++i]);
      cy = number(argv[++i]);
      have_centre = true;
    } else if (k == "--radius") {
      need(1);
      if (!have_centre) usage("--radius needs a --centre before it");
      a.spheres.push_back(SphereCircle{cx, cy, number(argv[++i])});
      have_centre = false;
    } else if (k == "--spheres") {
      need(1);
      a.sphere_count = int(number(argv[++i]));
    } else if (k == "--sphere-radius-world") {
      need(1);
      a.sphere_radius_world = number(argv[++i]);
    } else if (k == "--corners") {
      need(8);
      for (int n = 0; n < 8; ++n) a.corners.push_back(float(number(argv[++i])));
    } else if (k == "--exposure") {
      need(1);
      a.exposure = argv[++i];
    } else if (k == "--require") {
      a.require = true;
    } else if (k == "--check") {
      a.check = true;
    } else {
      usage(("unknown option " + k).c_str());
    }
  }
  if (have_centre) usage("--centre without --radius");
  return a;
}

std::string base_name(const std::string &p) {
  const size_t s = p.find_last_of('/');
  return s == std::string::npos ? p : p.substr(s + 1);
}

// ---- lights ----

int run_lights(const Args &a) {
  std::vector<std::string> images = a.images;
  SphereCamera cam;
  if (!a.project.empty()) {
    const Project p = read_project(a.project);
    if (p.rasters.empty()) throw InputError("Project '" + a.project + "' has no raster");
    cam = camera_from_shot(p.rasters[0].shot);
    if (images.empty())
      for (const Raster &r : p.rasters) images.push_back(r.image_path);
  }
  if (images.empty()) usage("no photos (--images or --project)");
  LightSettings st;
  st.manual_spheres = a.spheres;
  st.search.max_spheres = a.sphere_count;
  st.sphere_radius_world = a.sphere_radius_world;
  std::vector<std::string> names;
  for (const auto &p : images) names.push_back(base_name(p));
  const LightCalibration cal = calibrate_lights(
      images.size(), [&](size_t i) { return gray_image(calib::read_image(images[i])); }, cam, st, names);
  for (const auto &line : cal.log) std::printf("%s\n", line.c_str());
  for (size_t i = 0; i < cal.photos.size(); ++i) {
    const PhotoLight &p = cal.photos[i];
    if (!p.valid) continue;
    std::printf("%s %.6f %.6f %.6f", names[i].c_str(), p.dir[0], p.dir[1], p.dir[2]);
    if (cal.spheres.size() > 1) std::printf("  disagreement %.2f deg", p.disagreement_deg);
    if (p.has_position)
      std::printf("  position (%.4g, %.4g, %.4g) rms %.3g", p.position[0], p.position[1], p.position[2],
                  p.position_rms);
    std::printf("\n");
  }
  if (!a.out.empty()) {
    write_light_file(a.out, light_entries(cal, names));
    std::printf("Wrote %s (%zu lights).\n", a.out.c_str(), cal.valid_count());
  }
  return cal.valid_count() > 0 ? 0 : 1;
}

// ---- report ----

struct Check {
  bool ok = true;
  void expect(bool cond, const std::string &what) {
    if (!cond) {
      ok = false;
      std::printf("  MISSED: %s\n", what.c_str());
    }
  }
};

std::vector<double> errors_against(const LightCalibration &cal, const std::vector<std::array<double, 3>> &ref) {
  std::vector<double> e;
  for (size_t i = 0; i < ref.size() && i < cal.photos.size(); ++i)
    if (cal.photos[i].valid) e.push_back(angle_deg(cal.photos[i].dir, ref[i].data()));
  return e;
}

void print_row(const std::string &set, const std::string &sphere, const calib::Stats &s, size_t total) {
  std::printf("| %s | %s | %zu/%zu | %.2f | %.2f |\n", set.c_str(), sphere.c_str(), s.n, total, s.median, s.max);
}

void report_real_lights(const Args &a, Check &check) {
  std::printf("\n### Light directions: real photographs (orthographic, no camera intrinsics)\n\n");
  std::printf("| set | sphere circle | photos with a light | median error (deg) | max error (deg) |\n");
  std::printf("|---|---|---|---|---|\n");
  std::vector<calib::RealLightSet> sets;
  sets.push_back(calib::load_psm_chrome(a.shared));
  for (const char *obj : {"cat", "frog"})
    for (int probe = 1; probe <= 2; ++probe) sets.push_back(calib::load_harvard_probe(a.shared, obj, probe));
  for (const auto &set : sets) {
    std::vector<cv::Mat> photos;
    for (const auto &p : set.images) photos.push_back(calib::read_image(p));
    for (int manual = 1; manual >= 0; --manual) {
      LightSettings st;
      if (manual) st.manual_spheres.push_back(set.circle);
      const LightCalibration cal = calibrate_lights(photos, SphereCamera{}, st);
      const calib::Stats s = calib::stats_of(errors_against(cal, set.reference));
      const SphereCircle &c = cal.spheres[0].model.circle;
      char what[160];
      std::snprintf(what, sizeof what, "%s (%.1f, %.1f) r %.1f", manual ? set.circle_source.c_str() : "detected",
                    c.x, c.y, c.r);
      print_row(set.name, what, s, set.reference.size());
      const bool harvard = set.name.find("harvard") == 0;
      if (harvard)
        check.expect(s.median < (manual ? 1.0 : 1.5) && s.max < 3.0 && s.n == set.reference.size(),
                     set.name + (manual ? " with the set's circle" : " detected") + ": median/max targets");
    }
  }
}

// Harvard: two spheres per frame (cropped into separate probe images): per-frame angle between
// the two spheres' lights, ours and the reference's, and our combined light against the set's
// combined light_directions.txt.
void report_two_spheres(const Args &a, Check &check) {
  std::printf("\n### Two spheres per frame (harvard_psdata, sets' circles)\n\n");
  std::printf("| object | frames | disagreement ours: median / max (deg) | reference's own: median / max | "
              "combined light vs light_directions.txt: median / max |\n");
  std::printf("|---|---|---|---|---|\n");
  for (const char *obj : {"cat", "frog"}) {
    std::vector<LightCalibration> cal;
    std::vector<calib::RealLightSet> sets;
    for (int probe = 1; probe <= 2; ++probe) {
      sets.push_back(calib::load_harvard_probe(a.shared, obj, probe));
      std::vector<cv::Mat> photos;
      for (const auto &p : sets.back().images) photos.push_back(calib::read_image(p));
      LightSettings st;
      st.manual_spheres.push_back(sets.back().circle);
      cal.push_back(calibrate_lights(photos, SphereCamera{}, st));
    }
    const std::string dir = a.shared + "/real/harvard_psdata/" + obj + "/";
    std::vector<double> combined_ref;
    {
      std::ifstream in(dir + "light_directions.txt");
      double v;
      while (in >> v) combined_ref.push_back(v);
    }
    const size_t n = combined_ref.size() / 3;
    std::vector<double> ours, theirs, combined;
    for (size_t i = 0; i < n && i < cal[0].photos.size() && i < cal[1].photos.size(); ++i) {
      const PhotoLight &p1 = cal[0].photos[i], &p2 = cal[1].photos[i];
      theirs.push_back(angle_deg(sets[0].reference[i].data(), sets[1].reference[i].data()));
      if (!p1.valid || !p2.valid) continue;
      ours.push_back(angle_deg(p1.dir, p2.dir));
      double mean[3];
      for (int k = 0; k < 3; ++k) mean[k] = p1.dir[k] + p2.dir[k];
      const double ref[3] = {combined_ref[i], combined_ref[n + i], combined_ref[2 * n + i]};
      combined.push_back(angle_deg(mean, ref));
    }
    const calib::Stats o = calib::stats_of(ours), t = calib::stats_of(theirs), c = calib::stats_of(combined);
    std::printf("| %s | %zu | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f |\n", obj, o.n, o.median, o.max, t.median, t.max,
                c.median, c.max);
    check.expect(c.median < 1.0 && c.max < 3.0, std::string(obj) + ": combined light targets");
  }
}

void report_scene_lights(const Args &a, Check &check) {
  std::printf("\n### Light directions: Mitsuba scenes (perspective camera from project.mlp)\n\n");
  std::printf("| scene | sphere | photos with a light | median error (deg) | max error (deg) |\n");
  std::printf("|---|---|---|---|---|\n");
  for (const std::string &name : calib::scene_names(a.shared)) {
    const calib::SceneSet sc = calib::load_scene(a.shared, name);
    std::vector<cv::Mat> photos;
    for (const auto &p : sc.images) photos.push_back(calib::read_image(p));
    for (int manual = 1; manual >= 0; --manual) {
      LightSettings st;
      if (manual) st.manual_spheres.push_back(sc.sphere);
      st.sphere_radius_world = sc.sphere_radius_world;
      const LightCalibration cal = calibrate_lights(photos, sc.camera, st);
      std::vector<std::array<double, 3>> ref = sc.lights_cam;
      std::string note;
      if (sc.point_lights) {
        // A point light: the truth for the sphere is the direction from its highlight point.
        const SphereModel &m = cal.spheres[0].model;
        const double scale = sc.sphere_radius_world / std::sin(m.half_angle);
        for (size_t i = 0; i < ref.size(); ++i) {
          const Highlight &h = cal.photos[i].spheres[0].highlight;
          double l[3], p[3];
          if (!h.found || !highlight_to_light(sc.camera, m, h.x, h.y, l, nullptr, p)) continue;
          for (int k = 0; k < 3; ++k) ref[i][k] = sc.light_pos_cam[i][k] - p[k] * scale;
        }
        note = " (truth: highlight point to the point light)";
      }
      const calib::Stats s = calib::stats_of(errors_against(cal, ref));
      const SphereCircle &c = cal.spheres[0].model.circle;
      char what[200];
      std::snprintf(what, sizeof what, "%s (%.2f, %.2f) r %.2f%s", manual ? "ground-truth circle" : "detected", c.x,
                    c.y, c.r, note.c_str());
      print_row(name, what, s, ref.size());
      if (!sc.point_lights)
        check.expect(s.n == ref.size() && s.median < 1.0 && s.max < 6.0, name + ": light median/max targets");
    }
  }
}

// Exit status of `report` when its data is absent (ctest SKIP_RETURN_CODE).
constexpr int kSkip = 77;

// The folders `report` reads, relative to the shared data folder.
const char *const kReportData[] = {"real/psm_uw_seitz", "real/harvard_psdata", "real/colorchecker", "scenes"};

int run_report(const Args &a) {
  bool missing = false;
  for (const char *rel : kReportData)
    if (access((a.shared + "/" + rel).c_str(), R_OK) != 0) {
      std::printf("SKIP: shared test data not found: %s/%s (not part of the repository; set VBRDF_SHARED_DIR "
                  "or --shared to the folder holding scenes/ and real/)\n",
                  a.shared.c_str(), rel);
      missing = true;
    }
  if (missing) return kSkip;
  Check check;
  std::printf("## vbrdf_calibrate report (shared data: %s)\n", a.shared.c_str());
  report_real_lights(a, check);
  report_two_spheres(a, check);
  report_scene_lights(a, check);
  calib::report_colour(a.shared, check.ok);
  std::printf("\n%s\n", check.ok ? "All targets met." : "Some targets were missed (see MISSED lines).");
  return a.check && !check.ok ? 1 : 0;
}

} // namespace

int main(int argc, char **argv) {
  if (argc < 2) usage("no command");
  const std::string cmd = argv[1];
  const Args a = parse(argc, argv);
  try {
    if (cmd == "lights") return run_lights(a);
    if (cmd == "chart") return calib::run_chart(a.images, a.corners, a.lights, a.require, a.exposure, a.out);
    if (cmd == "report") return run_report(a);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "vbrdf_calibrate: %s\n", e.what());
    return 1;
  }
  usage(("unknown command " + cmd).c_str());
}
