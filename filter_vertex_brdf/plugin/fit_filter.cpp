#include "fit_filter.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/base/errors.h"
#include "filter_parameters.h"
#include "host_photos.h"
#include "meshlab_bridge.h"

namespace vbrdf_plugin {

namespace {

// Parameter names of this filter only (the .mlx scripts refer to them, never rename); the shared
// ones are in filter_parameters.h.
const char *const kOutputPly = "outputPly";
const char *const kOverwriteOutput = "overwriteOutput";
const char *const kFitReflectance = "fitReflectance";
const char *const kFitBackend = "fitBackend";
const char *const kInitialShininess = "initialShininess";
const char *const kSpecularLobe = "specularLobe";
const char *const kDiffuseTerm = "diffuseTerm";
const char *const kFindMaterials = "findMaterials";
const char *const kMaxIterations = "maxIterations";
const char *const kSharpenAlbedo = "sharpenAlbedoEdges";
const char *const kRefineRegistration = "refineRegistration";
const char *const kRefineNormals = "refineNormals";
const char *const kFillUnseenRings = "fillUnseenRings";

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
  // Short on purpose: MeshLab 2020.09 puts this text above the fields, and a long one pushes Apply
  // off a 1000-pixel screen. The details are in docs/parameters.md and in each field's tooltip / Help.
  return "Fits reflectance (colour, k<sub>d</sub>, k<sub>s</sub>, shininess) to every vertex from the visible "
         "registered photos and their lights; colours the mesh with the albedo and writes a PLY with every "
         "per-vertex value and a report. Hover over a field, or press Help, for what it does.";
}

host::FilterInterface::FilterClass FitFilter::filterClass() const {
  return host::FilterInterface::FilterClass(host::FilterInterface::Camera | host::FilterInterface::VertexColoring);
}

int FitFilter::requirements() const { return MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTQUALITY; }

int FitFilter::preConditions() const { return MeshModel::MM_FACENUMBER; }

// MM_VERTNUMBER: MeshLab 2020.09 then offers no Preview (MeshlabStdDialog::isPreviewable), as for
// its own filters that return MM_ALL: a preview would re-run the whole fit and write the PLY on
// every change of a field. (The vertices are not changed; MeshLab only refreshes its buffers.)
int FitFilter::postConditions() const {
  return MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTQUALITY | MeshModel::MM_VERTNUMBER;
}

void FitFilter::initParameters(const MeshDocument &, RichParameterList &params) const {
  shared::add_light_file(params);
  shared::add_light_placement(params);
  add_path(
      params, kOutputPly, "Output PLY",
      "Where the mesh with the per-vertex results is written (binary PLY with float properties), with a "
      "report beside it (same name ending in _report.txt). Relative paths are relative to the "
      "project folder. Empty: the project's name followed by _brdf.ply, beside the project.");
  params.addParam(RichBool(kOverwriteOutput, true, "Overwrite existing output",
                           "On: an existing output PLY and report are replaced (atomically: the previous files "
                           "stay intact until the new ones are complete) and the log says so. Off: the filter "
                           "stops before any work when they exist. Input files are never overwritten."));
  shared::add_specular_threshold(params);
  shared::add_diffuse_threshold(params, shared::DiffuseThresholdUse::Fit);
  shared::add_photo_and_visibility(params);
  params.addParam(RichBool(kFitReflectance, true, "Fit reflectance",
                           "Fit k_d, k_s, shininess and colour per vertex. Off: only the basic diffuse colour "
                           "(faster; kd/ks/shininess attributes are not written)."));
  params.addParam(RichEnum(kFitBackend, int(vbrdf::FitBackendChoice::Auto),
                           QStringList() << "Auto" << "GPU (compute shader)" << "CPU (reference)",
                           "Fit back end",
                           "Where the per-vertex fit runs. Auto: a GLSL compute shader in MeshLab's OpenGL "
                           "context when it supports OpenGL 4.3, else the CPU (double precision). Both give "
                           "the same result to about 1e-3."));
  params.addParam(RichFloat(kInitialShininess, vbrdf::kDefaultInitialShininess, "Initial shininess",
                            "Starting value of the Phong exponent alpha (the fit also tries an estimate from "
                            "the highlight samples and keeps the better one). Range [1, 2000]."));
  params.addParam(RichEnum(kSpecularLobe, int(vbrdf::kDefaultLobe),
                           QStringList() << "Phong on R.E (thesis)" << "Blinn-Phong on N.H" << "GGX on N.H",
                           "Specular lobe",
                           "The highlight's shape. Phong on R.E (the thesis): the cosine between the mirrored "
                           "light and the view to the power shininess. Blinn-Phong on N.H: the cosine between "
                           "the normal and the half vector to that power (follows glossy highlights seen away "
                           "from the camera axis better). GGX on N.H: the microfacet lobe of real glossy "
                           "surfaces, with its long tails; shininess is its Phong-equivalent exponent, "
                           "roughness sqrt(2 / (shininess + 2)). Written with the result (per-vertex "
                           "lobe_form) and used by every later step (relighting, evaluation)."));
  params.addParam(RichEnum(kDiffuseTerm, int(vbrdf::kFitDiffuseChoice),
                           QStringList() << "Auto" << "Lambert (thesis)" << "Coated (Fresnel in and out)",
                           "Diffuse term",
                           "What k_d multiplies: N.L (Lambert, the thesis) or N.L scaled by a clear coat's "
                           "Fresnel transmission on the way in and out (varnish, glaze, plastic: the diffuse "
                           "light dims at grazing light and view; the colour then holds from other cameras). "
                           "Auto: a quick pilot fit of both with every 4th photo held out (in turn, until 8 photos "
                           "were) picks the one that "
                           "predicts those photos better (the report says which). Written with the result "
                           "(per-vertex diffuse_form) and used by every later step."));
  params.addParam(RichBool(kFindMaterials, vbrdf::FitSettings().materials, "Find materials (shared lobes)",
                           "After the per-vertex fit, group the vertices into a few materials by their "
                           "specular response (how many: chosen by the error at held-out photos), fit one "
                           "lobe per material from the samples of all its vertices and give every vertex of a "
                           "glossy material a specular term (a vertex sees one or two highlights, a material "
                           "many; given only where the held-out photos show it helps); a diffuse material gets "
                           "none. Writes per-vertex 'material'; the report lists the materials. Holds better "
                           "from other cameras; costs about a seventh more time. On by default."));
  params.addParam(RichBool(kSharpenAlbedo, vbrdf::FitSettings().deconvolve_albedo, "Sharpen albedo edges",
                           "Where a photo's pixels straddle an albedo edge (a material boundary, a painted "
                           "line), the sampled colour blends the vertices on both sides. On: those vertices' "
                           "k_d C is deconvolved through the pixel footprints, kept only where the result "
                           "still reproduces the photos (not where the colour is a texture finer than the "
                           "mesh). Writes per-vertex 'diffuse_deconvolved'; the report says how many. On by "
                           "default."));
  params.addParam(RichBool(kRefineRegistration, vbrdf::FitSettings().registration.enabled, "Refine registration",
                           "Each viewpoint's camera is measured against its photos (the normals photometric "
                           "stereo reads from them, which the light does not change) and, where it is off by "
                           "more than a quarter pixel, corrected (turn and focal length) before any sample is "
                           "taken, unless the camera as given explains the photos clearly better (the fitted "
                           "model's residual); a correction's shift and roll are then refined by that residual "
                           "by up to 0.12 px. The corrected "
                           "cameras are applied to the project's rasters and written to <output>_registered.mlp; "
                           "the input project is never changed. The report gives each viewpoint's "
                           "misregistration before and after. Off by default."));
  params.addParam(RichBool(kRefineNormals, vbrdf::FitSettings().shading_normals.enabled, "Refine normals from photos",
                           "A scanned mesh is smoother than the surface, its normals a few degrees off. On: each "
                           "vertex's shading normal is refined from its photos jointly with its reflectance "
                           "(kept near the mesh normal and its neighbours', and left as the mesh's where the "
                           "lights do not determine it). Visibility and shadows keep the mesh. The layer's "
                           "normals and the PLY's nx ny nz become the refined ones (the relight filter and the "
                           "live view shade with them); the mesh's own normals are kept as mesh_nx/ny/nz. The "
                           "report says how far they moved. On by default."));
  params.addParam(RichInt(kMaxIterations, vbrdf::kDefaultMaxIterations, "Max iterations",
                          "Cap on the shininess updates per vertex (each followed by an exact re-solve of "
                          "k_d, k_s and colour). Converged vertices stop earlier. 0: initial estimate only."));
  shared::add_min_specular_samples(params);
  params.addParam(RichInt(kFillUnseenRings, 0, "Fill unseen gaps (rings)",
                          "Vertices no photo sees keep no model and their input colour. Give N > 0 to let "
                          "those within N edges of a modelled vertex take their neighbours' parameters "
                          "(fit_status 3, like seen vertices without a usable sample, which are always filled). "
                          "0 = off."));
  shared::add_quality_output(params);
  shared::add_color_correction(params);
  shared::add_only_selected(params);
}

vbrdf::FitSettings FitFilter::settings_from(const RichParameterList &params) {
  vbrdf::FitSettings s;
  s.light_file = shared::light_file(params);
  shared::read_light_placement(params, s.dome_radius, s.light_unit_scale);
  s.output_ply = path(params, kOutputPly);
  s.overwrite = params.getBool(kOverwriteOutput) ? vbrdf::OverwritePolicy::Replace : vbrdf::OverwritePolicy::Refuse;
  shared::read_gather(params, s.gather);
  shared::read_visibility(params, s.visibility_choice, s.visibility);

  const int fit_backend = params.getEnum(kFitBackend);
  require(fit_backend >= 0 && fit_backend <= 2, kFitBackend, "must be 0 (Auto), 1 (GPU) or 2 (CPU)");
  const float alpha0 = params.getFloat(kInitialShininess);
  require(alpha0 >= s.reflectance.alpha_min && alpha0 <= s.reflectance.alpha_max, kInitialShininess, "must be in [1, 2000]");
  const int iterations = params.getInt(kMaxIterations);
  require(iterations >= 0 && iterations <= 10000, kMaxIterations, "must be in [0, 10000]");
  const int fill_rings = params.getInt(kFillUnseenRings);
  require(fill_rings >= 0 && fill_rings <= 1000, kFillUnseenRings, "must be in [0, 1000]");
  const int lobe = params.getEnum(kSpecularLobe);
  require(lobe >= 0 && lobe < vbrdf::kLobeFormCount, kSpecularLobe,
          "must be 0 (Phong on R.E), 1 (Blinn-Phong on N.H) or 2 (GGX on N.H)");
  const int diffuse = params.getEnum(kDiffuseTerm);
  require(diffuse >= 0 && diffuse <= 2, kDiffuseTerm, "must be 0 (Auto), 1 (Lambert) or 2 (Coated)");

  s.fit_reflectance = params.getBool(kFitReflectance);
  s.fit_backend = vbrdf::FitBackendChoice(fit_backend);
  s.reflectance.alpha_init = alpha0;
  s.reflectance.max_iterations = iterations;
  s.reflectance.lobe = vbrdf::LobeForm(lobe);
  s.diffuse_choice = vbrdf::DiffuseTermChoice(diffuse);
  s.reflectance.min_specular_samples = shared::min_specular_samples(params);
  s.fill_unseen_rings = fill_rings;
  s.materials = params.getBool(kFindMaterials);
  s.deconvolve_albedo = params.getBool(kSharpenAlbedo);
  s.registration.enabled = params.getBool(kRefineRegistration);
  s.shading_normals.enabled = params.getBool(kRefineNormals);
  s.quality = shared::quality_output(params);
  s.color_correction = shared::color_correction(params);
  s.chart_corners = shared::chart_corners(params);
  s.exposure = shared::exposure_normalisation(params);
  return s;
}

void FitFilter::apply(FilterRun &run) const {
  MeshModel *mesh = run.document.mm();
  if (mesh == nullptr)
    throw vbrdf::InputError("No current mesh: open the registered mesh (or its .mlp project) first.");
  const auto log = [&run](const std::string &line) { run.log(GLLogStream::FILTER, line); };

  vbrdf::FitSettings settings = settings_from(run.params);
  MeshArrays arrays = mesh_arrays(*mesh);
  if (const size_t restored = restore_mesh_normals(*mesh, arrays))
    log("Vertex BRDF: " + std::to_string(restored) + " vertices start from the mesh's own normals (mesh_nx/ny/nz of "
        "an earlier fit), not from that fit's refined ones.");
  if (arrays.transformed)
    log("Vertex BRDF: the layer has a transformation matrix; the fit (and the output PLY) use the "
        "transformed, world coordinates in which the rasters are registered.");
  vbrdf::FitInput input;
  input.mesh = arrays.data.view();
  input.mesh_name = mesh->label().toUtf8().toStdString();
  input.mesh_path = mesh->fullName().toUtf8().toStdString();
  input.mesh_colors = arrays.data.colors;
  const ActiveRasters active = active_rasters(run.document);
  input.rasters = active.rasters;
  settings.gather.host_photos = host_photos(run.document);  // read in place, not decoded again
  shared::log_hidden_rasters(active.hidden, active.rasters.size(), log);
  if (shared::only_selected(run.params)) input.vertex_mask = shared::selection_mask(*mesh, arrays, log);
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
        input.mesh, settings.visibility_choice, settings.visibility, gl.get_proc(), log);
    std::unique_ptr<vbrdf::ReflectanceFitter> fitter;
    if (settings.fit_reflectance) fitter = vbrdf::make_reflectance_fitter(settings.fit_backend, gl.get_proc(), log);
    result = vbrdf::run_fit(input, settings, *visibility, fitter.get(), progress_adapter(run.progress, "Vertex BRDF: "),
                            log);
  }
  apply_corrected_cameras(run.document, result.registration, log);
  StoredResults stored;
  stored.layer = ColorLayer::Fit;
  stored.colors_rgba = std::move(result.colors_rgba);
  if (settings.fit_reflectance) stored.quality = std::move(result.quality);
  stored.attributes = std::move(result.attributes);
  stored.vertex_mask = input.vertex_mask;
  store_results(*mesh, arrays, stored);
  apply_shading_normals(*mesh, arrays, result.shading_normals, input.vertex_mask);

  std::ostringstream summary;
  summary << "Vertex BRDF: " << result.vertices_coloured << " of " << arrays.vertex_index.size()
          << " vertices coloured, " << result.vertices_unseen << " seen by no photo, " << result.vertices_no_diffuse
          << " seen but without usable sample; " << result.fit_full << " full fits, " << result.fit_diffuse_only
          << " diffuse-only (visibility: " << result.visibility_backend << ", fit: "
          << (result.fit_backend.empty() ? std::string("off") : result.fit_backend) << ", lights: " << result.light_file
          << ", colour correction: " << color_summary(settings, result) << "). Wrote " << result.output_ply << " ("
          << result.output_note << ")";
  log(summary.str());
  if (run.figure) {
    run.figure("vertices", double(arrays.vertex_index.size()));
    run.figure("vertices_coloured", double(result.vertices_coloured));
    run.figure("vertices_unseen", double(result.vertices_unseen));
    run.figure("vertices_without_sample", double(result.vertices_no_diffuse));
    run.figure("full_fits", double(result.fit_full));
    run.figure("diffuse_only_fits", double(result.fit_diffuse_only));
  }
}

} // namespace vbrdf_plugin
