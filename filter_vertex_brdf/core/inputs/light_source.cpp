#include "inputs/light_source.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <opencv2/core.hpp>

#include "base/angles.h"
#include "base/errors.h"
#include "base/file_util.h"
#include "inputs/light_file.h"
#include "base/output_file.h"

namespace vbrdf {

namespace {
using Vec3 = std::array<float, 3>;

float length3(const Vec3 &v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

// Distance from q to the box (0 inside).
float distance_to_box(const LightPlacement &p, const Vec3 &q) {
  float s = 0;
  for (int k = 0; k < 3; ++k) {
    const float d = std::max({p.box.min[k] - q[k], 0.0f, q[k] - p.box.max[k]});
    s += d * d;
  }
  return std::sqrt(s);
}

LightSource point_light(const Vec3 &position, const LightPlacement &placement, float intensity) {
  LightSource l;
  l.positional = true;
  l.position = position;
  l.intensity = intensity;
  const Vec3 c = placement.box.centre();
  Vec3 d{{position[0] - c[0], position[1] - c[1], position[2] - c[2]}};
  const float len = length3(d);
  if (len > 0)
    for (float &x : d) x /= len;
  else
    d = {{0, 0, 1}};
  l.direction = d;
  return l;
}

Vec3 camera_to_world_point(const Shot &shot, const Vec3 &p_cam) {
  // Camera frame: x right, y up, z towards the viewer, origin at the camera centre.
  float dir[3];
  const float len = length3(p_cam);
  if (!(len > 0)) {
    float c[3];
    camera_centre(shot, c);
    return {{c[0], c[1], c[2]}};
  }
  const float unit[3] = {p_cam[0] / len, p_cam[1] / len, p_cam[2] / len};
  camera_to_world_direction(shot, unit, dir);
  float c[3];
  camera_centre(shot, c);
  return {{c[0] + len * dir[0], c[1] + len * dir[1], c[2] + len * dir[2]}};
}

cv::FileStorage open_json(const std::string &path) {
  if (!file_exists(path)) throw InputError("Cannot open light file '" + path + "': check the path given in 'lightFile'.");
  cv::FileStorage fs;
  try {
    fs.open(path, cv::FileStorage::READ | cv::FileStorage::FORMAT_JSON);  // .dome too: JSON whatever the name
  } catch (const cv::Exception &e) {
    throw InputError("Light file '" + path + "' is not valid JSON (" + e.err + "): fix it or export it again.");
  }
  if (!fs.isOpened()) throw InputError("Light file '" + path + "' is not valid JSON: fix it or export it again.");
  return fs;
}

Vec3 read_vec3(const cv::FileNode &n, const std::string &path, const std::string &what) {
  Vec3 v{{0, 0, 0}};
  if (n.isSeq() && n.size() == 3) {
    for (int k = 0; k < 3; ++k) v[size_t(k)] = float(double(n[k]));
  } else if (n.isMap() && !n["x"].empty() && !n["y"].empty() && !n["z"].empty()) {
    v = {{float(double(n["x"])), float(double(n["y"])), float(double(n["z"]))}};
  } else {
    throw InputError("Light file '" + path + "': " + what + " is not a 3-vector ([x, y, z] or {x, y, z}).");
  }
  for (float c : v)
    if (!std::isfinite(c)) throw InputError("Light file '" + path + "': " + what + " is not finite.");
  return v;
}

std::vector<Vec3> read_vec3_list(const cv::FileNode &n, const std::string &path, const std::string &key) {
  std::vector<Vec3> out;
  if (n.empty() || !n.isSeq()) return out;
  for (size_t i = 0; i < n.size(); ++i)
    out.push_back(read_vec3(n[int(i)], path, key + "[" + std::to_string(i) + "]"));
  return out;
}

// Rasters matched to entries by file name; throws on a raster without an entry or an entry
// without a raster. Returns entry index per raster.
std::vector<size_t> match_entries(const std::vector<Raster> &rasters, const std::vector<std::string> &images,
                                  const std::string &path) {
  std::vector<LightEntry> named(images.size());
  for (size_t i = 0; i < images.size(); ++i) named[i].image = images[i];
  std::vector<size_t> index(rasters.size());
  std::vector<bool> used(images.size(), false);
  for (size_t r = 0; r < rasters.size(); ++r) {
    const int i = find_light_for_image(named, rasters[r].image_path);
    if (i < 0)
      throw InputError("Light file '" + path + "' has no entry for raster '" + rasters[r].label + "' (image '" +
                       file_name_of(rasters[r].image_path) + "'): add one or choose the file written for these photos.");
    index[r] = size_t(i);
    used[size_t(i)] = true;
  }
  for (size_t i = 0; i < images.size(); ++i)
    if (!used[i])
      throw InputError("Light file '" + path + "': entry '" + images[i] +
                       "' matches no raster of the project. Use the light file written for these photos.");
  return index;
}

std::vector<LightSource> from_lp(const std::vector<Raster> &rasters, const std::string &path,
                                 const LightPlacement &placement) {
  const std::vector<LightEntry> entries = read_light_file(path);
  std::vector<std::string> images;
  for (const LightEntry &e : entries) images.push_back(e.image);
  const std::vector<size_t> index = match_entries(rasters, images, path);
  std::vector<LightSource> lights(rasters.size());
  const Vec3 c = placement.box.centre();
  for (size_t r = 0; r < rasters.size(); ++r) {
    Vec3 d;
    camera_to_world_direction(rasters[r].shot, entries[index[r]].dir_cam, d.data());
    if (placement.dome_radius > 0) {
      const float R = placement.dome_radius;
      lights[r] = point_light({{c[0] + R * d[0], c[1] + R * d[1], c[2] + R * d[2]}}, placement, 1.0f);
    } else {
      lights[r] = LightSource::directional(d);
    }
  }
  return lights;
}

std::vector<LightSource> from_json(const std::vector<Raster> &rasters, const std::string &path,
                                   const LightPlacement &placement) {
  cv::FileStorage fs = open_json(path);
  const cv::FileNode root = fs.root();
  const cv::FileNode images_node = root["images"];
  if (images_node.empty() || !images_node.isSeq())
    throw InputError("Light file '" + path + "' has no \"images\" list: a light-position file names each photo "
                     "(docs/parameters.md#near-lights-light-positions).");
  std::vector<std::string> images;
  for (size_t i = 0; i < images_node.size(); ++i) images.push_back(std::string(images_node[int(i)]));
  const bool world = !root["position_world"].empty();
  const bool camera = !root["position_camera"].empty();
  if (world == camera)
    throw InputError("Light file '" + path + "' must hold exactly one of \"position_world\" (mesh frame) or "
                     "\"position_camera\" (each photo's camera frame): which frame the positions are in cannot be "
                     "told otherwise.");
  const std::string key = world ? "position_world" : "position_camera";
  const std::vector<Vec3> positions = read_vec3_list(root[key], path, key);
  if (positions.size() != images.size())
    throw InputError("Light file '" + path + "': " + std::to_string(images.size()) + " images but " +
                     std::to_string(positions.size()) + " entries in \"" + key + "\".");
  std::vector<float> intensity(images.size(), 1.0f);
  const cv::FileNode in = root["intensity"];
  if (!in.empty() && in.isSeq()) {
    if (in.size() != images.size())
      throw InputError("Light file '" + path + "': \"intensity\" has " + std::to_string(in.size()) +
                       " entries for " + std::to_string(images.size()) + " images.");
    for (size_t i = 0; i < images.size(); ++i) intensity[i] = float(double(in[int(i)]));
  }
  // A single "intensity" number is one intensity for every light: only ratios matter.
  for (size_t i = 0; i < intensity.size(); ++i)
    if (!(intensity[i] > 0) || !std::isfinite(intensity[i]))
      throw InputError("Light file '" + path + "': the intensity of '" + images[i] + "' must be positive.");
  const float scale = placement.unit_scale > 0 ? placement.unit_scale : 1.0f;
  const std::vector<size_t> index = match_entries(rasters, images, path);
  std::vector<LightSource> lights(rasters.size());
  for (size_t r = 0; r < rasters.size(); ++r) {
    const Vec3 &p = positions[index[r]];
    const Vec3 scaled{{p[0] * scale, p[1] * scale, p[2] * scale}};
    const Vec3 w = world ? scaled : camera_to_world_point(rasters[r].shot, scaled);
    lights[r] = point_light(w, placement, intensity[index[r]]);
  }
  return lights;
}

// Relight's frame for raster r: origin on the optical axis at the depth of the box centre.
Vec3 relight_frame_to_world(const Shot &shot, const Vec3 &p_cm, float scale, const LightPlacement &placement) {
  const Vec3 c = placement.box.centre();
  const float depth = view_depth(shot, c.data());
  const Vec3 p{{p_cm[0] * scale, p_cm[1] * scale, p_cm[2] * scale - depth}};  // camera frame, z towards viewer
  return camera_to_world_point(shot, p);
}

std::vector<LightSource> from_dome(const std::vector<Raster> &rasters, const std::string &path,
                                   const LightPlacement &placement) {
  cv::FileStorage fs = open_json(path);
  const cv::FileNode root = fs.root();
  std::string config = root["lightConfiguration"].empty() ? "directional" : std::string(root["lightConfiguration"]);
  const std::vector<Vec3> directions = read_vec3_list(root["directions"], path, "directions");
  std::vector<Vec3> positions;
  if (config == "lights3d") {
    positions = read_vec3_list(root["positions3d"], path, "positions3d");
  } else if (config == "spherical") {
    positions = read_vec3_list(root["positionsSphere"], path, "positionsSphere");
    if (positions.empty()) {
      const float radius = float(double(root["domeDiameter"])) / 2, offset = float(double(root["verticalOffset"]));
      if (!(radius > 0))
        throw InputError("Dome file '" + path + "': a spherical dome needs \"domeDiameter\" > 0 or \"positionsSphere\".");
      for (const Vec3 &d : directions) {
        const float len = length3(d);
        if (!(len > 0)) throw InputError("Dome file '" + path + "': a light direction has zero length.");
        positions.push_back({{d[0] / len * radius, d[1] / len * radius, d[2] / len * radius + offset}});
      }
    }
  } else if (config != "directional") {
    throw InputError("Dome file '" + path + "': unknown lightConfiguration '" + config +
                     "' (expected directional, spherical or lights3d).");
  }
  const size_t n = config == "directional" ? directions.size() : positions.size();
  if (n != rasters.size())
    throw InputError("Dome file '" + path + "' has " + std::to_string(n) + " lights (" + config + ") but the project has " +
                     std::to_string(rasters.size()) + " rasters: a .dome lists one light per photo, in file-name order.");
  if (config != "directional" && !(placement.unit_scale > 0))
    throw InputError("Dome file '" + path + "' gives light positions in cm: set 'lightUnitScale' to the mesh units "
                     "per cm (e.g. 10 for a mesh in mm, 0.01 for metres) so they can be placed around the mesh.");
  // Relight pairs lights with the photos sorted by file name.
  std::vector<size_t> order(rasters.size());
  for (size_t r = 0; r < order.size(); ++r) order[r] = r;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return file_name_of(rasters[a].image_path) < file_name_of(rasters[b].image_path);
  });
  std::vector<LightSource> lights(rasters.size());
  for (size_t i = 0; i < order.size(); ++i) {
    const size_t r = order[i];
    if (config == "directional") {
      Vec3 d = directions[i];
      const float len = length3(d);
      if (!(len > 0)) throw InputError("Dome file '" + path + "': a light direction has zero length.");
      for (float &x : d) x /= len;
      Vec3 w;
      camera_to_world_direction(rasters[r].shot, d.data(), w.data());
      lights[r] = LightSource::directional(w);
    } else {
      lights[r] = point_light(relight_frame_to_world(rasters[r].shot, positions[i], placement.unit_scale, placement),
                              placement, 1.0f);
    }
  }
  return lights;
}

} // namespace

LightSource LightSource::directional(const std::array<float, 3> &towards_light) {
  LightSource l;
  l.direction = towards_light;
  const float len = length3(l.direction);
  if (len > 0)
    for (float &x : l.direction) x /= len;
  return l;
}

void light_direction_at(const LightSource &light, const float x[3], float out[3]) {
  if (!light.positional) {
    for (int k = 0; k < 3; ++k) out[k] = light.direction[size_t(k)];
    return;
  }
  const float d[3] = {light.position[0] - x[0], light.position[1] - x[1], light.position[2] - x[2]};
  const float len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!(len > 1e-12f * light.reference_distance) || !std::isfinite(len)) {
    for (int k = 0; k < 3; ++k) out[k] = light.direction[size_t(k)];
    return;
  }
  for (int k = 0; k < 3; ++k) out[k] = d[k] / len;
}

float light_irradiance_at(const LightSource &light, const float x[3]) {
  if (!light.positional) return light.intensity;
  const float d[3] = {light.position[0] - x[0], light.position[1] - x[1], light.position[2] - x[2]};
  const float dist = std::max(std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), 1e-3f * light.reference_distance);
  const float ratio = light.reference_distance / dist;
  return light.intensity * ratio * ratio;
}

bool any_positional(const std::vector<LightSource> &lights) {
  return std::any_of(lights.begin(), lights.end(), [](const LightSource &l) { return l.positional; });
}

std::vector<LightSource> directional_lights(const std::vector<std::array<float, 3>> &towards_light) {
  std::vector<LightSource> lights;
  for (const auto &d : towards_light) lights.push_back(LightSource::directional(d));
  return lights;
}

std::vector<std::array<float, 3>> light_directions(const std::vector<LightSource> &lights) {
  std::vector<std::array<float, 3>> d;
  for (const LightSource &l : lights) d.push_back(l.direction);
  return d;
}

LightPlacement light_placement_of(const MeshView &mesh, float dome_radius, float unit_scale) {
  LightPlacement p;
  p.box = compute_bounds(mesh);
  p.dome_radius = dome_radius;
  p.unit_scale = unit_scale;
  return p;
}

namespace {
std::string json_string(const std::string &s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}
} // namespace

void write_light_positions(const std::string &path, const std::vector<std::string> &images,
                           const std::vector<std::array<float, 3>> &positions_world, const std::vector<float> &rms) {
  if (images.size() != positions_world.size() || (!rms.empty() && rms.size() != images.size()))
    throw InputError("Light positions for '" + path + "': " + std::to_string(images.size()) + " images, " +
                     std::to_string(positions_world.size()) + " positions.");
  std::ostringstream out;
  out.precision(9);
  out << "{\n \"format\": \"vertex-brdf light positions: world frame, mesh units\",\n \"images\": [";
  for (size_t i = 0; i < images.size(); ++i) out << (i ? ", " : "") << json_string(images[i]);
  out << "],\n \"position_world\": [";
  for (size_t i = 0; i < positions_world.size(); ++i) {
    for (float c : positions_world[i])
      if (!std::isfinite(c)) throw InputError("Light positions for '" + path + "': '" + images[i] + "' is not finite.");
    out << (i ? ", " : "") << "[" << positions_world[i][0] << ", " << positions_world[i][1] << ", "
        << positions_world[i][2] << "]";
  }
  out << "]";
  if (!rms.empty()) {
    out << ",\n \"position_rms_world\": [";
    for (size_t i = 0; i < rms.size(); ++i) out << (i ? ", " : "") << (std::isfinite(rms[i]) ? rms[i] : -1.0f);
    out << "]";
  }
  out << "\n}\n";
  write_text_file_atomically(path, out.str());
}

void check_light_positions(const std::vector<LightSource> &lights, const std::vector<Raster> &rasters,
                           const LightPlacement &placement, const std::string &path) {
  const float half_diagonal = 0.5f * placement.box.diagonal();
  for (size_t r = 0; r < lights.size(); ++r) {
    const LightSource &l = lights[r];
    if (!l.positional) continue;
    const std::string photo = r < rasters.size() ? "'" + file_name_of(rasters[r].image_path) + "'" : std::to_string(r);
    for (float c : l.position)
      if (!std::isfinite(c)) throw InputError("Light file '" + path + "': the light of photo " + photo + " is not finite.");
    const float d = distance_to_box(placement, l.position);
    std::ostringstream where;
    where << "(" << l.position[0] << ", " << l.position[1] << ", " << l.position[2] << ")";
    if (d <= 0)
      throw InputError("Light file '" + path + "': the light of photo " + photo + " at " + where.str() +
                       " lies inside the mesh's bounding box. Check the frame (world or camera) and the units "
                       "('lightUnitScale', 'domeRadius') of the positions.");
    if (d < half_diagonal)
      throw InputError("Light file '" + path + "': the light of photo " + photo + " at " + where.str() + " is " +
                       std::to_string(d) + " mesh units from the mesh's bounding box, nearer than half its diagonal (" +
                       std::to_string(half_diagonal) + "): a source that close is not a point for this object. Check "
                       "the frame and the units of the positions.");
  }
}

void set_reference_distance(std::vector<LightSource> &lights, const LightPlacement &placement) {
  const Vec3 c = placement.box.centre();
  std::vector<float> distances;
  for (const LightSource &l : lights)
    if (l.positional)
      distances.push_back(length3({{l.position[0] - c[0], l.position[1] - c[1], l.position[2] - c[2]}}));
  if (distances.empty()) return;
  std::nth_element(distances.begin(), distances.begin() + long(distances.size() / 2), distances.end());
  const float median = std::max(distances[distances.size() / 2], 1e-12f);
  for (LightSource &l : lights)
    if (l.positional) l.reference_distance = median;
}

std::vector<LightSource> resolve_lights(const std::vector<Raster> &rasters, const std::string &path,
                                        const LightPlacement &placement) {
  const std::string ext = extension_of(path);
  std::vector<LightSource> lights;
  if (ext == "json")
    lights = from_json(rasters, path, placement);
  else if (ext == "dome")
    lights = from_dome(rasters, path, placement);
  else
    lights = from_lp(rasters, path, placement);
  check_light_positions(lights, rasters, placement, path);
  set_reference_distance(lights, placement);
  return lights;
}

std::string describe_lights(const std::vector<LightSource> &lights, const LightPlacement &placement) {
  std::ostringstream s;
  size_t points = 0;
  float dmin = 1e30f, dmax = 0, subtended = 0;
  const Vec3 c = placement.box.centre();
  const float half = 0.5f * placement.box.diagonal();
  for (const LightSource &l : lights) {
    if (!l.positional) continue;
    ++points;
    const float d = length3({{l.position[0] - c[0], l.position[1] - c[1], l.position[2] - c[2]}});
    dmin = std::min(dmin, d), dmax = std::max(dmax, d);
    if (d > half) subtended = std::max(subtended, degrees_f(2 * std::asin(half / d)));
  }
  if (points == 0) {
    s << lights.size() << " directional lights";
    return s.str();
  }
  s.precision(3);
  s << points << " point lights, " << dmin << "-" << dmax << " mesh units from the object's centre (the object "
    << "subtends up to " << std::lround(subtended) << " degrees from the nearest: directions vary that much across it)";
  if (points < lights.size()) s << ", and " << lights.size() - points << " directional";
  return s.str();
}

} // namespace vbrdf
