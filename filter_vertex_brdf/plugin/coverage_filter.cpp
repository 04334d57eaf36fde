#include "coverage_filter.h"

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
const char *const kSuggestionFile = "suggestionFile";
const char *const kMinDiffuseSamples = "minDiffuseSamples";
const char *const kMinElevation = "minLightElevation";
const char *const kUseFitQuality = "useFitQuality";
const char *const kPoorDiffuseQuality = "poorDiffuseQuality";
const char *const kPoorSpecularQuality = "poorSpecularQuality";
const char *const kColorByCoverage = "colorByCoverage";
const char *const kSelectNewView = "selectNewViewVertices";

// The per-vertex attributes coverage adds to the mesh: each name beside the value it holds.
struct CoverageColumn {
  const char *name;
  float (*value)(const vbrdf::CoverageResult &r, size_t v);
};
const CoverageColumn kCoverageColumns[] = {
    {"coverage_class", [](const vbrdf::CoverageResult &r, size_t v) { return float(r.classes[v]); }},
    {"coverage_seen", [](const vbrdf::CoverageResult &r, size_t v) { return float(r.counts[v].seen); }},
    {"coverage_diffuse", [](const vbrdf::CoverageResult &r, size_t v) { return float(r.counts[v].diffuse); }},
    {"coverage_specular", [](const vbrdf::CoverageResult &r, size_t v) { return float(r.counts[v].specular); }},
};

std::vector<vbrdf::VertexAttribute> coverage_attributes(const vbrdf::CoverageResult &r) {
  std::vector<vbrdf::VertexAttribute> attrs;
  for (const CoverageColumn &column : kCoverageColumns) {
    vbrdf::VertexAttribute a{column.name, {}};
    a.values.reserve(r.classes.size());
    for (size_t v = 0; v < r.classes.size(); ++v) a.values.push_back(column.value(r, v));
    attrs.push_back(std::move(a));
  }
  return attrs;
}

} // namespace

QString CoverageFilter::name() const { return "Vertex BRDF: coverage and next light"; }

QString CoverageFilter::info() const {
  // Short on purpose (see FitFilter::info); the details are in
  // docs/parameters.md#vertex-brdf-coverage-and-next-light and the tooltips.
  return "Acquisition feedback: which vertices the photos so far cover (<b>purple</b> unseen, <b>blue</b> no "
         "diffuse sample, <b>yellow</b> no specular sample, <b>green</b> covered) and where to put the light next "
         "(log and a text file). Vertices only a new viewpoint can cover are selected.";
}

host::FilterInterface::FilterClass CoverageFilter::filterClass() const {
  return host::FilterInterface::FilterClass(host::FilterInterface::Camera | host::FilterInterface::VertexColoring);
}

int CoverageFilter::requirements() const { return MeshModel::MM_VERTCOLOR; }

int CoverageFilter::preConditions() const { return MeshModel::MM_FACENUMBER; }

// MM_VERTNUMBER: no Preview in MeshLab 2020.09 (see FitFilter::postConditions): a preview would
// rewrite the suggestion file on every change of a field.
int CoverageFilter::postConditions() const {
  return MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTFLAGSELECT | MeshModel::MM_VERTNUMBER;
}

void CoverageFilter::initParameters(const MeshDocument &, RichParameterList &params) const {
  shared::add_light_file(params);
  shared::add_light_placement(params);
  add_path(
      params, kSuggestionFile, "Suggestion file",
      "Where the suggestions are written (key: value lines, then the report); the vertices only a new "
      "viewpoint can cover go beside it (same name ending in _new_view_vertices.txt). Relative paths are "
      "relative to the project folder. Empty: the project's name followed by _next_light.txt, beside it.");
  shared::add_viewpoint_raster(params);
  shared::add_specular_threshold(params);
  shared::add_diffuse_threshold(params, shared::DiffuseThresholdUse::Coverage);
  params.addParam(RichInt(kMinDiffuseSamples, 1, "Diffuse samples needed",
                          "Diffuse samples a vertex needs to count as diffusely covered."));
  shared::add_min_specular_samples(params);
  params.addParam(RichFloat(kMinElevation, 5.0f, "Lowest light elevation (deg)",
                            "Suggested lights are at least this many degrees above the camera's image plane "
                            "(in [0, 80]): lights further back would be behind the object or in the picture."));
  params.addParam(RichBool(kUseFitQuality, true, "Prefer poorly fitted vertices",
                           "When the mesh has the per-vertex dq/sq of a fit, covered vertices whose diffuse "
                           "(specular) quality is below the thresholds below also ask for diffuse (specular) "
                           "samples; the poorer the fit, the more they weigh."));
  params.addParam(RichFloat(kPoorDiffuseQuality, 1.5f, "Poor diffuse quality (DQ)",
                            "DQ (in [0, 2], 2 = good) below which a covered vertex asks for more diffuse samples."));
  params.addParam(RichFloat(kPoorSpecularQuality, 1.5f, "Poor specular quality (SQ)",
                            "SQ (in [0, 2], 2 = good) below which a covered vertex asks for more specular samples."));
  params.addParam(RichBool(kColorByCoverage, true, "Colour vertices by coverage",
                           "Vertex colours show the classes: purple unseen, blue no diffuse sample, yellow no "
                           "specular sample, green fully covered. The classes are also kept in the per-vertex attributes coverage_class "
                           "and coverage_color; 'Vertex BRDF: show vertex colours' switches back to the colours before "
                           "(or to the fit's). Off: the vertex colours are not changed."));
  params.addParam(RichBool(kSelectNewView, true, "Select vertices needing a new viewpoint",
                           "Select exactly the vertices that no photo sees or that no placeable light of any "
                           "registered viewpoint can cover."));
  shared::add_photo_and_visibility(params);
  shared::add_only_selected(params);
}

vbrdf::CoverageSettings CoverageFilter::settings_from(const RichParameterList &params) {
  vbrdf::CoverageSettings s;
  s.light_file = shared::light_file(params);
  shared::read_light_placement(params, s.dome_radius, s.light_unit_scale);
  s.suggestion_file = path(params, kSuggestionFile);
  s.viewpoint_raster = shared::viewpoint_raster(params);
  shared::read_gather(params, s.gather);
  shared::read_visibility(params, s.visibility_choice, s.visibility);
  s.min_diffuse = params.getInt(kMinDiffuseSamples);
  require(s.min_diffuse >= 1 && s.min_diffuse <= 1000, kMinDiffuseSamples, "must be in [1, 1000]");
  s.min_specular = shared::min_specular_samples(params);
  s.suggest.min_elevation_deg = params.getFloat(kMinElevation);
  require(s.suggest.min_elevation_deg >= 0.0f && s.suggest.min_elevation_deg <= 80.0f, kMinElevation,
          "must be in [0, 80] degrees");
  s.poor_dq = params.getFloat(kPoorDiffuseQuality);
  s.poor_sq = params.getFloat(kPoorSpecularQuality);
  require(s.poor_dq >= 0.0f && s.poor_dq <= 2.0f, kPoorDiffuseQuality, "must be in [0, 2]");
  require(s.poor_sq >= 0.0f && s.poor_sq <= 2.0f, kPoorSpecularQuality, "must be in [0, 2]");
  return s;
}

CoverageFilter::Display CoverageFilter::display_from(const RichParameterList &params) {
  Display display;
  display.color_by_class = params.getBool(kColorByCoverage);
  display.select_new_view = params.getBool(kSelectNewView);
  display.use_fit_quality = params.getBool(kUseFitQuality);
  display.only_selected = shared::only_selected(params);
  return display;
}

vbrdf::CoverageSettings CoverageFilter::default_settings() {
  RichParameterList params;
  CoverageFilter().initParameters(MeshDocument(), params);
  return settings_from(params);
}

vbrdf::CoverageResult CoverageFilter::run_on_document(FilterRun &run, vbrdf::CoverageSettings settings,
                                                      const Display &display) {
  MeshModel *mesh = run.document.mm();
  if (mesh == nullptr)
    throw vbrdf::InputError("No current mesh: open the registered mesh (or its .mlp project) first.");
  const auto log = [&run](const std::string &line) { run.log(GLLogStream::FILTER, line); };
  const MeshArrays arrays = mesh_arrays(*mesh);
  vbrdf::CoverageInput input;
  input.mesh = arrays.data.view();
  input.mesh_name = mesh->label().toUtf8().toStdString();
  const ActiveRasters active = active_rasters(run.document);
  input.rasters = active.rasters;
  settings.gather.host_photos = host_photos(run.document);  // read in place, not decoded again
  shared::log_hidden_rasters(active.hidden, active.rasters.size(), log);
  if (display.only_selected) input.vertex_mask = shared::selection_mask(*mesh, arrays, log);
  input.project_path = project_path(run.document, *mesh);
  settings.light_file = resolve_path(settings.light_file, input.project_path);
  settings.suggestion_file = resolve_path(settings.suggestion_file, input.project_path);
  if (!host::rasters(run.document).empty()) {
    // viewpointRaster counts the document's rasters; the core counts the visible ones.
    const size_t chosen = shared::chosen_raster(run.document, settings.viewpoint_raster);
    const auto at = std::find(active.document_index.begin(), active.document_index.end(), chosen);
    require(at != active.document_index.end(), shared::kViewpointRaster,
            "names raster " + std::to_string(chosen) + " ('" + utf8(host::rasters(run.document)[chosen]->label()) +
                "'), which is hidden: show it in the layer dialog or choose a visible raster");
    settings.viewpoint_raster = int(at - active.document_index.begin());
  }
  if (display.use_fit_quality) {
    input.dq = vertex_float_attribute(*mesh, arrays, "dq");
    input.sq = vertex_float_attribute(*mesh, arrays, "sq");
    if (input.dq.empty() != input.sq.empty()) input.dq.clear(), input.sq.clear();
    if (!input.dq.empty()) input.quality_source = "the mesh's dq/sq from the last fit";
  }

  vbrdf::CoverageResult result;
  {
    // The GL back end needs the context current for its whole life: destroy it inside the scope.
    const bool needs_gl = settings.visibility_choice != vbrdf::VisibilityChoice::CPU;
    GlContextScope gl(needs_gl ? run.gl_context : nullptr, log);
    auto visibility = vbrdf::make_visibility_backend(input.mesh, settings.visibility_choice, settings.visibility, gl.get_proc(), log);
    result = vbrdf::run_coverage(input, settings, *visibility, progress_adapter(run.progress, "Vertex BRDF coverage: "),
                                 log);
  }
  StoredResults stored;
  stored.layer = ColorLayer::Coverage;
  stored.colors_rgba = result.colors_rgba;  // kept in coverage_color; shown only when asked
  stored.paint = display.color_by_class;
  stored.attributes = coverage_attributes(result);
  stored.vertex_mask = input.vertex_mask;
  store_results(*mesh, arrays, stored);
  if (display.select_new_view) select_vertices(*mesh, arrays, result.new_view_vertices);
  return result;
}

void CoverageFilter::apply(FilterRun &run) const {
  const Display display = display_from(run.params);
  const vbrdf::CoverageResult r = run_on_document(run, settings_from(run.params), display);
  std::ostringstream summary;
  summary << "Vertex BRDF coverage: " << r.class_counts[vbrdf::kFullyCovered] << " fully covered, "
          << r.class_counts[vbrdf::kDiffuseNoSpecular] << " without specular sample, "
          << r.class_counts[vbrdf::kSeenNotDiffuse] << " without diffuse sample, " << r.class_counts[vbrdf::kUnseen]
          << " unseen; " << r.new_view_vertices.size() << " need a new viewpoint"
          << (display.select_new_view ? " (selected)" : "") << ". Suggestions: " << r.suggestion_file;
  run.log(GLLogStream::FILTER, summary.str());
}

} // namespace vbrdf_plugin
