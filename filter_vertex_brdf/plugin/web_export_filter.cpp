#include "web_export_filter.h"

#include "core/base/errors.h"
#include "core/base/number_format.h"
#include "core/base/output_file.h"
#include "core/publish/web_export.h"
#include "core/publish/web_viewer.h"
#include "filter_parameters.h"
#include "meshlab_bridge.h"

namespace vbrdf_plugin {

namespace {

// Parameter names (the .mlx scripts refer to them, never rename).
const char *const kResultPly = "exportedResultPly";
const char *const kOutputGlb = "outputGlb";
const char *const kWriteViewer = "writeViewer";
const char *const kOverwrite = "overwriteWebFiles";

std::string without_extension(const std::string &path, const char *ext) {
  const size_t n = std::char_traits<char>::length(ext);
  return path.size() > n && path.compare(path.size() - n, n, ext) == 0 ? path.substr(0, path.size() - n) : path;
}

} // namespace

QString WebExportFilter::name() const { return "Vertex BRDF: export for the web"; }

QString WebExportFilter::info() const {
  return "Writes a result PLY of <i>Vertex BRDF: fit per-vertex reflectance</i> as a binary glTF 2.0 file (GLB) "
         "that a web browser relights with the same model (colour, k_d, k_s, shininess, lobe and diffuse forms), "
         "and beside it <code>&lt;name&gt;.html</code>, a viewer with the GLB inside that opens from the file "
         "system with no server and no network, and <code>&lt;name&gt;_hosted.html</code>, the viewer loading "
         "the GLB by URL for a web server. The photo lights and viewpoints of the visible rasters go into the "
         "GLB. Generic glTF viewers show the albedo with a plain material.";
}

host::FilterInterface::FilterClass WebExportFilter::filterClass() const { return host::FilterInterface::Camera; }

int WebExportFilter::postConditions() const { return MeshModel::MM_NONE; }

void WebExportFilter::initParameters(const MeshDocument &, RichParameterList &params) const {
  add_path(params, kResultPly, "Result PLY",
           "The PLY the fit wrote (by default <project>_brdf.ply beside the project). Empty: that default file.");
  add_path(params, kOutputGlb, "Output GLB",
           "The GLB to write; the viewer pages are written beside it with the same name (.html, _hosted.html). "
           "Empty: the result's name with _web.glb.");
  params.addParam(RichBool(kWriteViewer, true, "Write the viewer pages",
                           "Also write <name>.html (GLB embedded: opens from the file system) and <name>_hosted.html "
                           "(loads <name>.glb by URL). Off: the GLB alone."));
  params.addParam(RichBool(kOverwrite, true, "Overwrite existing output",
                           "Replace existing files (each is replaced whole: a failed write leaves the previous one). "
                           "Off: refuse when a file exists."));
}

void WebExportFilter::apply(FilterRun &run) const {
  MeshModel *mesh = run.document.mm();
  if (mesh == nullptr) throw vbrdf::InputError("No current mesh: open the project the result was fitted on first.");
  const std::string project = project_path(run.document, *mesh);
  std::string file = resolve_path(path(run.params, kResultPly), project);
  if (file.empty()) file = vbrdf::default_output_path(project);
  std::string glb_path = resolve_path(path(run.params, kOutputGlb), project);
  if (glb_path.empty()) glb_path = without_extension(file, ".ply") + "_web.glb";

  const vbrdf::ResultPly result = vbrdf::read_result_ply(file);
  const ActiveRasters active = active_rasters(run.document);
  const vbrdf::WebCapture capture = vbrdf::web_capture_of(active.rasters, project, "", result.mesh.view());
  const vbrdf::WebGlb glb = vbrdf::build_web_glb(result, file, capture);
  const bool viewer = run.params.getBool(kWriteViewer);
  const vbrdf::WebOutputPaths paths = vbrdf::write_web_outputs(
      glb, glb_path, viewer, run.params.getBool(kOverwrite) ? vbrdf::OverwritePolicy::Replace : vbrdf::OverwritePolicy::Refuse,
      utf8(mesh->label()));
  std::string log = "Vertex BRDF: web export of " + file + ": " + paths.glb + ": " + glb.summary() + "; " +
                    vbrdf::counted(capture.lights.size(), "photo light") + ", " + vbrdf::counted(capture.cameras.size(), "viewpoint") +
                    (capture.note.empty() ? "" : " (" + capture.note + ")") + ".";
  if (viewer) log += " Viewer: " + paths.html + " (opens from the file system), " + paths.hosted_html + " (beside the GLB on a web server).";
  run.log(GLLogStream::FILTER, log);
}

} // namespace vbrdf_plugin
