#include "relight_filter.h"

#include <cmath>
#include <sstream>

#include <QDir>
#include <QFileInfo>
#include <vcg/complex/allocate.h>

#include "core/base/errors.h"
#include "core/base/file_util.h"
#include "core/inputs/light_file.h"
#include "core/inputs/light_source.h"
#include "core/io/output_ply.h"
#include "core/run/fit_run.h"
#include "core/inputs/project.h"
#include "core/relight/relight_render.h"
#include "core/io/result_ply.h"
#include "core/io/result_schema.h"
#include "filter_parameters.h"
#include "meshlab_bridge.h"

namespace vbrdf_plugin {

namespace {

// Parameter names of this filter only (the .mlx scripts refer to them, never rename); the shared
// ones are in filter_parameters.h.
const char *const kFitResultPly = "fitResultPly";
const char *const kRasterProject = "rasterProject";
const char *const kOutputFolder = "outputFolder";
const char *const kRenderRasters = "renderRasters";
const char *const kNovelView = "novelView";
const char *const kViewRaster = "viewRaster";
const char *const kOrbitAzimuth = "orbitAzimuth";
const char *const kOrbitElevation = "orbitElevation";
const char *const kDistanceScale = "distanceScale";
const char *const kNovelLight = "novelLight";
const char *const kHeatMapMax = "heatMapMax";

using Settings = RelightFilter::Settings;

} // namespace

RelightFilter::Settings RelightFilter::settings_from(const RichParameterList &params) {
  Settings s;
  s.fit_result_ply = path(params, kFitResultPly);
  s.raster_project = path(params, kRasterProject);
  s.light_file = shared::light_file(params);
  shared::read_light_placement(params, s.dome_radius, s.light_unit_scale);
  s.output_folder = utf8(params.getString(kOutputFolder));
  s.render_rasters = params.getBool(kRenderRasters);
  s.novel_view = params.getBool(kNovelView);
  require(s.render_rasters || s.novel_view, kRenderRasters, "and 'novelView' are both off: nothing to render");
  s.view_raster = params.getInt(kViewRaster);
  require(s.view_raster >= 0, kViewRaster, "must be a raster index (0 = the first raster)");
  s.azimuth = params.getFloat(kOrbitAzimuth);
  s.elevation = params.getFloat(kOrbitElevation);
  require(std::isfinite(s.azimuth) && std::fabs(s.azimuth) <= 360, kOrbitAzimuth, "must be in [-360, 360] degrees");
  require(std::isfinite(s.elevation) && std::fabs(s.elevation) <= 89, kOrbitElevation, "must be in [-89, 89] degrees");
  s.distance_scale = params.getFloat(kDistanceScale);
  require(std::isfinite(s.distance_scale) && s.distance_scale >= 0.05f && s.distance_scale <= 20, kDistanceScale,
          "must be in [0.05, 20]");
  const vcg::Point3f light = host::direction_value(params, kNovelLight);
  require(std::isfinite(light.Norm()) && light.Norm() > 1e-6f, kNovelLight, "must be a non-zero direction");
  for (int k = 0; k < 3; ++k) s.novel_light[k] = light[k] / light.Norm();
  s.output.heat_map_max_de = params.getFloat(kHeatMapMax);
  require(std::isfinite(s.output.heat_map_max_de) && s.output.heat_map_max_de > 0 && s.output.heat_map_max_de <= 100,
          kHeatMapMax, "must be in (0, 100]");
  s.output.encoding = shared::photo_encoding(params);
  s.output.color_correction = shared::color_correction(params);
  s.output.chart_corners = shared::chart_corners(params);
  s.output.exposure = shared::exposure_normalisation(params);
  s.render.shadow_map_size = shared::shadow_map_size(params);
  return s;
}

namespace {

// The fit filter's per-vertex float attributes, read by name through the result schema.
// The model's forms go into `render` (lobe, diffuse).
std::vector<vbrdf::VertexFit> fits_from_mesh(MeshModel &mesh, const MeshArrays &arrays,
                                             vbrdf::RelightRenderSettings &render) {
  using Alloc = vcg::tri::Allocator<CMeshO>;
  vbrdf::ResultColumns columns;
  for (const vbrdf::ResultAttribute &a : vbrdf::result_schema()) {
    auto h = Alloc::FindPerVertexAttribute<float>(mesh.cm, a.name);
    if (!Alloc::IsValidHandle(mesh.cm, h)) continue;
    std::vector<float> &column = columns[a.name];
    for (size_t v : arrays.vertex_index) column.push_back(h[v]);
  }
  const std::string missing = vbrdf::first_missing_model_attribute(columns);
  if (!missing.empty())
    throw vbrdf::InputError("Mesh '" + utf8(mesh.label()) + "' has no per-vertex '" + missing +
                            "': apply \"Vertex BRDF: fit per-vertex reflectance\" (with 'Fit reflectance' on) "
                            "first, or set 'fitResultPly' to the PLY it wrote.");
  std::vector<vbrdf::VertexFit> fits;
  const std::vector<vbrdf::VertexRecord> records = vbrdf::records_from_columns(columns, utf8(mesh.label()));
  for (const vbrdf::VertexRecord &record : records) fits.push_back(record.fit);
  render.lobe = vbrdf::lobe_form_of(records, utf8(mesh.label()));
  render.diffuse = vbrdf::diffuse_forms_of(records);
  return fits;
}

// Fits of a saved result PLY, which must be this mesh (same vertices in the same order).
std::vector<vbrdf::VertexFit> fits_from_file(const std::string &path, const MeshArrays &arrays,
                                             vbrdf::RelightRenderSettings &render) {
  const vbrdf::ResultPly result = vbrdf::read_result_ply(path);
  const std::vector<float> &p = arrays.data.positions, &q = result.mesh.positions;
  const float tolerance = 1e-4f * std::max(1e-12f, vbrdf::compute_bounds(arrays.data.view()).diagonal());
  bool same = p.size() == q.size();
  for (size_t i = 0; same && i < p.size(); ++i) same = std::fabs(p[i] - q[i]) <= tolerance;
  if (!same)
    throw vbrdf::InputError("The fit result '" + path + "' has " + std::to_string(q.size() / 3) +
                            " vertices that do not match the current mesh (" + std::to_string(p.size() / 3) +
                            " vertices): choose the PLY the fit wrote for this mesh, or clear 'fitResultPly'.");
  return vbrdf::fits_from_result(result, path, &render.lobe, &render.diffuse);
}

struct RasterSet {
  std::vector<vbrdf::Raster> rasters;
  std::string project;
};

RasterSet rasters_to_render(const MeshDocument &document, const MeshModel &mesh, const Settings &s) {
  RasterSet set;
  if (!s.raster_project.empty()) {
    set.project = resolve_path(s.raster_project, project_path(document, mesh));
    set.rasters = vbrdf::read_project(set.project).rasters;
  } else {
    set.project = project_path(document, mesh);
    set.rasters = document_rasters(document);
  }
  if (set.rasters.empty())
    throw vbrdf::InputError("No raster to render: open the project with its photos, or set 'rasterProject' to an "
                            ".mlp (e.g. the held-out photos' heldout/project.mlp).");
  return set;
}

std::string default_output_folder(const std::string &project) {
  if (project.empty()) return utf8(QDir::current().absoluteFilePath("vertex_brdf_relight"));
  const QFileInfo info(QString::fromStdString(project));
  return utf8(info.absoluteDir().absoluteFilePath(info.completeBaseName() + "_relight"));
}

void log_report(const vbrdf::RelightReport &report, const std::function<void(const std::string &)> &log) {
  char line[512];
  for (const vbrdf::RelightRow &row : report.rows) {
    const vbrdf::PixelComparison &c = row.comparison;
    const vbrdf::PixelComparison &w = row.whole_surface;
    std::snprintf(line, sizeof line,
                  "  %s: %zu lit pixels, CIEDE2000 mean %.2f, p95 %.2f, PSNR %.1f dB; whole surface (%zu pixels, "
                  "unfitted as black): mean %.2f, p95 %.2f",
                  row.label.c_str(), c.pixels, c.mean_de2000, c.p95_de2000, c.psnr_db, w.pixels, w.mean_de2000,
                  w.p95_de2000);
    log(line);
  }
  const vbrdf::PixelComparison &all = report.overall.comparison;
  std::snprintf(line, sizeof line,
                "Vertex BRDF relight: %zu rasters, %zu lit visible pixels: CIEDE2000 mean %.2f, p95 %.2f, PSNR %.1f dB",
                report.rows.size(), all.pixels, all.mean_de2000, all.p95_de2000, all.psnr_db);
  log(line);
  const vbrdf::PixelComparison &whole = report.overall.whole_surface;
  std::snprintf(line, sizeof line,
                "Vertex BRDF relight: whole surface (%zu pixels, silhouettes included, unfitted surface as black): "
                "CIEDE2000 mean %.2f, p95 %.2f, PSNR %.1f dB",
                whole.pixels, whole.mean_de2000, whole.p95_de2000, whole.psnr_db);
  log(line);
}

void render_novel_view(vbrdf::RelightRenderer &renderer, const RasterSet &set, const vbrdf::MeshData &mesh,
                       const Settings &s, std::vector<std::string> &files) {
  if (size_t(s.view_raster) >= set.rasters.size())
    throw vbrdf::InputError("Parameter 'viewRaster' is " + std::to_string(s.view_raster) + " but there are only " +
                            std::to_string(set.rasters.size()) + " rasters (the first is 0).");
  const vbrdf::Raster &base = set.rasters[size_t(s.view_raster)];
  if (!vbrdf::shot_is_valid(base.shot))
    throw vbrdf::InputError("Raster '" + base.label + "' has no valid camera: choose another 'viewRaster'.");
  const std::array<float, 3> pivot = vbrdf::compute_bounds(mesh.view()).centre();
  const vbrdf::Shot shot = vbrdf::orbit_shot(base.shot, pivot.data(), s.azimuth, s.elevation, s.distance_scale);
  std::array<float, 3> light_world;
  vbrdf::camera_to_world_direction(shot, s.novel_light, light_world.data());
  const vbrdf::RelitImage image = renderer.render(shot, vbrdf::LightSource::directional(light_world));
  const std::string path = vbrdf::join_path(s.output_folder, "novel_view.png");
  for (const vbrdf::Raster &r : set.rasters)
    if (r.image_path == path)
      throw vbrdf::InputError("'" + path + "' is the photo of raster '" + r.label + "': choose another output folder.");
  if (!QDir().mkpath(QString::fromStdString(s.output_folder)))
    throw vbrdf::ProcessingError("Cannot create the output folder '" + s.output_folder + "'.");
  vbrdf::write_png_atomically(path, vbrdf::display_image(image));
  files.push_back(path);
}

} // namespace

QString RelightFilter::name() const { return "Vertex BRDF: relight and compare"; }

QString RelightFilter::info() const {
  // Short on purpose (see FitFilter::info); the details are in
  // docs/parameters.md#vertex-brdf-relight-and-compare and the tooltips.
  return "Renders the fitted per-vertex reflectance model (the attributes the fit stored, or its PLY) with OpenGL for "
         "every raster's camera and light, or a novel view, and compares it with the photos: images, a contact "
         "sheet and a table of CIEDE2000 and PSNR in the output folder. The mesh is not changed. Hover over a "
         "field, or press Help, for what it does.";
}

host::FilterInterface::FilterClass RelightFilter::filterClass() const {
  return host::FilterInterface::FilterClass(host::FilterInterface::Camera | host::FilterInterface::Measure);
}

int RelightFilter::preConditions() const { return MeshModel::MM_FACENUMBER; }

int RelightFilter::postConditions() const { return MeshModel::MM_NONE; }

void RelightFilter::initParameters(const MeshDocument &, RichParameterList &params) const {
  add_path(params, kFitResultPly, "Fit result (.ply)",
                               "A PLY written by the fit filter for this mesh. Empty: the per-vertex attributes the "
                               "fit stored on the current mesh in this session.");
  add_path(params, kRasterProject, "Raster project (.mlp)",
                               "Render the rasters of this project instead of the document's, e.g. the held-out "
                               "photos (heldout/project.mlp) to measure relighting on lights the fit never saw. "
                               "Its mesh is ignored; its cameras must be registered to the current mesh.");
  shared::add_light_file(params);
  shared::add_light_placement(params);
  params.addParam(RichString(kOutputFolder, "", "Output folder",
                             "Where the images, contact_sheet.png and relight_table.csv are written (created if "
                             "needed; existing files of the same names are replaced, and the log counts them). "
                             "Relative paths are relative to the project folder. Empty: <project name>_relight "
                             "beside the project."));
  params.addParam(RichBool(kRenderRasters, true, "Render every raster",
                           "Render each raster's camera under its light and compare with its photo."));
  params.addParam(RichBool(kNovelView, false, "Render a novel view",
                           "Also render the camera of 'View raster' moved by the orbit parameters, under 'Novel "
                           "light', into novel_view.png."));
  params.addParam(RichInt(kViewRaster, 0, "View raster",
                          "Index of the raster (0 = first) whose camera the novel view starts from."));
  params.addParam(RichFloat(kOrbitAzimuth, 0.0f, "Orbit azimuth (deg)",
                            "Turns the novel camera around the mesh centre about its up axis; positive moves it to "
                            "its right. Range [-360, 360]."));
  params.addParam(RichFloat(kOrbitElevation, 0.0f, "Orbit elevation (deg)",
                            "Tilts the novel camera around the mesh centre about its right axis; positive moves it "
                            "up. Range [-89, 89]."));
  params.addParam(RichFloat(kDistanceScale, 1.0f, "Distance scale",
                            "Multiplies the novel camera's distance to the mesh centre (below 1: closer). "
                            "Range [0.05, 20]."));
  params.addParam(host::direction_parameter(kNovelLight, vcg::Point3f(0.0f, 0.0f, 1.0f), "Novel light direction",
                              "Direction towards the light for the novel view, in that camera's frame: x right, y up, "
                              "z towards the viewer (0 0 1 = a light behind the camera)."));
  params.addParam(RichFloat(kHeatMapMax, 10.0f, "Heat map maximum (CIEDE2000)",
                            "Colour difference shown at the top of the heat map's colour scale (larger values are "
                            "clipped). 1 is about a just-noticeable difference. Range (0, 100]."));
  shared::add_photo_encoding(params);
  shared::add_color_correction(params);
  shared::add_shadow_map_size(params);
}

void RelightFilter::apply(FilterRun &run) const {
  MeshModel *mesh = run.document.mm();
  if (mesh == nullptr) throw vbrdf::InputError("No current mesh: open the fitted mesh (or its .mlp project) first.");
  const auto log = [&run](const std::string &line) { run.log(GLLogStream::FILTER, line); };
  Settings s = settings_from(run.params);
  const MeshArrays arrays = mesh_arrays(*mesh);
  const std::string project = project_path(run.document, *mesh);
  const std::vector<vbrdf::VertexFit> fits =
      s.fit_result_ply.empty() ? fits_from_mesh(*mesh, arrays, s.render)
                               : fits_from_file(resolve_path(s.fit_result_ply, project), arrays, s.render);
  const RasterSet set = rasters_to_render(run.document, *mesh, s);
  s.output_folder =
      s.output_folder.empty() ? default_output_folder(set.project) : resolve_path(s.output_folder, project);
  s.output.folder = s.output_folder;
  std::vector<vbrdf::LightSource> lights;
  if (s.render_rasters) {
    const std::string light_file =
        vbrdf::resolve_light_file(resolve_path(s.light_file, project), set.rasters, set.project);
    const vbrdf::MeshView view = arrays.data.view();
    lights = vbrdf::resolve_lights(set.rasters, light_file,
                                   vbrdf::light_placement_of(view, s.dome_radius, s.light_unit_scale));
  }

  GlContextScope gl(run.gl_context, log);
  if (!gl.get_proc())
    throw vbrdf::ProcessingError("relighting needs OpenGL 3.3, and MeshLab gave no usable OpenGL context (in "
                                 "PyMeshLab: set VBRDF_OPENGL=1 and run under a display or xvfb-run, "
                                 "docs/pymeshlab.md#opengl).");
  vbrdf::RelightRenderer renderer(arrays.data.view(), fits, gl.get_proc(), s.render);
  std::vector<std::string> files;
  size_t replaced = s.novel_view && vbrdf::file_exists(vbrdf::join_path(s.output_folder, "novel_view.png"));
  if (s.render_rasters) {
    const vbrdf::RelightReport report = vbrdf::relight_rasters(renderer, set.rasters, lights, s.output,
                                                               progress_adapter(run.progress, "Vertex BRDF: "));
    for (const std::string &line : report.color_log) log("Vertex BRDF relight, colour correction: " + line);
    log_report(report, log);
    files = report.files;
    replaced += report.replaced;
  }
  if (s.novel_view) render_novel_view(renderer, set, arrays.data, s, files);
  log("Vertex BRDF relight: wrote " + std::to_string(files.size()) + " files to " + s.output_folder + " (" +
      std::to_string(replaced) + " replaced earlier files of the same names; OpenGL: " + renderer.renderer_name() + ").");
}

} // namespace vbrdf_plugin
