#include "calib_data.h"

#include <algorithm>
#include <cmath>
#include <dirent.h>
#include <fstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/errors.h"
#include "inputs/light_file.h"
#include "inputs/project.h"

namespace vbrdf {
namespace calib {

namespace {
constexpr double kPi = 3.14159265358979323846;

cv::FileStorage open_json(const std::string &path) {
  cv::FileStorage fs;
  try {
    fs.open(path, cv::FileStorage::READ | cv::FileStorage::FORMAT_JSON);
  } catch (const cv::Exception &e) {
    throw InputError("Cannot parse '" + path + "': " + e.what());
  }
  if (!fs.isOpened()) throw InputError("Cannot open '" + path + "'");
  return fs;
}

std::vector<double> read_numbers(const std::string &path) {
  std::ifstream in(path);
  if (!in) throw InputError("Cannot open '" + path + "'");
  std::vector<double> v;
  std::string tok;
  // Some files separate with commas (Harvard's refined_light.txt): treat them as blanks.
  while (in >> tok) {
    std::replace(tok.begin(), tok.end(), ',', ' ');
    size_t pos = 0;
    while (pos < tok.size()) {
      size_t used = 0;
      const std::string rest = tok.substr(pos);
      if (rest.find_first_not_of(' ') == std::string::npos) break;
      v.push_back(std::stod(rest, &used));
      pos += used;
    }
  }
  return v;
}

// World point / direction to the camera frame of a shot (x right, y up, z towards the viewer).
std::array<double, 3> to_camera(const Shot &shot, const double p[3], bool point) {
  const vcg::Matrix44f r = shot.Extrinsics.Rot();
  const vcg::Point3f c = shot.GetViewPoint();
  double d[3] = {p[0], p[1], p[2]};
  if (point)
    for (int k = 0; k < 3; ++k) d[k] -= c[k];
  std::array<double, 3> out{{0, 0, 0}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[i] += r[i][j] * d[j];
  return out;
}
} // namespace

cv::Mat read_tga(const std::string &path) {
  std::ifstream f(path, std::ios::binary);
  unsigned char h[18];
  if (!f || !f.read(reinterpret_cast<char *>(h), 18)) throw InputError("Cannot read TGA '" + path + "'");
  const int w = h[12] | h[13] << 8, ht = h[14] | h[15] << 8, bpp = h[16];
  if (h[2] != 2 || (bpp != 24 && bpp != 32) || h[1] != 0)
    throw InputError("TGA '" + path + "': only uncompressed true-colour images are supported");
  f.ignore(h[0]);
  cv::Mat m(ht, w, bpp == 24 ? CV_8UC3 : CV_8UC4);
  if (!f.read(reinterpret_cast<char *>(m.data), std::streamsize(m.total() * m.elemSize())))
    throw InputError("TGA '" + path + "' is truncated");
  if (!(h[17] & 0x20)) cv::flip(m, m, 0);  // bottom-left origin
  return m;
}

cv::Mat read_image(const std::string &path) {
  const std::string ext = path.size() > 4 ? path.substr(path.size() - 4) : "";
  if (ext == ".tga" || ext == ".TGA") return read_tga(path);
  cv::Mat m = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (m.empty()) throw InputError("Cannot read image '" + path + "'");
  return m;
}

RealLightSet load_psm_chrome(const std::string &shared) {
  const std::string d = shared + "/real/psm_uw_seitz/";
  RealLightSet s;
  s.name = "psm_uw_seitz/chrome";
  const std::vector<double> v = read_numbers(d + "lights.txt");
  const size_t n = size_t(v.at(0));
  for (size_t i = 0; i < n; ++i) {
    s.images.push_back(d + "chrome/chrome." + std::to_string(i) + ".tga");
    s.reference.push_back({{v.at(1 + 3 * i), v.at(2 + 3 * i), v.at(3 + 3 * i)}});
  }
  cv::Mat mask, g;
  cv::cvtColor(read_tga(d + "chrome/chrome.mask.tga"), g, cv::COLOR_BGR2GRAY);
  mask = g > 127;
  const cv::Moments m = cv::moments(mask, true);
  s.circle = SphereCircle{m.m10 / m.m00 + 0.5, m.m01 / m.m00 + 0.5, std::sqrt(m.m00 / kPi)};
  s.circle_source = "centroid and area of chrome.mask.tga";
  return s;
}

RealLightSet load_harvard_probe(const std::string &shared, const std::string &object, int probe) {
  const std::string d = shared + "/real/harvard_psdata/" + object + "/LightProbe-" + std::to_string(probe) + "/";
  RealLightSet s;
  s.name = "harvard_psdata/" + object + "/LightProbe-" + std::to_string(probe);
  const std::vector<double> l = read_numbers(d + "light_directions.txt");
  const size_t n = l.size() / 3;
  for (size_t i = 0; i < n; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "Image_%02zu.JPG", i + 1);
    s.images.push_back(d + name);
    s.reference.push_back({{l[i], l[n + i], l[2 * n + i]}});  // 3 x n, row-major
  }
  const std::vector<double> c = read_numbers(d + "circle_data.txt");
  const cv::Mat first = read_image(s.images.at(0));
  // PSBox flips the image upside down and uses MATLAB's 1-based pixel indices: column j has
  // its centre at j - 0.5 here, flipped row i is top-down row H - i (centre H - i + 0.5).
  s.circle = SphereCircle{c.at(0) - 0.5, first.rows - c.at(1) + 0.5, c.at(2)};
  s.circle_source = "circle_data.txt of the set (PSBox)";
  return s;
}

SceneSet load_scene(const std::string &shared, const std::string &name) {
  SceneSet s;
  s.name = name;
  s.dir = shared + "/scenes/" + name;
  const Project project = read_project(s.dir + "/project.mlp");
  if (project.rasters.empty()) throw InputError("Scene '" + name + "' has no raster");
  s.shot = project.rasters[0].shot;
  s.camera = camera_from_shot(s.shot);
  for (const LightEntry &e : read_light_file(s.dir + "/lights.lp")) {
    s.lp_names.push_back(e.image);
    s.images.push_back(s.dir + "/" + e.image);
    s.lights_cam.push_back({{e.dir_cam[0], e.dir_cam[1], e.dir_cam[2]}});
  }

  cv::FileStorage gt = open_json(s.dir + "/gt_scene.json");
  const cv::FileNode sp = gt["sphere"];
  s.sphere = SphereCircle{double(sp["ellipse_center_px"][0]), double(sp["ellipse_center_px"][1]),
                          double(sp["radius_px"])};
  s.sphere_radius_world = double(sp["radius_world"]);
  const double cw[3] = {double(sp["center_world"][0]), double(sp["center_world"][1]), double(sp["center_world"][2])};
  s.sphere_centre_cam = to_camera(s.shot, cw, true);
  for (const cv::FileNode &h : sp["highlight_px"]) s.highlight_px.push_back({{double(h[0]), double(h[1])}});

  const cv::FileNode ch = gt["chart"];
  for (const cv::FileNode &p : ch["patch_centers_px"]) s.patch_centres.push_back({{double(p[0]), double(p[1])}});
  for (const cv::FileNode &p : ch["reflectance_linear"])
    s.patch_reference.push_back({{float(double(p[0])), float(double(p[1])), float(double(p[2]))}});
  const cv::FileNode resp = gt["camera_response"];
  s.exposure = double(resp["exposure"]);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s.cast[i][j] = double(resp["combined_matrix_A"][i][j]);

  cv::FileStorage lw = open_json(s.dir + "/lights_world.json");
  s.point_lights = std::string(lw["type"]) == "point";
  if (s.point_lights)
    for (const cv::FileNode &p : lw["position_world"]) {
      const double w[3] = {double(p[0]), double(p[1]), double(p[2])};
      s.light_pos_cam.push_back(to_camera(s.shot, w, true));
    }
  return s;
}

std::vector<std::string> scene_names(const std::string &shared) {
  std::vector<std::string> names;
  DIR *d = opendir((shared + "/scenes").c_str());
  if (!d) return names;
  while (dirent *e = readdir(d)) {
    const std::string n = e->d_name;
    if (n[0] == '.') continue;
    std::ifstream probe(shared + "/scenes/" + n + "/gt_scene.json");
    if (probe) names.push_back(n);
  }
  closedir(d);
  std::sort(names.begin(), names.end());
  return names;
}

Stats stats_of(std::vector<double> v) {
  Stats s;
  s.n = v.size();
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.median = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  s.max = v.back();
  for (double x : v) s.mean += x;
  s.mean /= double(v.size());
  return s;
}

} // namespace calib
} // namespace vbrdf
