#include "show_colors_filter.h"

#include "core/base/errors.h"
#include "filter_parameters.h"
#include "meshlab_bridge.h"

namespace vbrdf_plugin {

namespace {

const char *const kColors = "colors";  // the .mlx name (never rename)
const ColorLayer kLayers[] = {ColorLayer::Input, ColorLayer::Fit, ColorLayer::Coverage};  // the enum's order

} // namespace

QString ShowColorsFilter::name() const { return "Vertex BRDF: show vertex colours"; }

QString ShowColorsFilter::info() const {
  return "Shows one of the vertex colourings the Vertex BRDF filters keep: the colours the mesh had before any of "
         "them painted it, the fitted albedo of the last fit (or of a loaded result), or the coverage classes of the "
         "last coverage run. The fit's \"keep the input colour\" always means the first of these, whatever is shown.";
}

host::FilterInterface::FilterClass ShowColorsFilter::filterClass() const { return host::FilterInterface::VertexColoring; }

int ShowColorsFilter::requirements() const { return MeshModel::MM_VERTCOLOR; }

int ShowColorsFilter::postConditions() const { return MeshModel::MM_VERTCOLOR; }

void ShowColorsFilter::initParameters(const MeshDocument &, RichParameterList &params) const {
  params.addParam(RichEnum(kColors, 0,
                           QStringList() << "Before Vertex BRDF (original)" << "Fitted albedo" << "Coverage classes",
                           "Colours to show",
                           "Original: the colours before any Vertex BRDF filter painted the mesh. Fitted albedo: the "
                           "last fit's (or a loaded result's) display colours. Coverage classes: purple unseen, blue "
                           "no diffuse sample, yellow no specular sample, green fully covered."));
}

void ShowColorsFilter::apply(FilterRun &run) const {
  MeshModel *mesh = run.document.mm();
  if (mesh == nullptr) throw vbrdf::InputError("No current mesh.");
  const int choice = run.params.getEnum(kColors);
  require(choice >= 0 && choice < 3, kColors, "must be 0 (original), 1 (fitted albedo) or 2 (coverage classes)");
  const ColorLayer layer = kLayers[choice];
  if (!show_color_layer(*mesh, layer))
    throw vbrdf::InputError(std::string("Mesh '") + utf8(mesh->label()) + "' has no " + color_layer_label(layer) +
                            (layer == ColorLayer::Fit
                                 ? ": run 'Vertex BRDF: fit per-vertex reflectance' or 'Vertex BRDF: load result "
                                   "attributes' first."
                                 : ": run 'Vertex BRDF: coverage and next light' first."));
  run.log(GLLogStream::FILTER, std::string("Vertex BRDF: showing ") + color_layer_label(layer) + ".");
}

} // namespace vbrdf_plugin
