#include "import_photos_filter.h"

#include <set>
#include <sstream>

#include <QDir>
#include <QFileInfo>
#include <QImageReader>

#include "core/run/coverage_run.h"
#include "core/base/errors.h"
#include "core/base/file_util.h"
#include "core/inputs/light_file.h"
#include "coverage_filter.h"
#include "filter_parameters.h"
#include "meshlab_bridge.h"

namespace vbrdf_plugin {

namespace {

// Parameter names of this filter only (the .mlx scripts refer to them, never rename); the shared
// ones are in filter_parameters.h.
const char *const kPhotoFiles = "photoFiles";
const char *const kPhotoFolder = "photoFolder";
const char *const kReferenceRaster = "referenceRaster";
const char *const kLightSource = "lightSource";
const char *const kUpdateCoverage = "updateCoverage";

enum LightSource { kFromLightFile = 0, kFromSphere = 1 };
using Settings = ImportPhotosFilter::Settings;

// The photos to import: the listed files, else every new image of the folder (default: the
// reference raster's photo folder). Photos that already are rasters are skipped.
std::vector<std::string> photos_to_import(const Settings &s, const std::vector<vbrdf::Raster> &rasters,
                                          const vbrdf::Raster &reference, const std::string &project,
                                          const std::function<void(const std::string &)> &log) {
  if (s.photo_files.empty()) {
    std::string folder = resolve_path(s.photo_folder, project);
    if (folder.empty()) folder = vbrdf::directory_of(reference.image_path);
    return vbrdf::new_photos_in_folder(folder, rasters);
  }
  std::set<std::string> taken;
  for (const vbrdf::Raster &r : rasters) taken.insert(canonical_path(r.image_path));
  std::vector<std::string> photos;
  for (const std::string &item : s.photo_files) {
    const std::string path = resolve_path(item, project);
    if (!vbrdf::file_exists(path))
      throw vbrdf::InputError("Photo '" + path + "' (parameter '" + kPhotoFiles + "') does not exist: check the name; "
                              "relative names are relative to the project folder.");
    if (taken.insert(canonical_path(path)).second) photos.push_back(path);
    else log("Vertex BRDF import: '" + path + "' is already a raster; skipped.");
  }
  return photos;
}

// Photos of one viewpoint must have the registered photo's size (same camera settings).
void check_sizes(const std::vector<std::string> &photos, const vbrdf::Raster &reference) {
  for (const std::string &p : photos) {
    const QSize size = QImageReader(QString::fromStdString(p)).size();
    if (!size.isValid())
      throw vbrdf::InputError("Photo '" + p + "' cannot be read as an image: check the file.");
    if (size.width() != reference.width() || size.height() != reference.height())
      throw vbrdf::InputError("Photo '" + p + "' is " + std::to_string(size.width()) + "x" +
                              std::to_string(size.height()) + " but raster '" + reference.label + "' is " +
                              std::to_string(reference.width()) + "x" + std::to_string(reference.height()) +
                              ": photos of one viewpoint need the same camera settings; register it on its own.");
  }
}

std::vector<vbrdf::Raster> new_rasters(const std::vector<std::string> &photos, const vbrdf::Raster &reference) {
  std::vector<vbrdf::Raster> out;
  for (const std::string &p : photos) {
    vbrdf::Raster r;
    r.label = vbrdf::file_name_of(p);
    r.image_path = p;
    r.shot = reference.shot;
    out.push_back(r);
  }
  return out;
}

// Sphere mode: estimates the lights of the new photos (and of the viewpoint's rasters that have
// none) and writes them, with every entry of the existing .lp, to the output .lp. Returns its path.
std::string lights_from_sphere(const Settings &s, const std::vector<vbrdf::Raster> &rasters,
                               const std::vector<vbrdf::Raster> &added, size_t reference_index,
                               const std::string &project, const std::function<void(const std::string &)> &log) {
  const vbrdf::Raster &reference = rasters[reference_index];
  const std::string given = resolve_path(s.light_file, project);
  if (!given.empty() && vbrdf::extension_of(given) != "lp")
    throw vbrdf::InputError("Parameter '" + std::string(shared::kLightFile) + "': the import merges the new photos' "
                            "lights into an RTI .lp, but '" + given + "' is not one (light positions in .json or "
                            ".dome are not merged). Give the .lp of the earlier photos, or leave it empty.");
  const std::string existing_lp = given.empty() ? vbrdf::find_default_light_file(rasters, project) : given;
  std::vector<vbrdf::LightEntry> existing;
  if (!existing_lp.empty()) existing = vbrdf::read_light_file(existing_lp);
  std::string out = resolve_path(s.output_light_file, project);
  if (out.empty()) out = shared::default_output_light_file(project, shared::OutputLightFileUse::Import);
  if (!given.empty() && canonical_path(out) == canonical_path(given))
    throw vbrdf::InputError("Parameter '" + std::string(shared::kOutputLightFile) + "' names the input light file '" + given +
                            "': choose another output so that the original stays untouched.");

  // The sphere is located on every photo of the viewpoint; lights are estimated where missing.
  std::vector<std::string> photos;
  std::vector<size_t> wanted;
  const auto viewpoints = vbrdf::group_viewpoints(rasters);
  for (size_t i : viewpoints[vbrdf::viewpoint_of_raster(viewpoints, reference_index)].rasters) {
    if (vbrdf::find_light_for_image(existing, rasters[i].image_path) < 0) wanted.push_back(photos.size());
    photos.push_back(rasters[i].image_path);
  }
  for (const vbrdf::Raster &r : added) wanted.push_back(photos.size()), photos.push_back(r.image_path);
  const auto entries = vbrdf::sphere_light_entries(photos, wanted, reference.shot, s.sphere, vbrdf::directory_of(out),
                                                   [&log](const std::string &l) { log("Vertex BRDF import: " + l); });
  vbrdf::write_light_file(out, vbrdf::merge_light_entries(existing, entries));
  log("Vertex BRDF import: " + std::to_string(entries.size()) + " light(s) estimated from the sphere; wrote " + out +
      (existing_lp.empty() ? std::string() : " (with the entries of " + existing_lp + ")"));
  return out;
}

// .lp mode: the given .lp, checked for every raster, or the default one (resolve_light_file: the
// newest one beside the project or photos that has an entry for every raster, the new photos included).
std::string lights_from_file(const Settings &s, const std::vector<vbrdf::Raster> &all, const std::string &project) {
  const std::string given = resolve_path(s.light_file, project);
  if (!given.empty()) vbrdf::lights_for_rasters(all, given);  // names the first raster without entry
  return vbrdf::resolve_light_file(given, all, project);
}

} // namespace

QString ImportPhotosFilter::name() const { return "Vertex BRDF: import new photos of a viewpoint"; }

QString ImportPhotosFilter::info() const {
  return "The step between two shots of an acquisition: adds the new photos taken from an already "
         "registered camera position as raster layers that copy the registration (shot) of that raster, so "
         "the viewpoint is never re-aligned, then updates the coverage colours and the next-light suggestions "
         "(as \"Vertex BRDF: coverage and next light\" with its default settings).<br><br>"
         "Photos: a list of files (separated by ';'), or every image in a folder that is not a raster yet "
         "(default: the folder of the reference raster's photo). They must have the reference photo's size.<br>"
         "Lights: from an <i>.lp</i> file that has an entry for every photo, or estimated from the reflective "
         "sphere visible in the photos (located on all photos of the viewpoint, or given by centre and radius "
         "in pixels); the estimated lights are written, with every entry of the existing .lp, to a new .lp "
         "beside the project, which the fit, coverage and relight filters then find by themselves (each takes "
         "the most recently modified .lp beside the project or the photos that has an entry for every raster). Save the project (File &gt; Save Project) to keep the new rasters.";
}

host::FilterInterface::FilterClass ImportPhotosFilter::filterClass() const {
  return host::FilterInterface::FilterClass(host::FilterInterface::Camera | host::FilterInterface::RasterLayer);
}

int ImportPhotosFilter::requirements() const { return MeshModel::MM_VERTCOLOR; }

int ImportPhotosFilter::preConditions() const { return MeshModel::MM_FACENUMBER; }

// MM_VERTNUMBER: no Preview in MeshLab 2020.09 (see FitFilter::postConditions): a preview would add
// the rasters and write the light file at every change of a field.
int ImportPhotosFilter::postConditions() const {
  return MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTFLAGSELECT | MeshModel::MM_VERTNUMBER;
}

void ImportPhotosFilter::initParameters(const MeshDocument &, RichParameterList &params) const {
  params.addParam(RichString(kPhotoFiles, "", "Photo files",
                             "New photos to import, separated by ';' (relative names are relative to the project "
                             "folder). Empty: every image of the photo folder that is not a raster yet."));
  params.addParam(RichString(kPhotoFolder, "", "Photo folder",
                             "Used when no photo file is listed: every image (png, jpg, tif, bmp) in this folder "
                             "that is not a raster yet is imported. Empty: the folder of the reference raster's "
                             "photo."));
  params.addParam(RichInt(kReferenceRaster, -1, "Reference raster",
                          "The registered raster (counted from 0 in the layer list) whose camera the new photos "
                          "share; -1: the last raster."));
  params.addParam(RichEnum(kLightSource, kFromLightFile, QStringList() << "Light file (.lp)" << "Reflective sphere",
                           "Light directions",
                           "Light file: the .lp must have an entry for every photo. Reflective sphere: each new "
                           "photo's light is estimated from the sphere's highlight (sphere parameters below) and "
                           "written, with the entries of the light file (the lights of the photos taken before), "
                           "to the output .lp."));
  shared::add_light_file(params);
  shared::add_sphere_outline(params);
  shared::add_output_light_file(params, shared::OutputLightFileUse::Import);
  params.addParam(RichBool(kUpdateCoverage, true, "Update coverage",
                           "Then run \"Vertex BRDF: coverage and next light\" with its default settings: vertex "
                           "colours by coverage, suggestions in the log and beside the project."));
}

ImportPhotosFilter::Settings ImportPhotosFilter::settings_from(const RichParameterList &params) {
  Settings s;
  for (const QString &item : params.getString(kPhotoFiles).split(QRegExp("[;\n]"), QString::SkipEmptyParts))
    if (!item.trimmed().isEmpty()) s.photo_files.push_back(utf8(item.trimmed()));
  s.photo_folder = utf8(params.getString(kPhotoFolder).trimmed());
  s.reference_raster = params.getInt(kReferenceRaster);
  require(s.reference_raster >= -1, kReferenceRaster, "must be -1 (the last raster) or a raster index");
  const int source = params.getEnum(kLightSource);
  require(source == kFromLightFile || source == kFromSphere, kLightSource, "must be 0 (.lp) or 1 (sphere)");
  s.lights_from_sphere = source == kFromSphere;
  s.light_file = shared::light_file(params);
  s.sphere = shared::sphere_outline(params);
  s.output_light_file = shared::output_light_file(params);
  s.update_coverage = params.getBool(kUpdateCoverage);
  return s;
}

void ImportPhotosFilter::apply(FilterRun &run) const {
  const Settings s = settings_from(run.params);
  MeshModel *mesh = run.document.mm();
  if (mesh == nullptr)
    throw vbrdf::InputError("No current mesh: open the registered mesh (or its .mlp project) first.");
  const auto log = [&run](const std::string &line) { run.log(GLLogStream::FILTER, line); };
  const std::vector<vbrdf::Raster> rasters = document_rasters(run.document);
  if (rasters.empty())
    throw vbrdf::InputError("The project has no raster: register the first photo of the viewpoint (e.g. with "
                            "Raster alignment), then import the others with this filter.");
  const int ref = s.reference_raster;
  require(ref < int(rasters.size()), kReferenceRaster,
          "must be -1 (the last raster) or a raster index from 0 to " + std::to_string(rasters.size() - 1));
  const size_t reference_index = ref < 0 ? rasters.size() - 1 : size_t(ref);
  const vbrdf::Raster &reference = rasters[reference_index];
  if (!vbrdf::shot_is_valid(reference.shot))
    throw vbrdf::InputError("Raster '" + reference.label + "' has no valid camera: register it first, or choose a "
                            "registered raster as reference.");

  const std::string project = project_path(run.document, *mesh);
  const std::vector<std::string> photos = photos_to_import(s, rasters, reference, project, log);
  check_sizes(photos, reference);
  const std::vector<vbrdf::Raster> added = new_rasters(photos, reference);
  std::vector<vbrdf::Raster> all = rasters;
  all.insert(all.end(), added.begin(), added.end());

  // Lights first: a failure leaves the document unchanged.
  std::string light_file;
  if (!added.empty())
    light_file = s.lights_from_sphere ? lights_from_sphere(s, rasters, added, reference_index, project, log)
                                      : lights_from_file(s, all, project);
  for (const vbrdf::Raster &r : added) add_raster(run.document, r.image_path, r.shot, r.label);
  log("Vertex BRDF import: " + std::to_string(added.size()) + " new photo(s) added with the camera of raster '" +
      reference.label + "'" + (light_file.empty() ? std::string(" (no new photo found)") : "; lights: " + light_file) +
      ". Save the project to keep them.");

  if (s.update_coverage) {
    vbrdf::CoverageSettings settings = CoverageFilter::default_settings();
    settings.light_file = light_file;  // "" = the coverage filter's own search
    CoverageFilter::run_on_document(run, settings, CoverageFilter::Display());
  }
}

} // namespace vbrdf_plugin
