#include "filter_parameters.h"

#include <cmath>

#include <QDir>
#include <QFileInfo>

#include "core/base/errors.h"
#include "meshlab_bridge.h"

namespace vbrdf_plugin {

void require(bool ok, const char *param, const std::string &what) {
  if (!ok) throw vbrdf::InputError(std::string("Parameter '") + param + "' " + what);
}

std::vector<float> parse_corners(const QString &text, const char *param) {
  QString cleaned = text;
  cleaned.replace(',', ' ').replace(';', ' ');
  std::vector<float> values;
  for (const QString &word : cleaned.split(' ', QString::SkipEmptyParts)) {
    bool ok = false;
    const float v = word.toFloat(&ok);
    require(ok && std::isfinite(v), param,
            "must be numbers (x y of the dark skin, bluish green, black and white patch centres); '" + utf8(word) +
                "' is not a number");
    values.push_back(v);
  }
  require(values.size() % 8 == 0, param,
          "needs 8 numbers per viewpoint (x y of 4 patch centres), got " + std::to_string(values.size()));
  return values;
}

void add_path(RichParameterList &params, const char *name, const QString &label, const QString &tooltip) {
  params.addParam(RichString(name, "", label, tooltip + " Type or paste the path (absolute, or relative to the project folder)."));
}

std::string path(const RichParameterList &params, const char *name) {
  QString text;
  require(host::text_value(params.getParameterByName(name).value(), text), name, "must be a path (text)");
  return utf8(text.trimmed());
}

std::string with_labels(const std::string &message, const RichParameterList &params) {
  std::string out = message;
  for (const RichParameter &p : params) {
    const std::string quoted = "'" + utf8(p.name()) + "'";
    const std::string labelled = "'" + utf8(p.fieldDescription()) + "' [" + utf8(p.name()) + "]";
    for (size_t at = out.find(quoted); at != std::string::npos; at = out.find(quoted, at + labelled.size()))
      out.replace(at, quoted.size(), labelled);
  }
  return out;
}

namespace shared {

const char *const kLightFile = "lightFile";
const char *const kDomeRadius = "domeRadius";
const char *const kLightUnitScale = "lightUnitScale";
const char *const kSpecularThreshold = "specularThreshold";
const char *const kDiffuseThreshold = "diffuseThreshold";
const char *const kPhotoEncoding = "photoEncoding";
const char *const kSaturationLevel = "saturationLevel";
const char *const kVisibilityBackend = "visibilityBackend";
const char *const kDepthTolerance = "depthTolerance";
const char *const kShadowMapSize = "shadowMapSize";
const char *const kMemoryBudgetMB = "memoryBudgetMB";
const char *const kMinSpecularSamples = "minSpecularSamples";
const char *const kViewpointRaster = "viewpointRaster";
const char *const kSphereCenterX = "sphereCenterX";
const char *const kSphereCenterY = "sphereCenterY";
const char *const kSphereRadius = "sphereRadius";
const char *const kOutputLightFile = "outputLightFile";
const char *const kColorCorrection = "colorCorrection";
const char *const kChartCorners = "chartCorners";
const char *const kExposureNormalisation = "exposureNormalisation";
const char *const kOnlySelected = "onlySelectedVertices";
const char *const kQualityOutput = "qualityOutput";

namespace {

// An enum parameter's value, checked against its entry count (the core's enums share the order).
int enum_value(const RichParameterList &params, const char *name, int count, const char *entries) {
  const int v = params.getEnum(name);
  require(v >= 0 && v < count, name, std::string("must be ") + entries);
  return v;
}

} // namespace

// --- Light file ---------------------------------------------------------------------------------

void add_light_file(RichParameterList &params) {
  add_path(
      params, kLightFile, "Light file (.lp, .json, .dome)",
      "Each photo's light. RTI .lp: first line the number of photos, then one line per photo: image file name "
      "and the unit direction towards the light (x right, y up, z towards the camera): distant lights, or "
      "lights on a dome with 'Dome radius'. Near lights (a dome, a flash or a lamp within a few object sizes): "
      ".json with \"images\" and \"position_world\" (mesh frame and units) or \"position_camera\" (each "
      "photo's camera frame), or a Relight .dome (cm: set 'Light unit scale'). Photos are matched by file "
      "name. Empty: the most recently modified *.lp beside the project or the photos that has an entry for "
      "every raster (the rule of every Vertex BRDF filter).");
}

void add_light_placement(RichParameterList &params) {
  params.addParam(RichFloat(kDomeRadius, 0.0f, "Dome radius (mesh units)",
                            "0: the .lp's directions are distant lights (one direction for the whole object). "
                            "> 0: they are point lights on a dome of this radius around the mesh's centre, so "
                            "that each vertex gets its own light direction and a 1/distance^2 fall-off. Use it "
                            "when the lights are within about 10 object sizes "
                            "(docs/parameters.md#near-lights-light-positions)."));
  params.addParam(RichFloat(kLightUnitScale, 0.0f, "Light unit scale",
                            "Mesh units per unit of the light file's positions: 0 = the .json's positions are in "
                            "mesh units; a Relight .dome is in cm and needs it (10 for a mesh in mm, 0.01 for "
                            "metres)."));
}

void read_light_placement(const RichParameterList &params, float &dome_radius, float &unit_scale) {
  dome_radius = params.getFloat(kDomeRadius);
  unit_scale = params.getFloat(kLightUnitScale);
  require(std::isfinite(dome_radius) && dome_radius >= 0, kDomeRadius, "must be 0 (distant lights) or positive");
  require(std::isfinite(unit_scale) && unit_scale >= 0, kLightUnitScale, "must be 0 (not given) or positive");
}

std::string light_file(const RichParameterList &params) { return path(params, kLightFile); }

// --- Sample classification and photos -----------------------------------------------------------

void add_specular_threshold(RichParameterList &params) {
  params.addParam(RichFloat(kSpecularThreshold, vbrdf::kDefaultSpecularThreshold,
                            "Highlight threshold (R.E, any lobe)",
                            "A lit sample whose mirror direction R is this close to the view direction E "
                            "(R.E above the threshold, in (0,1]) is a highlight: excluded from the diffuse "
                            "colour, counted as specular evidence (and as specular coverage)."));
}

void add_diffuse_threshold(RichParameterList &params, DiffuseThresholdUse use) {
  const bool fit = use == DiffuseThresholdUse::Fit;
  const QString common = "A lit sample with N.L below the threshold (in [0,1)) is grazing: noisy and sensitive to "
                         "normal errors. ";
  params.addParam(RichFloat(
      kDiffuseThreshold, fit ? vbrdf::kFitDiffuseThreshold : vbrdf::kCoverageDiffuseThreshold, "Diffuse threshold (N.L)",
      common + (fit ? "The fit uses grazing samples for the diffuse colour and the fit only where a vertex has no "
                      "others. 0.2 measured best (the thesis used 0.5)."
                    : "It does not count as diffuse coverage. 0.5 (the thesis's value, above the fit's 0.2) asks "
                      "the photographer for well-lit samples.")));
}

void add_photo_encoding(RichParameterList &params) {
  params.addParam(RichEnum(kPhotoEncoding, int(vbrdf::PhotoEncoding::Auto),
                           QStringList() << "Auto" << "sRGB (8-bit)" << "Linear", "Photo encoding",
                           "How photo values map to light. Auto: 8-bit photos are sRGB-encoded (camera "
                           "JPEG/PNG), 16-bit photos are linear. sRGB: decode with the sRGB curve. Linear: "
                           "values are proportional to radiance (e.g. 16-bit from RAW)."));
}

vbrdf::PhotoEncoding photo_encoding(const RichParameterList &params) {
  return vbrdf::PhotoEncoding(enum_value(params, kPhotoEncoding, 3, "0 (Auto), 1 (sRGB) or 2 (Linear)"));
}

void add_shadow_map_size(RichParameterList &params) {
  params.addParam(RichInt(kShadowMapSize, vbrdf::kDefaultShadowMapSize, "Shadow map size",
                          "Resolution (pixels per side) of the depth map rendered from each light direction "
                          "over the mesh bounds (OpenGL visibility and cast shadows). 0: automatic, from the "
                          "mesh's edge length (a texel about a quarter of an edge, 1024 to 4096). Otherwise "
                          "[64, 16384]."));
}

int shadow_map_size(const RichParameterList &params) {
  const int size = params.getInt(kShadowMapSize);
  require(size == 0 || (size >= 64 && size <= 16384), kShadowMapSize, "must be 0 (automatic) or in [64, 16384]");
  return size;
}

void add_photo_and_visibility(RichParameterList &params) {
  add_photo_encoding(params);
  params.addParam(RichFloat(kSaturationLevel, vbrdf::kSaturationLevel, "Saturation level",
                            "Fraction of the maximum code value (in (0,1]) at or above which a channel counts "
                            "as clipped; samples touching a clipped pixel are not used (nor counted as "
                            "coverage)."));
  params.addParam(RichEnum(kVisibilityBackend, int(vbrdf::VisibilityChoice::Auto),
                           QStringList() << "Auto" << "GPU (OpenGL)" << "CPU (ray cast)", "Visibility",
                           "How occlusion from the camera and cast shadows from each light are computed. "
                           "Auto: OpenGL depth passes in MeshLab's context when it supports them, else the "
                           "CPU. CPU: exact ray casting (slower)."));
  params.addParam(RichFloat(kDepthTolerance, vbrdf::kDefaultDepthTolerance, "Depth tolerance",
                            "A vertex counts as visible (or lit) when it is at most this far behind the first "
                            "surface along the ray, as a fraction of the bounding-box diagonal."));
  add_shadow_map_size(params);
  params.addParam(RichInt(kMemoryBudgetMB, int(vbrdf::GatherSettings().photo_cache_bytes >> 20), "Photo memory (MB)",
                          "Decoded photos kept in memory at once; photos beyond it are reloaded when "
                          "needed. The rasters' images MeshLab has already loaded are read in place and "
                          "take none of it. At least 16."));
}

void read_gather(const RichParameterList &params, vbrdf::GatherSettings &gather) {
  const float specular = params.getFloat(kSpecularThreshold);
  require(specular > 0.0f && specular <= 1.0f, kSpecularThreshold, "must be in (0, 1]");
  const float diffuse = params.getFloat(kDiffuseThreshold);
  require(diffuse >= 0.0f && diffuse < 1.0f, kDiffuseThreshold, "must be in [0, 1)");
  const float saturation = params.getFloat(kSaturationLevel);
  require(saturation > 0.0f && saturation <= 1.0f, kSaturationLevel, "must be in (0, 1]");
  const int budget = params.getInt(kMemoryBudgetMB);
  require(budget >= 16, kMemoryBudgetMB,
          "('Photo memory (MB)') must be at least 16: raise it (photos beyond it are decoded again when needed).");
  gather.specular_threshold = specular;
  gather.diffuse_threshold = diffuse;
  gather.encoding = photo_encoding(params);
  gather.saturation_level = saturation;
  gather.photo_cache_bytes = size_t(budget) << 20;
}

void read_visibility(const RichParameterList &params, vbrdf::VisibilityChoice &choice,
                     vbrdf::VisibilitySettings &visibility) {
  choice = vbrdf::VisibilityChoice(enum_value(params, kVisibilityBackend, 3, "0 (Auto), 1 (GPU) or 2 (CPU)"));
  const float tolerance = params.getFloat(kDepthTolerance);
  require(std::isfinite(tolerance) && tolerance > 0.0f && tolerance < 1.0f, kDepthTolerance, "must be in (0, 1)");
  visibility.depth_tolerance = tolerance;
  visibility.shadow_map_size = shadow_map_size(params);
}

// --- Coverage and fit ---------------------------------------------------------------------------

void add_min_specular_samples(RichParameterList &params) {
  params.addParam(RichInt(kMinSpecularSamples, vbrdf::kDefaultMinSpecularSamples, "Min specular samples",
                          "Highlight samples (R.E above the specular threshold, lit, unsaturated) a vertex "
                          "needs before k_s and shininess are fitted; with fewer the fit gives it a "
                          "diffuse-only model (k_s = 0), which guards against 'diffuse holes' (k_d ~ 0, huge "
                          "k_s). Coverage counts a vertex as fully covered from the same number, so that "
                          "'fully covered' means a full fit. Range [1, 1000]."));
}

int min_specular_samples(const RichParameterList &params) {
  const int n = params.getInt(kMinSpecularSamples);
  require(n >= 1 && n <= 1000, kMinSpecularSamples, "must be in [1, 1000]");
  return n;
}

// --- Vertex quality -----------------------------------------------------------------------------

void add_quality_output(RichParameterList &params) {
  params.addParam(RichEnum(kQualityOutput, int(vbrdf::QualityOutput::DQ),
                           QStringList() << "Diffuse quality (DQ)" << "Specular quality (SQ)" << "Fit RMSE",
                           "Vertex quality",
                           "What goes into vertex quality: DQ or SQ (0..2, higher is better) or the fit RMSE (lower "
                           "is better). Vertices without a model get the median of the others."));
}

vbrdf::QualityOutput quality_output(const RichParameterList &params) {
  return vbrdf::QualityOutput(enum_value(params, kQualityOutput, 3, "0 (DQ), 1 (SQ) or 2 (RMSE)"));
}

// --- Only on selection --------------------------------------------------------------------------

void add_only_selected(RichParameterList &params) {
  params.addParam(RichBool(kOnlySelected, false, "Only on selection",
                           "Work on the selected vertices only (as MeshLab's colour projection): the others take no "
                           "sample and keep their colours, quality and attributes in the document; in the fit's "
                           "PLY they have no model (fit_status 0). Off: every vertex."));
}

bool only_selected(const RichParameterList &params) { return params.getBool(kOnlySelected); }

std::vector<uint8_t> selection_mask(const MeshModel &mesh, const MeshArrays &arrays,
                                    const std::function<void(const std::string &)> &log) {
  size_t count = 0;
  std::vector<uint8_t> mask = selected_vertices(mesh, arrays, count);
  require(count > 0, kOnlySelected,
          "is on but no vertex of '" + utf8(mesh.label()) + "' is selected: select vertices (Edit > Select "
          "Vertices, or Filters > Selection) or turn it off");
  log("Vertex BRDF: only on selection: " + std::to_string(count) + " of " + std::to_string(mask.size()) +
      " vertices take part.");
  return mask;
}

void log_hidden_rasters(size_t hidden, size_t used, const std::function<void(const std::string &)> &log) {
  if (hidden == 0) return;
  log("Vertex BRDF: " + std::to_string(hidden) + " hidden raster(s) left out (only visible rasters take part, as in "
      "MeshLab's colour projection); " + std::to_string(used) + " used.");
}

// --- Viewpoint ----------------------------------------------------------------------------------

void add_viewpoint_raster(RichParameterList &params) {
  params.addParam(RichInt(kViewpointRaster, -1, "Viewpoint raster",
                          "The viewpoint (camera position: every raster sharing its camera) is that of this "
                          "raster, counted from 0 in the layer list; -1: MeshLab's current raster (the last "
                          "one loaded or imported, unless another is selected)."));
}

int viewpoint_raster(const RichParameterList &params) {
  const int r = params.getInt(kViewpointRaster);
  require(r >= -1, kViewpointRaster, "must be -1 (the current raster) or a raster index");
  return r;
}

size_t chosen_raster(MeshDocument &document, int param) {
  const int count = int(host::rasters(document).size());
  require(count > 0, kViewpointRaster, "needs a raster: the project has none");
  if (param >= 0) {
    require(param < count, kViewpointRaster,
            "is " + std::to_string(param) + " but the project has " + std::to_string(count) +
                " rasters (counted from 0; -1 = the current raster)");
    return size_t(param);
  }
  const int current = host::current_raster_index(document);
  return size_t(current >= 0 ? current : count - 1);
}

// --- Mirror sphere ------------------------------------------------------------------------------

void add_sphere_outline(RichParameterList &params) {
  params.addParam(RichFloat(kSphereCenterX, 0.0f, "Sphere centre x (px)",
                            "Centre of the mirror sphere's outline in the photos, in image pixels from the left "
                            "edge (x right, y down, as in an image viewer). Used when the radius is above 0."));
  params.addParam(RichFloat(kSphereCenterY, 0.0f, "Sphere centre y (px)",
                            "Centre of the sphere's outline, in image pixels from the top edge."));
  params.addParam(RichFloat(kSphereRadius, 0.0f, "Sphere radius (px)",
                            "Radius of the sphere's outline in image pixels. 0: find the sphere automatically; "
                            "above 0: use this outline and skip the detection."));
}

vbrdf::SphereCircle sphere_outline(const RichParameterList &params, const char *x, const char *y, const char *r) {
  const vbrdf::SphereCircle c{float(params.getFloat(x)), float(params.getFloat(y)), float(params.getFloat(r))};
  require(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.r) && c.r >= 0, r,
          "must be 0 (find the sphere automatically) or the sphere's radius in pixels (with a finite centre)");
  return c;
}

vbrdf::SphereCircle sphere_outline(const RichParameterList &params) {
  return sphere_outline(params, kSphereCenterX, kSphereCenterY, kSphereRadius);
}

void add_output_light_file(RichParameterList &params, OutputLightFileUse use) {
  const QString common = "Where the estimated light directions are written (RTI .lp: image name and unit direction "
                         "towards the light, x right, y up, z towards the camera), replacing the file atomically. "
                         "Relative paths are relative to the project folder. ";
  add_path(
      params, kOutputLightFile, "Output light file (.lp)",
      common + (use == OutputLightFileUse::Sphere
                    ? "Entries of other viewpoints' rasters already in it are kept. Empty: the project's name "
                      "followed by _sphere.lp, beside the project (sphere lights only)."
                    : "Sphere mode only: every entry of the light file above is kept. Empty: the project's name "
                      "followed by _lights.lp, beside the project (the acquisition's lights so far)."));
}

std::string output_light_file(const RichParameterList &params) {
  return path(params, kOutputLightFile);
}

std::string default_output_light_file(const std::string &project, OutputLightFileUse use) {
  const QFileInfo info(QString::fromStdString(project.empty() ? std::string("vertex_brdf") : project));
  const QString suffix = use == OutputLightFileUse::Sphere ? "_sphere.lp" : "_lights.lp";
  return utf8(QDir(info.absolutePath()).filePath(info.completeBaseName() + suffix));
}

// --- Colour correction --------------------------------------------------------------------------

void add_color_correction(RichParameterList &params) {
  params.addParam(RichEnum(kColorCorrection, int(vbrdf::ColorCorrectionChoice::Auto),
                           QStringList() << "Off" << "Auto (use a chart if found)" << "Required",
                           "Colour correction",
                           "Correct the photos' colours and exposure from a 24-patch ColorChecker (Classic, Mini, "
                           "Passport) visible in the photos of each viewpoint, in linear space: the fit corrects "
                           "its samples; relight, set as for the fit, corrects the compared photos the same way. "
                           "Auto: viewpoints whose photos show a chart are corrected, the others are used "
                           "uncorrected (the log says which). Required: a viewpoint without a usable chart is an "
                           "error. Off: photos are used as decoded."));
  params.addParam(RichString(kChartCorners, "", "Chart corner patches (px)",
                             "Only if the chart is not detected: centres of the chart's four corner patches in the "
                             "first photo of the viewpoint, in image pixels (x right, y down from the top-left "
                             "corner), in the order dark skin, bluish green, black, white: \"x1 y1 x2 y2 x3 y3 x4 "
                             "y4\". Several viewpoints: 8 numbers for all, or 8 per viewpoint in raster order. "
                             "Empty: detect the chart automatically."));
  params.addParam(RichEnum(kExposureNormalisation, int(vbrdf::ExposureMode::Auto),
                           QStringList() << "Auto" << "Off (one exposure)" << "On (each photo by its chart)",
                           "Exposure normalisation",
                           "With colour correction: how the photos' brightness is normalised by the chart's grey "
                           "patches. Auto: one exposure for all photos when the chart's brightness follows its "
                           "angle to the light (constant light intensity), else each photo by its own chart "
                           "(varying intensity, e.g. a hand-held flash). On: always per photo. Off: never."));
}

vbrdf::ColorCorrectionChoice color_correction(const RichParameterList &params) {
  return vbrdf::ColorCorrectionChoice(enum_value(params, kColorCorrection, 3, "0 (Off), 1 (Auto) or 2 (Required)"));
}

std::vector<float> chart_corners(const RichParameterList &params) {
  return parse_corners(params.getString(kChartCorners), kChartCorners);
}

vbrdf::ExposureMode exposure_normalisation(const RichParameterList &params) {
  return vbrdf::ExposureMode(enum_value(params, kExposureNormalisation, 3, "0 (Auto), 1 (Off) or 2 (On)"));
}

} // namespace shared
} // namespace vbrdf_plugin
