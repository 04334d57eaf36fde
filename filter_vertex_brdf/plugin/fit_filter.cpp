#include "fit_filter.h"

#include <cmath>
#include <sstream>

#include "core/errors.h"
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

void require(bool ok, const char *param, const std::string &what) {
  if (!ok) throw vbrdf::InputError(std::string("Parameter '") + param + "' " + what);
}

} // namespace

QString FitFilter::name() const { return "Vertex BRDF: fit per-vertex reflectance"; }

QString FitFilter::info() const {
  return "Estimates the diffuse reflectance (albedo) of every vertex from the registered photos of the "
         "project (the raster layers), each taken from a fixed camera under a different, known light "
         "direction (an RTI/photometric-stereo capture).<br><br>"
         "Light directions are read from an <i>.lp</i> file (RTIBuilder/Relight format: one line per photo, "
         "<code>image lx ly lz</code>, direction towards the light in the camera frame). For each vertex "
         "and photo the filter tests visibility from the camera and cast shadows from the light (OpenGL "
         "depth passes, or a CPU ray cast), samples the photo, and discards shadowed, grazing "
         "(N&middot;L below the diffuse threshold), specular (R&middot;E above the specular threshold) and "
         "saturated samples. The albedo is the least-squares fit of the remaining samples to a Lambertian "
         "model.<br><br>"
         "Results: vertex colours become the fitted albedo (sRGB; vertices no photo sees keep their "
         "colour), the per-vertex values are stored as float attributes (diffuse_r/g/b, n_visible, "
         "n_diffuse, n_specular, coloured, ...) and written with the geometry to a PLY, plus a text "
         "report beside it. The mesh geometry is not changed. The mesh needs per-vertex normals; photos "
         "must be undistorted.<br><br>"
         "Reflectance is known up to one global scale (unknown light intensity and exposure).";
}

MeshFilterInterface::FilterClass FitFilter::filterClass() const {
  return MeshFilterInterface::FilterClass(MeshFilterInterface::Camera | MeshFilterInterface::VertexColoring);
}

int FitFilter::requirements() const { return MeshModel::MM_VERTCOLOR; }

int FitFilter::preConditions() const { return MeshModel::MM_FACENUMBER; }

int FitFilter::postConditions() const { return MeshModel::MM_VERTCOLOR; }

void FitFilter::initParameters(const MeshDocument &, RichParameterList &params) const {
  params.addParam(RichOpenFile(
      kLightFile, "", QStringList("Light positions (*.lp)"), "Light file (.lp)",
      "RTI light file: first line the number of photos, then one line per photo: image file name and the "
      "unit direction towards the light (x right, y up, z towards the camera). Photos are matched by file "
      "name. Empty: the first *.lp beside the project, else beside the first photo."));
  params.addParam(RichSaveFile(
      kOutputPly, "", "PLY (*.ply)", "Output PLY",
      "Where the mesh with the per-vertex results is written (binary PLY with float properties), with a "
      "report beside it (same name ending in _report.txt). Relative paths are relative to the "
      "project folder. Empty: the project's name followed by _brdf.ply, beside the project."));
  params.addParam(RichFloat(kSpecularThreshold, 0.9f, "Specular threshold (R.E)",
                            "A lit sample whose mirror direction R is this close to the view direction E "
                            "(R.E above the threshold, in (0,1]) is a highlight: excluded from the diffuse "
                            "colour, counted as specular evidence."));
  params.addParam(RichFloat(kDiffuseThreshold, 0.5f, "Diffuse threshold (N.L)",
                            "Samples lit at a grazing angle (N.L below the threshold, in [0,1)) are not used "
                            "for the diffuse colour: they are noisy and sensitive to normal errors."));
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
  params.addParam(RichInt(kShadowMapSize, 2048, "Shadow map size",
                          "Resolution (pixels per side) of the depth map rendered from each light direction "
                          "over the mesh bounds (OpenGL visibility)."));
  params.addParam(RichInt(kMemoryBudgetMB, 2048, "Photo memory (MB)",
                          "Decoded photos kept in memory at once; photos beyond it are reloaded when "
                          "needed."));
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
  require(map_size >= 64 && map_size <= 16384, kShadowMapSize, "must be in [64, 16384]");
  const int budget = params.getInt(kMemoryBudgetMB);
  require(budget >= 16, kMemoryBudgetMB, "must be at least 16");

  s.gather.specular_threshold = specular;
  s.gather.diffuse_threshold = diffuse;
  s.gather.encoding = vbrdf::PhotoEncoding(encoding);  // same order as the enum's entries
  s.gather.saturation_level = saturation;
  s.gather.photo_cache_bytes = size_t(budget) << 20;
  s.visibility_choice = vbrdf::VisibilityChoice(backend);
  s.visibility.depth_tolerance = tolerance;
  s.visibility.shadow_map_size = map_size;
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
    GlContextScope gl(settings.visibility_choice == vbrdf::VisibilityChoice::CPU ? nullptr : run.gl_context, log);
    std::unique_ptr<vbrdf::VisibilityBackend> visibility =
        vbrdf::make_visibility_backend(input.mesh, settings, gl.get_proc(), log);
    result = vbrdf::run_fit(input, settings, *visibility, progress_adapter(run.progress, "Vertex BRDF: "), log);
  }
  store_results(*mesh, arrays, result.colors_rgba, result.attributes);

  std::ostringstream summary;
  summary << "Vertex BRDF: " << result.vertices_coloured << " of " << arrays.vertex_index.size()
          << " vertices coloured, " << result.vertices_unseen << " seen by no photo, " << result.vertices_no_diffuse
          << " seen but without diffuse sample (visibility: " << result.visibility_backend
          << ", lights: " << result.light_file << "). Wrote " << result.output_ply;
  log(summary.str());
}

} // namespace vbrdf_plugin
