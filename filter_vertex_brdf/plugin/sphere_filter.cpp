#include "sphere_filter.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>

#include <QDir>
#include <QFileInfo>

#include "core/inputs/camera.h"
#include "core/base/errors.h"
#include "core/base/file_util.h"
#include "core/base/number_format.h"
#include "core/inputs/light_file.h"
#include "core/inputs/light_source.h"
#include "core/inputs/photo.h"
#include "core/run/fit_run.h"
#include "core/calibration/sphere_lights.h"
#include "filter_parameters.h"
#include "meshlab_bridge.h"

namespace vbrdf_plugin {

namespace {

// Parameter names of this filter only (the .mlx scripts refer to them, never rename); the shared
// ones (the first sphere's outline among them) are in filter_parameters.h.
const char *const kSphere2X = "sphere2CenterX";
const char *const kSphere2Y = "sphere2CenterY";
const char *const kSphere2Radius = "sphere2Radius";
const char *const kSphereCount = "sphereCount";
const char *const kSphereRadiusWorld = "sphereRadiusWorld";

const char *const kPrefix = "Vertex BRDF sphere: ";
const char *const kFitFilterName = "Vertex BRDF: fit per-vertex reflectance";


std::vector<size_t> viewpoint_of(const std::vector<vbrdf::Raster> &rasters, size_t raster) {
  for (const std::vector<size_t> &group : vbrdf::rasters_by_viewpoint(rasters))
    if (std::find(group.begin(), group.end(), raster) != group.end()) return group;
  return {raster};
}

// Mean of the linear channels (sphere_lights.h's grey image), through the photo's own table so
// that the chosen encoding applies.
template <typename T>
cv::Mat gray_of(const vbrdf::Photo &photo) {
  cv::Mat out(photo.pixels.size(), CV_32FC1);
  for (int y = 0; y < out.rows; ++y) {
    float *o = out.ptr<float>(y);
    for (int x = 0; x < out.cols; ++x)
      o[x] = (photo.lut[photo.code<T>(x, y, 0)] + photo.lut[photo.code<T>(x, y, 1)] + photo.lut[photo.code<T>(x, y, 2)]) / 3.0f;
  }
  return out;
}

// Loads photo i of the viewpoint on demand (detection reads each photo once or twice, the
// highlights once more); reports progress and honours cancellation.
vbrdf::GrayLoader gray_loader(const std::vector<vbrdf::Raster> &rasters, const std::vector<size_t> &group,
                              const SphereFilter::Settings &p, const vbrdf::ProgressFn &progress) {
  const size_t expected = (p.manual.empty() ? 3 : 1) * group.size();
  auto loads = std::make_shared<size_t>(0);
  return [&rasters, &group, &p, progress, expected, loads](size_t i) {
    const vbrdf::Raster &r = rasters[group.at(i)];
    const float fraction = std::min(0.95f, float(++*loads) / float(std::max<size_t>(1, expected)));
    if (progress && !progress(fraction, "finding the sphere and its highlights"))
      throw vbrdf::ProcessingError("cancelled");
    const vbrdf::Photo photo = vbrdf::load_photo(r.image_path, p.encoding, vbrdf::kSaturationLevel, r.width(), r.height());
    return photo.pixels.depth() == CV_16U ? gray_of<uint16_t>(photo) : gray_of<uint8_t>(photo);
  };
}

// The output must not replace the project, the mesh or a photo.
void check_output(const std::string &out, const std::string &project, const MeshModel *mesh,
                  const std::vector<vbrdf::Raster> &rasters) {
  std::vector<std::string> inputs = {project};
  if (mesh != nullptr) inputs.push_back(utf8(mesh->fullName()));
  for (const vbrdf::Raster &r : rasters) inputs.push_back(r.image_path);
  const std::string target = canonical_path(out);
  for (const std::string &in : inputs)
    if (!in.empty() && canonical_path(in) == target)
      throw vbrdf::InputError("Parameter '" + std::string(shared::kOutputLightFile) + "' names the input file '" + in +
                              "': choose another .lp path so that the input stays untouched.");
}

// Entries of an existing output .lp for rasters of other viewpoints, by raster index: running the
// filter once per viewpoint builds one .lp for the whole project.
std::map<size_t, vbrdf::LightEntry> other_viewpoint_entries(const std::string &out,
                                                            const std::vector<vbrdf::Raster> &rasters,
                                                            const std::vector<size_t> &group,
                                                            const std::function<void(const std::string &)> &log) {
  std::map<size_t, vbrdf::LightEntry> kept;
  if (!vbrdf::file_exists(out)) return kept;
  std::vector<vbrdf::LightEntry> existing;
  try {
    existing = vbrdf::read_light_file(out);
  } catch (const vbrdf::InputError &e) {
    log(std::string(kPrefix) + "the existing '" + out + "' is not a valid .lp (" + e.what() + "); it is replaced.");
    return kept;
  }
  for (size_t r = 0; r < rasters.size(); ++r) {
    if (std::find(group.begin(), group.end(), r) != group.end()) continue;
    const int i = vbrdf::find_light_for_image(existing, rasters[r].image_path);
    if (i >= 0) kept[r] = existing[size_t(i)];
  }
  return kept;
}

// A triangulated near-light position in the world frame (a MeshLab shot is rigid, so these are
// world units once the sphere radius is known in world units: the core then scales them).
std::array<float, 3> world_position(const vbrdf::PhotoLight &pl, const vbrdf::Raster &r) {
  const float p[3] = {float(pl.position[0]), float(pl.position[1]), float(pl.position[2])};
  const float length = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
  float dir[3], centre[3];
  vbrdf::camera_to_world_direction(r.shot, p, dir);
  vbrdf::camera_centre(r.shot, centre);
  return {{centre[0] + length * dir[0], centre[1] + length * dir[1], centre[2] + length * dir[2]}};
}

void log_positions(const vbrdf::LightCalibration &cal, const std::vector<vbrdf::Raster> &rasters,
                   const std::vector<size_t> &group, double radius_world,
                   const std::function<void(const std::string &)> &log) {
  for (size_t i = 0; i < cal.photos.size(); ++i) {
    const vbrdf::PhotoLight &pl = cal.photos[i];
    if (!pl.has_position) continue;
    const vbrdf::Raster &r = rasters[group[i]];
    const std::string name = "raster '" + r.label + "'";
    if (radius_world <= 0) {
      log(std::string(kPrefix) + name +
          vbrdf::formatted(": near light at (%.3f, %.3f, %.3f) sphere radii in the camera frame (RMS miss %.3f); set "
              "'sphereRadiusWorld' for world coordinates.",
              pl.position[0], pl.position[1], pl.position[2], pl.position_rms));
      continue;
    }
    const std::array<float, 3> w = world_position(pl, r);
    log(std::string(kPrefix) + name +
        vbrdf::formatted(": near light at world (%.4f, %.4f, %.4f), RMS miss %.4f.", w[0], w[1], w[2], pl.position_rms));
  }
}

// Image name as written in the .lp: relative to its folder when the photo is inside it (as
// RTIBuilder and Relight resolve them), else the absolute path.
std::string lp_image_name(const QDir &folder, const std::string &image) {
  const QString relative = folder.relativeFilePath(QString::fromStdString(image));
  if (relative.startsWith("../")) return utf8(QFileInfo(QString::fromStdString(image)).absoluteFilePath());
  return utf8(relative);
}

// The .lp lines: this viewpoint's lights and the kept entries of other viewpoints, in raster order.
std::vector<vbrdf::LightEntry> lp_entries(const vbrdf::LightCalibration &cal, const std::vector<vbrdf::Raster> &rasters,
                                          const std::vector<size_t> &group,
                                          std::map<size_t, vbrdf::LightEntry> entries, const std::string &out) {
  const QDir folder = QFileInfo(QString::fromStdString(out)).absoluteDir();
  for (size_t i = 0; i < group.size(); ++i) {
    const vbrdf::PhotoLight &pl = cal.photos[i];
    if (!pl.valid) continue;
    vbrdf::LightEntry e;
    e.image = lp_image_name(folder, rasters[group[i]].image_path);
    for (int c = 0; c < 3; ++c) e.dir_cam[c] = float(pl.dir[c]);
    entries[group[i]] = e;
  }
  std::vector<vbrdf::LightEntry> out_entries;
  for (const auto &kv : entries) out_entries.push_back(kv.second);
  return out_entries;
}

// With two spheres and their radius in world units: the triangulated positions of this viewpoint's
// lights as a light-position file beside the .lp (<name>_positions.json, light_source.h), for
// the fit's lightFile, when every photo of the viewpoint has one; the log says how precise they
// are (the rays' RMS miss) or why no file was written.
void write_positions(const vbrdf::LightCalibration &cal, const std::vector<vbrdf::Raster> &rasters,
                     const std::vector<size_t> &group, double radius_world, const std::string &out_lp,
                     const std::function<void(const std::string &)> &log) {
  size_t with_position = 0;
  for (const vbrdf::PhotoLight &pl : cal.photos) with_position += pl.valid && pl.has_position;
  if (with_position == 0) return;  // distant lights (or one sphere): the .lp says it all
  if (radius_world <= 0) {
    log(std::string(kPrefix) + "near-light positions were triangulated for " + std::to_string(with_position) +
        " photo(s); give 'sphereRadiusWorld' (the spheres' radius in mesh units) to get them in the mesh's frame "
        "as a light-position file for the fit.");
    return;
  }
  if (with_position < group.size()) {
    log(std::string(kPrefix) + "no light-position file: " + std::to_string(group.size() - with_position) +
        " photo(s) of the viewpoint have no triangulated position (no light, or spheres that agree within "
        "a degree: a distant light). Fit with the .lp, or with 'domeRadius' if the lights stand on a dome.");
    return;
  }
  const QDir folder = QFileInfo(QString::fromStdString(out_lp)).absoluteDir();
  std::vector<std::string> images;
  std::vector<std::array<float, 3>> positions;
  std::vector<float> rms;
  for (size_t i = 0; i < group.size(); ++i) {
    images.push_back(lp_image_name(folder, rasters[group[i]].image_path));
    positions.push_back(world_position(cal.photos[i], rasters[group[i]]));
    rms.push_back(float(cal.photos[i].position_rms));
  }
  std::vector<float> sorted = rms;
  std::sort(sorted.begin(), sorted.end());
  const std::string path = vbrdf::strip_extension(out_lp) + "_positions.json";
  vbrdf::write_light_positions(path, images, positions, rms);
  log(std::string(kPrefix) + "wrote the " + std::to_string(group.size()) + " triangulated light positions to '" +
      path + "'" + vbrdf::formatted(" (the reflected rays miss them by %.4g median, %.4g at most, in mesh units). ",
                       sorted[sorted.size() / 2], sorted.back()) +
      "For near lights, set the fit's lightFile to it.");
}

void validate_viewpoint(const std::vector<vbrdf::Raster> &rasters, const std::vector<size_t> &group) {
  for (size_t r : group) {
    if (!vbrdf::shot_is_valid(rasters[r].shot))
      throw vbrdf::InputError("Raster '" + rasters[r].label + "' has no valid camera: register it to the mesh first.");
    if (!vbrdf::file_exists(rasters[r].image_path))
      throw vbrdf::InputError("Raster '" + rasters[r].label + "': photo '" + rasters[r].image_path +
                              "' is missing. Restore the file or fix the path in the project.");
  }
}

// Spheres and per-photo lights of the viewpoint, logged; InputError when no photo got a light.
vbrdf::LightCalibration calibrate(const std::vector<vbrdf::Raster> &rasters, const std::vector<size_t> &group,
                                  size_t chosen, const SphereFilter::Settings &p, const vbrdf::ProgressFn &progress,
                                  const std::function<void(const std::string &)> &log) {
  vbrdf::LightSettings settings;
  settings.manual_spheres = p.manual;
  settings.search.max_spheres = p.sphere_count;
  settings.sphere_radius_world = p.radius_world;
  std::vector<std::string> names;
  for (size_t r : group) names.push_back(rasters[r].label);  // the core quotes them
  const vbrdf::SphereCamera camera = vbrdf::camera_from_shot(rasters[chosen].shot);
  const vbrdf::LightCalibration cal =
      vbrdf::calibrate_lights(group.size(), gray_loader(rasters, group, p, progress), camera, settings, names);
  for (const std::string &line : cal.log) log(kPrefix + line);
  log_positions(cal, rasters, group, p.radius_world, log);
  if (cal.valid_count() == 0)
    throw vbrdf::InputError("No photo of the viewpoint of raster '" + rasters[chosen].label +
                            "' got a light: the sphere shows no highlight (see the warnings). Check the sphere's "
                            "centre and radius (parameters '" + shared::kSphereCenterX + "', '" +
                            shared::kSphereCenterY + "', '" + shared::kSphereRadius + "'); nothing was written.");
  return cal;
}

} // namespace

QString SphereFilter::name() const { return "Vertex BRDF: estimate light directions from a reflective sphere"; }

QString SphereFilter::info() const {
  return "Estimates the light direction of every photo of one viewpoint (the rasters that share the chosen "
         "raster's camera) from the highlight on a mirror sphere (chrome or black glass ball) visible in the "
         "photos, and writes them to an <i>.lp</i> file (RTIBuilder/Relight format) for \"Vertex BRDF: fit "
         "per-vertex reflectance\" (its <i>lightFile</i> parameter).<br><br>"
         "The sphere is found automatically (circles in the median and maximum images, the track of the "
         "highlights over the photos), or given by its centre and radius in image pixels of the photos (x right, "
         "y down from the top-left corner, as in any image viewer); the log says which method found it. The "
         "light is the mirror reflection of the camera ray through the highlight, with the perspective of the "
         "raster's camera. A photo whose sphere is in shadow or shows no highlight gets no light (the log names "
         "it).<br><br>"
         "With two or more spheres the log reports how much their directions disagree (a near light) and, for "
         "photos where they disagree by more than a degree, the triangulated light position (in world units "
         "when the spheres' radius in world units is given). Entries of other viewpoints already in the output "
         ".lp are kept, so running the filter once per viewpoint builds one .lp for the project. The mesh and "
         "the project are not changed.";
}

host::FilterInterface::FilterClass SphereFilter::filterClass() const { return host::FilterInterface::Camera; }

int SphereFilter::postConditions() const { return MeshModel::MM_NONE; }

void SphereFilter::initParameters(const MeshDocument &, RichParameterList &params) const {
  shared::add_viewpoint_raster(params);
  shared::add_sphere_outline(params);
  params.addParam(RichFloat(kSphere2X, 0.0f, "Second sphere centre x (px)",
                            "Optional second sphere (needs the first one set): centre x in image pixels."));
  params.addParam(RichFloat(kSphere2Y, 0.0f, "Second sphere centre y (px)",
                            "Second sphere: centre y in image pixels from the top edge."));
  params.addParam(RichFloat(kSphere2Radius, 0.0f, "Second sphere radius (px)",
                            "Second sphere: radius in image pixels; 0: no second sphere given."));
  params.addParam(RichInt(kSphereCount, 1, "Spheres to find",
                          "Automatic detection only: how many spheres to look for (1 to 4). With two or more, "
                          "each photo's light is the mean of the spheres' directions and the log reports their "
                          "disagreement and the near-light position."));
  params.addParam(RichFloat(kSphereRadiusWorld, 0.0f, "Sphere radius (world units)",
                            "Physical radius of the spheres in the mesh's units (all spheres the same size). "
                            "Only for triangulated near-light positions: given, they are logged in world "
                            "coordinates; 0: in sphere radii, camera frame."));
  shared::add_photo_encoding(params);
  shared::add_output_light_file(params, shared::OutputLightFileUse::Sphere);
}

SphereFilter::Settings SphereFilter::settings_from(const RichParameterList &params) {
  Settings p;
  p.viewpoint_raster = shared::viewpoint_raster(params);
  const vbrdf::SphereCircle first = shared::sphere_outline(params);
  const vbrdf::SphereCircle second = shared::sphere_outline(params, kSphere2X, kSphere2Y, kSphere2Radius);
  require(first.r > 0 || second.r == 0, shared::kSphereRadius,
          "must be set when the second sphere is given (set the first sphere's centre and radius too)");
  if (first.r > 0) p.manual.push_back(first);
  if (second.r > 0) p.manual.push_back(second);
  p.sphere_count = params.getInt(kSphereCount);
  require(p.sphere_count >= 1 && p.sphere_count <= 4, kSphereCount, "must be in [1, 4]");
  p.radius_world = params.getFloat(kSphereRadiusWorld);
  require(std::isfinite(p.radius_world) && p.radius_world >= 0, kSphereRadiusWorld,
          "must be 0 (unknown) or the spheres' radius in the mesh's units");
  p.encoding = shared::photo_encoding(params);
  p.output = shared::output_light_file(params);
  return p;
}

void SphereFilter::apply(FilterRun &run) const {
  const auto log = [&run](const std::string &line) {
    const bool warning = line.find("Warning") != std::string::npos;
    run.log(warning ? GLLogStream::WARNING : GLLogStream::FILTER, line);
  };
  const Settings p = settings_from(run.params);
  const std::vector<vbrdf::Raster> rasters = document_rasters(run.document);
  if (rasters.empty())
    throw vbrdf::InputError("The project has no rasters: load the registered photos of the viewpoint (File > Import "
                            "Raster) or open the .mlp.");
  const size_t chosen = shared::chosen_raster(run.document, p.viewpoint_raster);
  const std::vector<size_t> group = viewpoint_of(rasters, chosen);
  validate_viewpoint(rasters, group);
  const MeshModel *mesh = run.document.mm();
  const std::string project = mesh != nullptr ? project_path(run.document, *mesh) : std::string();
  std::string out = resolve_path(p.output, project);
  if (out.empty()) out = shared::default_output_light_file(project, shared::OutputLightFileUse::Sphere);
  check_output(out, project, mesh, rasters);
  log(std::string(kPrefix) + "viewpoint of raster '" + rasters[chosen].label + "': " + std::to_string(group.size()) +
      " photo(s).");

  const vbrdf::ProgressFn progress = progress_adapter(run.progress, kPrefix);
  const vbrdf::LightCalibration cal = calibrate(rasters, group, chosen, p, progress, log);
  const auto kept = other_viewpoint_entries(out, rasters, group, log);
  vbrdf::write_light_file(out, lp_entries(cal, rasters, group, kept, out));
  if (progress) progress(1.0f, "done");
  log(std::string(kPrefix) + "wrote " + std::to_string(cal.valid_count()) + " light direction(s) to '" + out + "'" +
      (kept.empty() ? std::string() : " (kept " + std::to_string(kept.size()) + " entries of other viewpoints)") +
      ". To fit with them, set lightFile to '" + out + "' in \"" + kFitFilterName + "\".");
  write_positions(cal, rasters, group, p.radius_world, out, log);
  if (cal.valid_count() < group.size())
    log(std::string(kPrefix) + "Warning: " + std::to_string(group.size() - cal.valid_count()) +
        " photo(s) got no light and have no entry in the .lp: the fit will ask for them; remove those rasters or "
        "give their lights by hand.");
}

} // namespace vbrdf_plugin
