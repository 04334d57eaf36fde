#include "load_result_filter.h"

#include <sstream>

#include "core/base/errors.h"
#include "core/io/result_attach.h"
#include "core/io/result_schema.h"
#include "filter_parameters.h"
#include "meshlab_bridge.h"

namespace vbrdf_plugin {

namespace {

// Parameter names (the .mlx scripts refer to them, never rename).
const char *const kResultPly = "resultPly";
const char *const kShowColors = "showResultColors";

} // namespace

QString LoadResultFilter::name() const { return "Vertex BRDF: load result attributes"; }

QString LoadResultFilter::info() const {
  return "Puts the per-vertex values of a result PLY written by <i>Vertex BRDF: fit per-vertex reflectance</i> back "
         "onto the current mesh as per-vertex attributes (" +
         QString::fromStdString(vbrdf::result_attribute_names()) +
         "), so that the fit can be inspected after MeshLab has re-opened the file (MeshLab drops a PLY's own "
         "properties on loading). The current mesh must be the one the result was fitted on: same vertices, in "
         "the same order and place.<br>Vertex quality becomes DQ, SQ or the fit RMSE (vertices without a model "
         "get the median, so they do not read as the worst): <i>Filters &gt; Color Creation and Processing &gt; "
         "Colorize by vertex Quality</i> shows it, <i>Filters &gt; Quality Measure and Computations &gt; Per "
         "Vertex Quality Histogram</i> counts it, and <i>Filters &gt; Quality Measure and Computations &gt; Per "
         "Vertex Quality Function</i> can compute from the attributes (e.g. <code>kd*2</code>).";
}

host::FilterInterface::FilterClass LoadResultFilter::filterClass() const {
  return host::FilterInterface::FilterClass(host::FilterInterface::Camera | host::FilterInterface::VertexColoring);
}

int LoadResultFilter::requirements() const { return MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTQUALITY; }

int LoadResultFilter::preConditions() const { return MeshModel::MM_NONE; }

int LoadResultFilter::postConditions() const { return MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTQUALITY; }

void LoadResultFilter::initParameters(const MeshDocument &, RichParameterList &params) const {
  add_path(params, kResultPly, "Result PLY",
           "The PLY the fit wrote for this mesh (by default <project>_brdf.ply beside the project). Empty: that "
           "default file.");
  shared::add_quality_output(params);
  params.addParam(RichBool(kShowColors, true, "Show the result's colours",
                           "Vertex colours become the result's (the fitted albedo); they are also kept as the fit's "
                           "colours for 'Vertex BRDF: show vertex colours'. Off: only the attributes and quality."));
}

void LoadResultFilter::apply(FilterRun &run) const {
  MeshModel *mesh = run.document.mm();
  if (mesh == nullptr) throw vbrdf::InputError("No current mesh: open the mesh the result was fitted on first.");
  const vbrdf::QualityOutput quality = shared::quality_output(run.params);
  const MeshArrays arrays = mesh_arrays(*mesh);
  const std::string project = project_path(run.document, *mesh);
  std::string file = resolve_path(path(run.params, kResultPly), project);
  if (file.empty()) file = vbrdf::default_output_path(project);

  const vbrdf::ResultPly result = vbrdf::read_result_ply(file);
  const vbrdf::AttachedResult attached =
      vbrdf::attach_result(result, arrays.data.view(), utf8(mesh->label()), file, quality);
  StoredResults stored;
  stored.layer = ColorLayer::Fit;
  stored.colors_rgba = attached.colors_rgba;
  stored.paint = run.params.getBool(kShowColors);
  stored.quality = attached.quality;
  stored.attributes = attached.attributes;
  store_results(*mesh, arrays, stored);

  std::ostringstream log;
  log << "Vertex BRDF: attached " << attached.attributes.size() << " attributes (";
  for (size_t i = 0; i < attached.attributes.size(); ++i) log << (i ? ", " : "") << attached.attributes[i].name;
  log << ") from " << file << " to " << arrays.vertex_index.size() << " vertices (largest position difference "
      << attached.max_position_error << ").";
  if (attached.quality.empty())
    log << " No reflectance model in the file ('" << attached.missing_model_attribute << "' missing): quality unchanged.";
  else
    log << " Quality: "
        << (quality == vbrdf::QualityOutput::SQ ? "SQ" : quality == vbrdf::QualityOutput::RMSE ? "fit RMSE" : "DQ")
        << "; " << attached.modelled << " vertices have a model, the others got the median.";
  run.log(GLLogStream::FILTER, log.str());
}

} // namespace vbrdf_plugin
