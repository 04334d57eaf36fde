#include "fit_filter.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/errors.h"
#include "core/result_schema.h"
#include "meshlab_bridge.h"

namespace vbrdf_plugin {

namespace {

// Parameter names: the .mlx scripts refer to them, never rename.
const char *const kLightFile = "lightFile";
const char *const kOutputPly = "outputPly";
const char *const kSpecularThreshold = "specularThreshold";
const char *const kDiffuseThreshold = "diffuseThreshold";
const char *const kPhotoEncoding = "photoEncoding";
const char *const kSaturationLevel = "saturationLevel";
const char *const kVisibilityBackend = "visibilityBackend";
const char *const kDepthTolerance = "depthTolerance";
const char *const kShadowMapSize = "shadowMapSize";
const char *const kMemoryBudgetMB = "memoryBudgetMB";
const char *const kFitReflectance = "fitReflectance";
const char *const kFitBackend = "fitBackend";
const char *const kInitialShininess = "initialShininess";
const char *const kMaxIterations = "maxIterations";
const char *const kMinSpecularSamples = "minSpecularSamples";
const char *const kFillUnseenRings = "fillUnseenRings";
const char *const kQualityOutput = "qualityOutput";
const char *const kColorCorrection = "colorCorrection";
const char *const kChartCorners = "chartCorners";
const char *const kExposureNormalisation = "exposureNormalisation";

void require(bool ok, const char *param, const std::string &what) {
  if (!ok) throw vbrdf::InputError(std::string("Parameter '") + param + "' " + what);
}

// "x1 y1 ... x4 y4" (spaces, commas or semicolons between numbers), 8 per viewpoint; "" = detect.
std::vector<float> parse_corners(const QString &text) {
  QString cleaned = text;
  cleaned.replace(',', ' ').replace(';', ' ');
  std::vector<float> values;
  for (const QString &word : cleaned.split(' ', QString::SkipEmptyParts)) {
    bool ok = false;
    const float v = word.toFloat(&ok);
    require(ok && std::isfinite(v), kChartCorners,
            "must be numbers (x y of the dark skin, bluish green, black and white patch centres); '" +
                word.toStdString() + "' is not a number");
    values.push_back(v);
  }
  require(values.size() % 8 == 0, kChartCorners,
          "needs 8 numbers per viewpoint (x y of 4 patch centres), got " + std::to_string(values.size()));
  return values;
}

std::string color_summary(const vbrdf::FitSettings &settings, const vbrdf::FitResult &result) {
  if (settings.color_correction == vbrdf::ColorCorrectionChoice::Off) return "off";
  if (result.color_viewpoints_corrected == 0) {
    const bool located = std::any_of(result.colors.begin(), result.colors.end(),
                                     [](const vbrdf::ColorCalibration &c) { return !c.patches.empty(); });
    return located ? "chart not usable, colours uncorrected" : "no chart found, colours uncorrected";
  }
  return std::to_string(result.color_viewpoints_corrected) + " of " + std::to_string(result.colors.size()) +
         " viewpoint(s) corrected from the chart";
}

} // namespace

QString FitFilter::name() const { return "Vertex BRDF: fit per-vertex reflectance"; }

QString FitFilter::info() const {
  return "Fits a Phong reflectance model (colour C, diffuse k<sub>d</sub>, specular k<sub>s</sub>, "
         "shininess &alpha;) to every vertex from the registered photos of the project (the raster layers), "
         "each taken under a different, known light direction (an RTI/photometric-stereo capture; several "
         "viewpoints may be mixed).<br><br>"
         "Light directions are read from an <i>.lp</i> file (RTIBuilder/Relight format: one line per photo, "
         "<code>image lx ly lz</code>, direction towards the light in the camera frame). For each vertex "
         "and photo the filter tests visibility from the camera and cast shadows from the light (OpenGL "
         "depth passes, or a CPU ray cast), samples the photo, and discards shadowed, grazing "
         "(N&middot;L below the diffuse threshold), specular (R&middot;E above the specular threshold) and "
         "saturated samples for a first diffuse colour, then fits f = k<sub>d</sub> (N&middot;L) C + "
         "k<sub>s</sub> (R&middot;E)<sup>&alpha;</sup> to all lit, unsaturated samples (weighted by N&middot;L; "
         "on the GPU with a compute shader when MeshLab's OpenGL context allows, else on the CPU). Vertices "
         "with too little specular evidence get a diffuse-only fit (k<sub>s</sub> = 0).<br><br>"
         "Results: vertex colours become the fitted albedo (sRGB; vertices no photo sees keep their "
         "colour), vertex quality the chosen fit quality, the per-vertex values are stored as float "
         "attributes (" + QString::fromStdString(vbrdf::result_attribute_names()) + "; diffuse_r/g/b = "
         "k<sub>d</sub> C) and written with the geometry to a PLY, plus a text "
         "report beside it. The mesh geometry is not changed. The mesh needs per-vertex normals; photos "
         "must be undistorted.<br><br>"
         "Colour correction: when a 24-patch ColorChecker is in the photos of a viewpoint (detected, or "
         "located by its corner patches), a colour correction fitted to the chart (3x3 matrix, tone curve + "
         "matrix or per-channel polynomial, whichever predicts held-out patches best) is applied to every "
         "sample in linear space before the fit, and the photos' exposure is normalised by the chart's neutral "
         "patches (per photo when the light intensity varies). The albedo is then a reflectance in linear sRGB "
         "without the camera's colour cast. Without a chart the reflectance is known up to one global scale "
         "(unknown light intensity and exposure) and the camera's colours.";
}

MeshFilterInterface::FilterClass FitFilter::filterClass() const {
  return MeshFilterInterface::FilterClass(MeshFilterInterface::Camera | MeshFilterInterface::VertexColoring);
}

int FitFilter::requirements() const { return MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTQUALITY; }

int FitFilter::preConditions() const { return MeshModel::MM_FACENUMBER; }

int FitFilter::postConditions() const { return MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTQUALITY; }

void FitFilter::initParameters(const MeshDocument &, RichParameterList &params) const {
  params.addParam(RichOpenFile(
      kLightFile, "", QStringList("Light positions (*.lp)"), "Light file (.lp)",
      "RTI light file: first line the number of photos, then one line per photo: image file name and the "
      "unit direction towards the light (x right, y up, z towards the camera). Photos are matched by file "
      "name. Empty: the most recently modified *.lp beside the project or the photos that has an entry for "
      "every photo (the rule of every Vertex BRDF filter)."));
  params.addParam(RichSaveFile(
      kOutputPly, "", "PLY (*.ply)", "Output PLY",
      "Where the mesh with the per-vertex results is written (binary PLY with float properties), with a "
      "report beside it (same name ending in _report.txt). Relative paths are relative to the "
      "project folder. Empty: the project's name followed by _brdf.ply, beside the project."));
  params.addParam(RichFloat(kSpecularThreshold, 0.9f, "Specular threshold (R.E)",
                            "A lit sample whose mirror direction R is this close to the view direction E "
                            "(R.E above the threshold, in (0,1]) is a highlight: excluded from the diffuse "
                            "colour, counted as specular evidence."));
  params.addParam(RichFloat(kDiffuseThreshold, vbrdf::kFitDiffuseThreshold, "Diffuse threshold (N.L)",
                            "Samples lit at a grazing angle (N.L below the threshold, in [0,1)) are not used "
                            "for the diffuse colour and the fit while a vertex has others: they are noisy "
                            "and sensitive to normal errors. 0.2 measured best (the thesis used 0.5)."));
  params.addParam(RichEnum(kPhotoEncoding, 0, QStringList() << "Auto" << "sRGB (8-bit)" << "Linear",
                           "Photo encoding",
                           "How photo values map to light. Auto: 8-bit photos are sRGB-encoded (camera "
                           "JPEG/PNG), 16-bit photos are linear. sRGB: decode with the sRGB curve. Linear: "
                           "values are proportional to radiance (e.g. 16-bit from RAW)."));
  params.addParam(RichFloat(kSaturationLevel, 0.99f, "Saturation level",
                            "Fraction of the maximum code value (in (0,1]) at or above which a channel counts "
                            "as clipped; samples touching a clipped pixel are not used."));
  params.addParam(RichEnum(kVisibilityBackend, 0, QStringList() << "Auto" << "GPU (OpenGL)" << "CPU (ray cast)",
                           "Visibility",
                           "How occlusion from the camera and cast shadows from each light are computed. "
                           "Auto: OpenGL depth passes in MeshLab's context when it supports them, else the "
                           "CPU. CPU: exact ray casting (slower)."));
  params.addParam(RichFloat(kDepthTolerance, 0.002f, "Depth tolerance",
                            "A vertex counts as visible (or lit) when it is at most this far behind the first "
                            "surface along the ray, as a fraction of the bounding-box diagonal."));
  params.addParam(RichInt(kShadowMapSize, 0, "Shadow map size",
                          "Resolution (pixels per side) of the depth map rendered from each light direction "
                          "over the mesh bounds (OpenGL visibility). 0: automatic, from the mesh's edge "
                          "length (a texel about a quarter of an edge, 1024 to 4096)."));
  params.addParam(RichInt(kMemoryBudgetMB, 2048, "Photo memory (MB)",
                          "Decoded photos kept in memory at once; photos beyond it are reloaded when "
                          "needed."));
  params.addParam(RichBool(kFitReflectance, true, "Fit Phong reflectance",
                           "Fit k_d, k_s, shininess and colour per vertex. Off: only the basic diffuse colour "
                           "(faster; kd/ks/shininess attributes are not written)."));
  params.addParam(RichEnum(kFitBackend, 0, QStringList() << "Auto" << "GPU (compute shader)" << "CPU (reference)",
                           "Fit back end",
                           "Where the per-vertex fit runs. Auto: a GLSL compute shader in MeshLab's OpenGL "
                           "context when it supports OpenGL 4.3, else the CPU (double precision). Both give "
                           "the same result to about 1e-3."));
  params.addParam(RichFloat(kInitialShininess, 10.0f, "Initial shininess",
                            "Starting value of the Phong exponent alpha (the fit also tries an estimate from "
                            "the highlight samples and keeps the better one). Range [1, 2000]."));
  params.addParam(RichInt(kMaxIterations, 50, "Max iterations",
                          "Cap on the shininess updates per vertex (each followed by an exact re-solve of "
                          "k_d, k_s and colour). Converged vertices stop earlier. 0: initial estimate only."));
  params.addParam(RichInt(kMinSpecularSamples, 2, "Min specular samples",
                          "Highlight samples (R.E above the specular threshold, lit, unsaturated) a vertex "
                          "needs before k_s and shininess are fitted; with fewer the vertex gets a "
                          "diffuse-only fit (k_s = 0). Guards against 'diffuse holes' (k_d ~ 0, huge k_s)."));
  params.addParam(RichInt(kFillUnseenRings, 0, "Fill unseen gaps (rings)",
                          "Vertices no photo sees keep no model and their input colour. Give N > 0 to let "
                          "those within N edges of a modelled vertex take their neighbours' parameters "
                          "(fit_status 3, like seen vertices without a usable sample, which are always filled). "
                          "0 = off."));
  params.addParam(RichEnum(kQualityOutput, 0, QStringList() << "Diffuse quality (DQ)" << "Specular quality (SQ)"
                                                             << "Fit RMSE",
                           "Vertex quality",
                           "What is stored in vertex quality, for Render > Color > Per Vertex Quality: the "
                           "thesis's diffuse or specular quality (0..2, higher is better) or the weighted "
                           "fit RMSE (lower is better)."));
  params.addParam(RichEnum(kColorCorrection, 1, QStringList() << "Off" << "Auto (use a chart if found)" << "Required",
                           "Colour correction",
                           "Correct the photos' colours and exposure from a 24-patch ColorChecker (Classic, Mini, "
                           "Passport) visible in the photos of each viewpoint, in linear space, before the fit. "
                           "Auto: viewpoints whose photos show a chart are corrected, the others are fitted "
                           "uncorrected (the log says which). Required: a viewpoint without a usable chart is an "
                           "error. Off: photos are used as decoded."));
  params.addParam(RichString(kChartCorners, "", "Chart corner patches (px)",
                             "Only if the chart is not detected: centres of the chart's four corner patches in the "
                             "first photo of the viewpoint, in image pixels (x right, y down from the top-left "
                             "corner), in the order dark skin, bluish green, black, white: \"x1 y1 x2 y2 x3 y3 x4 "
                             "y4\". Several viewpoints: 8 numbers for all, or 8 per viewpoint in raster order. "
                             "Empty: detect the chart automatically."));
  params.addParam(RichEnum(kExposureNormalisation, 0,
                           QStringList() << "Auto" << "Off (one exposure)" << "On (each photo by its chart)",
                           "Exposure normalisation",
                           "With colour correction: how the photos' brightness is normalised by the chart's grey "
                           "patches. Auto: one exposure for all photos when the chart's brightness follows its "
                           "angle to the light (constant light intensity), else each photo by its own chart "
                           "(varying intensity, e.g. a hand-held flash). On: always per photo. Off: never."));
}

vbrdf::FitSettings FitFilter::settings_from(const RichParameterList &params) {
  vbrdf::FitSettings s;
  s.light_file = params.getOpenFileName(kLightFile).toUtf8().toStdString();
  s.output_ply = params.getSaveFileName(kOutputPly).toUtf8().toStdString();

  const float specular = params.getFloat(kSpecularThreshold);
  require(specular > 0.0f && specular <= 1.0f, kSpecularThreshold, "must be in (0, 1]");
  const float diffuse = params.getFloat(kDiffuseThreshold);
  require(diffuse >= 0.0f && diffuse < 1.0f, kDiffuseThreshold, "must be in [0, 1)");
  const int encoding = params.getEnum(kPhotoEncoding);
  require(encoding >= 0 && encoding <= 2, kPhotoEncoding, "must be 0 (Auto), 1 (sRGB) or 2 (Linear)");
  const float saturation = params.getFloat(kSaturationLevel);
  require(saturation > 0.0f && saturation <= 1.0f, kSaturationLevel, "must be in (0, 1]");
  const int backend = params.getEnum(kVisibilityBackend);
  require(backend >= 0 && backend <= 2, kVisibilityBackend, "must be 0 (Auto), 1 (GPU) or 2 (CPU)");
  const float tolerance = params.getFloat(kDepthTolerance);
  require(std::isfinite(tolerance) && tolerance > 0.0f && tolerance < 1.0f, kDepthTolerance, "must be in (0, 1)");
  const int map_size = params.getInt(kShadowMapSize);
  require(map_size == 0 || (map_size >= 64 && map_size <= 16384), kShadowMapSize, "must be 0 (automatic) or in [64, 16384]");
  const int budget = params.getInt(kMemoryBudgetMB);
  require(budget >= 16, kMemoryBudgetMB, "must be at least 16");
  const int fit_backend = params.getEnum(kFitBackend);
  require(fit_backend >= 0 && fit_backend <= 2, kFitBackend, "must be 0 (Auto), 1 (GPU) or 2 (CPU)");
  const float alpha0 = params.getFloat(kInitialShininess);
  require(alpha0 >= s.phong.alpha_min && alpha0 <= s.phong.alpha_max, kInitialShininess, "must be in [1, 2000]");
  const int iterations = params.getInt(kMaxIterations);
  require(iterations >= 0 && iterations <= 10000, kMaxIterations, "must be in [0, 10000]");
  const int min_specular = params.getInt(kMinSpecularSamples);
  require(min_specular >= 1 && min_specular <= 1000, kMinSpecularSamples, "must be in [1, 1000]");
  const int fill_rings = params.getInt(kFillUnseenRings);
  require(fill_rings >= 0 && fill_rings <= 1000, kFillUnseenRings, "must be in [0, 1000]");
  const int quality = params.getEnum(kQualityOutput);
  require(quality >= 0 && quality <= 2, kQualityOutput, "must be 0 (DQ), 1 (SQ) or 2 (RMSE)");
  const int color = params.getEnum(kColorCorrection);
  require(color >= 0 && color <= 2, kColorCorrection, "must be 0 (Off), 1 (Auto) or 2 (Required)");
  const int exposure = params.getEnum(kExposureNormalisation);
  require(exposure >= 0 && exposure <= 2, kExposureNormalisation, "must be 0 (Auto), 1 (Off) or 2 (On)");

  s.gather.specular_threshold = specular;
  s.gather.diffuse_threshold = diffuse;
  s.gather.encoding = vbrdf::PhotoEncoding(encoding);  // same order as the enum's entries
  s.gather.saturation_level = saturation;
  s.gather.photo_cache_bytes = size_t(budget) << 20;
  s.visibility_choice = vbrdf::VisibilityChoice(backend);
  s.visibility.depth_tolerance = tolerance;
  s.visibility.shadow_map_size = map_size;
  s.fit_reflectance = params.getBool(kFitReflectance);
  s.fit_backend = vbrdf::FitBackendChoice(fit_backend);
  s.phong.alpha_init = alpha0;
  s.phong.max_iterations = iterations;
  s.phong.min_specular_samples = min_specular;
  s.fill_unseen_rings = fill_rings;
  s.quality = vbrdf::QualityOutput(quality);
  s.color_correction = vbrdf::ColorCorrectionChoice(color);  // same order as the enum's entries
  s.chart_corners = parse_corners(params.getString(kChartCorners));
  s.exposure = vbrdf::ExposureMode(exposure);               // same order as the enum's entries
  return s;
}

void FitFilter::apply(FilterRun &run) const {
  MeshModel *mesh = run.document.mm();
  if (mesh == nullptr)
    throw vbrdf::InputError("No current mesh: open the registered mesh (or its .mlp project) first.");
  const auto log = [&run](const std::string &line) { run.log(GLLogStream::FILTER, line); };

  vbrdf::FitSettings settings = settings_from(run.params);
  const MeshArrays arrays = mesh_arrays(*mesh);
  if (arrays.transformed)
    log("Vertex BRDF: the layer has a transformation matrix; the fit (and the output PLY) use the "
        "transformed, world coordinates in which the rasters are registered.");
  vbrdf::FitInput input;
  input.mesh = arrays.data.view();
  input.mesh_name = mesh->label().toUtf8().toStdString();
  input.mesh_path = mesh->fullName().toUtf8().toStdString();
  input.mesh_colors = arrays.data.colors;
  input.rasters = document_rasters(run.document);
  input.project_path = project_path(run.document, *mesh);
  settings.light_file = resolve_path(settings.light_file, input.project_path);
  settings.output_ply = resolve_path(settings.output_ply, input.project_path);

  // Bad input is reported before any GL work (run_fit checks again, cheaply).
  vbrdf::validate_input(input);

  vbrdf::FitResult result;
  {
    // The GL back end needs the context current for its whole life: destroy it inside the scope.
    const bool gpu_fit = settings.fit_reflectance && settings.fit_backend != vbrdf::FitBackendChoice::CPU;
    const bool needs_gl = settings.visibility_choice != vbrdf::VisibilityChoice::CPU || gpu_fit;
    GlContextScope gl(needs_gl ? run.gl_context : nullptr, log);
    std::unique_ptr<vbrdf::VisibilityBackend> visibility = vbrdf::make_visibility_backend(
        input.mesh, settings, settings.visibility_choice == vbrdf::VisibilityChoice::CPU ? nullptr : gl.get_proc(), log);
    std::unique_ptr<vbrdf::PhongFitter> fitter;
    if (settings.fit_reflectance) fitter = vbrdf::make_phong_fitter(settings, gl.get_proc(), log);
    result = vbrdf::run_fit(input, settings, *visibility, fitter.get(), progress_adapter(run.progress, "Vertex BRDF: "),
                            log);
  }
  store_results(*mesh, arrays, result.colors_rgba, settings.fit_reflectance ? result.quality : std::vector<float>(),
                result.attributes);

  std::ostringstream summary;
  summary << "Vertex BRDF: " << result.vertices_coloured << " of " << arrays.vertex_index.size()
          << " vertices coloured, " << result.vertices_unseen << " seen by no photo, " << result.vertices_no_diffuse
          << " seen but without usable sample; " << result.fit_full << " full Phong fits, " << result.fit_diffuse_only
          << " diffuse-only (visibility: " << result.visibility_backend << ", fit: "
          << (result.fit_backend.empty() ? std::string("off") : result.fit_backend) << ", lights: " << result.light_file
          << ", colour correction: " << color_summary(settings, result) << "). Wrote " << result.output_ply;
  log(summary.str());
}

} // namespace vbrdf_plugin
