#include "inputs/light_file.h"

#include <algorithm>
#include <cmath>
#include <dirent.h>
#include <fstream>
#include <set>
#include <sstream>
#include <sys/stat.h>

#include "base/errors.h"
#include "base/file_util.h"
#include "base/output_file.h"

namespace vbrdf {

namespace {
[[noreturn]] void fail(const std::string &path, int line, const std::string &what) {
  throw InputError("Light file '" + path + "', line " + std::to_string(line) + ": " + what +
                   ". Expected an RTI .lp file: first line N, then N lines 'image_file lx ly lz'.");
}

bool is_blank(const std::string &s) {
  return std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isspace(c); });
}
} // namespace

std::vector<LightEntry> read_light_file(const std::string &path) {
  std::ifstream in(path);
  if (!in) throw InputError("Cannot open light file '" + path + "': check the path given in 'lightFile'.");
  std::string line;
  int line_no = 0;
  long count = -1;
  while (count < 0 && std::getline(in, line)) {
    ++line_no;
    if (line_no == 1 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);  // UTF-8 byte-order mark
    if (is_blank(line)) continue;
    std::istringstream ls(line);
    if (!(ls >> count) || count <= 0) fail(path, line_no, "the first line must be the number of lights");
  }
  if (count < 0) fail(path, line_no, "the file is empty");

  std::vector<LightEntry> lights;
  std::vector<int> lines;  // line number of each entry
  while (std::getline(in, line)) {
    ++line_no;
    if (is_blank(line)) continue;
    if (long(lights.size()) == count)
      fail(path, line_no, "more light lines than the count (" + std::to_string(count) + ") on the first line");
    // The image name may contain spaces: the last three tokens are the direction.
    std::string name = line, tokens[3];
    for (int k = 2; k >= 0; --k) {
      while (!name.empty() && std::isspace((unsigned char)name.back())) name.pop_back();
      const size_t start = name.find_last_of(" \t");
      if (start == std::string::npos) fail(path, line_no, "expected 'image_file lx ly lz'");
      tokens[k] = name.substr(start + 1);
      name.erase(start);
    }
    while (!name.empty() && std::isspace((unsigned char)name.back())) name.pop_back();
    const size_t first = name.find_first_not_of(" \t");
    if (first == std::string::npos) fail(path, line_no, "expected 'image_file lx ly lz'");
    LightEntry e;
    e.image = name.substr(first);
    for (int k = 0; k < 3; ++k) {
      char *end = nullptr;
      e.dir_cam[k] = std::strtof(tokens[k].c_str(), &end);
      if (end == tokens[k].c_str() || *end != '\0' || !std::isfinite(e.dir_cam[k]))
        fail(path, line_no, "'" + tokens[k] + "' is not a number");
    }
    const float len = std::sqrt(e.dir_cam[0] * e.dir_cam[0] + e.dir_cam[1] * e.dir_cam[1] + e.dir_cam[2] * e.dir_cam[2]);
    if (!(len > 1e-6f)) fail(path, line_no, "the light direction has zero length");
    for (float &c : e.dir_cam) c /= len;
    for (size_t i = 0; i < lights.size(); ++i) {
      if (lights[i].image != e.image) continue;
      const float dot = lights[i].dir_cam[0] * e.dir_cam[0] + lights[i].dir_cam[1] * e.dir_cam[1] +
                        lights[i].dir_cam[2] * e.dir_cam[2];
      if (dot < 0.99999f)
        fail(path, line_no, "photo '" + e.image + "' is listed again (first on line " + std::to_string(lines[i]) +
                                ") with another direction; keep the one line that belongs to it");
    }
    lights.push_back(e);
    lines.push_back(line_no);
  }
  if (long(lights.size()) != count)
    fail(path, line_no, "the first line says " + std::to_string(count) + " lights but " +
                            std::to_string(lights.size()) + " light lines follow");
  return lights;
}

void write_light_file(const std::string &path, const std::vector<LightEntry> &lights) {
  std::ostringstream out;
  out << lights.size() << "\n";
  out.precision(9);
  for (const LightEntry &e : lights)
    out << e.image << " " << e.dir_cam[0] << " " << e.dir_cam[1] << " " << e.dir_cam[2] << "\n";
  write_text_file_atomically(path, out.str());
}

int find_light_for_image(const std::vector<LightEntry> &lights, const std::string &image_path) {
  const std::string name = file_name_of(image_path);
  for (size_t i = 0; i < lights.size(); ++i)
    if (file_name_of(lights[i].image) == name) return int(i);
  const std::string lower = to_lower(name);
  for (size_t i = 0; i < lights.size(); ++i)
    if (to_lower(file_name_of(lights[i].image)) == lower) return int(i);
  return -1;
}

namespace {
std::vector<std::string> lp_files_in(const std::string &dir) {
  std::vector<std::string> found;
  if (DIR *d = ::opendir(dir.c_str())) {
    while (dirent *e = ::readdir(d)) {
      const std::string n = e->d_name;
      if (n.size() > 3 && to_lower(n.substr(n.size() - 3)) == ".lp") found.push_back(join_path(dir, n));
    }
    ::closedir(d);
  }
  std::sort(found.begin(), found.end());
  return found;
}

double modification_time(const std::string &path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) return 0;
  return double(st.st_mtim.tv_sec) + 1e-9 * double(st.st_mtim.tv_nsec);
}

// "" when `lp_path` has an entry for every raster, else why not.
std::string why_not_covering(const std::string &lp_path, const std::vector<Raster> &rasters) {
  std::vector<LightEntry> lights;
  try {
    lights = read_light_file(lp_path);
  } catch (const InputError &e) {
    return e.what();
  }
  for (const Raster &r : rasters)
    if (find_light_for_image(lights, r.image_path) < 0)
      return "has no entry for raster '" + r.label + "' (image '" + file_name_of(r.image_path) + "')";
  return "";
}
} // namespace

std::string find_default_light_file(const std::vector<Raster> &rasters, const std::string &project_path,
                                    std::vector<std::string> *checked) {
  std::vector<std::string> dirs;
  if (!project_path.empty()) dirs.push_back(directory_of(project_path));
  for (const Raster &r : rasters) dirs.push_back(directory_of(r.image_path));
  std::vector<std::pair<double, std::string>> candidates;  // (-time, path): newest first, then path order
  std::set<std::string> seen_dirs, seen_files;
  for (const std::string &d : dirs)
    if (seen_dirs.insert(d).second)
      for (const std::string &f : lp_files_in(d))
        if (seen_files.insert(f).second) candidates.emplace_back(-modification_time(f), f);
  std::sort(candidates.begin(), candidates.end());
  for (const auto &candidate : candidates) {
    const std::string why = why_not_covering(candidate.second, rasters);
    if (why.empty()) return candidate.second;
    if (checked) checked->push_back(candidate.second + ": " + why);
  }
  return "";
}

std::string resolve_light_file(const std::string &given, const std::vector<Raster> &rasters,
                               const std::string &project_path) {
  if (!given.empty()) return given;
  std::vector<std::string> checked;
  const std::string found = find_default_light_file(rasters, project_path, &checked);
  if (!found.empty()) return found;
  if (checked.empty())
    throw InputError("No light file (.lp) found beside the project or the photos: set 'lightFile' to the .lp "
                     "that gives each photo's light direction.");
  std::string why;
  for (const std::string &c : checked) why += "\n  " + c;
  throw InputError("No light file (.lp) beside the project or the photos has an entry for every raster: set "
                   "'lightFile' to the .lp that gives each photo's light direction, or add the missing lines." +
                   why);
}

} // namespace vbrdf
