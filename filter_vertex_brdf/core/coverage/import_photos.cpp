// Between two shots: the new photos of a viewpoint and their lights (contract in
// coverage/import_photos.h).
#include "coverage/import_photos.h"

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <dirent.h>
#include <set>


#include "base/errors.h"
#include "base/file_util.h"
#include "calibration/sphere_lights.h"
#include "inputs/image_codec.h"

namespace vbrdf {

namespace {
bool is_image_name(const std::string &name) {
  const std::string lower = to_lower(name);
  for (const char *ext : {".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp"}) {
    const std::string e = ext;
    if (lower.size() > e.size() && lower.compare(lower.size() - e.size(), e.size(), e) == 0) return true;
  }
  return false;
}

std::string canonical(const std::string &path) {
  char buffer[PATH_MAX];
  return ::realpath(path.c_str(), buffer) ? std::string(buffer) : path;
}

std::string relative_to(const std::string &path, const std::string &folder) {
  const std::string a = canonical(path), dir = canonical(folder) + "/";
  return a.compare(0, dir.size(), dir) == 0 ? a.substr(dir.size()) : a;
}
} // namespace

std::vector<std::string> new_photos_in_folder(const std::string &folder, const std::vector<Raster> &rasters) {
  std::set<std::string> taken;
  for (const Raster &r : rasters) taken.insert(canonical(r.image_path));
  DIR *d = ::opendir(folder.c_str());
  if (!d) throw InputError("Photo folder '" + folder + "' cannot be read: check the path.");
  std::vector<std::string> found;
  while (dirent *e = ::readdir(d)) {
    const std::string name = e->d_name;
    const std::string path = join_path(folder, name);
    if (is_image_name(name) && file_exists(path) && !taken.count(canonical(path))) found.push_back(path);
  }
  ::closedir(d);
  std::sort(found.begin(), found.end());
  return found;
}

std::vector<LightEntry> sphere_light_entries(const std::vector<std::string> &photos, const std::vector<size_t> &wanted,
                                             const Shot &shot, const SphereCircle &manual,
                                             const std::string &lp_folder,
                                             const LogFn &log) {
  LightSettings settings;
  if (manual.r > 0) settings.manual_spheres.push_back(manual);
  std::vector<std::string> names;
  for (const std::string &p : photos) names.push_back(file_name_of(p));
  const GrayLoader load = [&photos](size_t i) {
    const cv::Mat image = read_image_unchanged(photos[i]);
    if (image.empty()) throw InputError("Photo '" + photos[i] + "' cannot be read: check the file.");
    return gray_image(image, true);
  };
  const LightCalibration cal = calibrate_lights(photos.size(), load, camera_from_shot(shot), settings, names);
  for (const std::string &line : cal.log) log("Sphere: " + line);
  std::vector<LightEntry> out;
  for (size_t i : wanted) {
    const PhotoLight &p = cal.photos.at(i);
    if (!p.valid)
      throw InputError("Photo '" + photos[i] + "': no light from the sphere (" +
                       (p.warning.empty() ? std::string("no highlight found") : p.warning) +
                       "). Check that the sphere and its highlight are in the picture, give the sphere's centre "
                       "and radius, or take the light from an .lp.");
    LightEntry e;
    e.image = relative_to(photos[i], lp_folder);
    for (int k = 0; k < 3; ++k) e.dir_cam[k] = float(p.dir[k]);
    out.push_back(e);
  }
  return out;
}

std::vector<LightEntry> merge_light_entries(const std::vector<LightEntry> &existing, const std::vector<LightEntry> &added) {
  std::vector<LightEntry> out;
  for (const LightEntry &e : existing)
    if (find_light_for_image(added, e.image) < 0) out.push_back(e);
  out.insert(out.end(), added.begin(), added.end());
  return out;
}

} // namespace vbrdf
