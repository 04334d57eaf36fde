#pragma once
// "Vertex BRDF: coverage and next light": the acquisition feedback of vbrdf::run_coverage on the
// MeshLab document: vertex colours by coverage class, selection of the vertices only a new
// viewpoint can cover, the next diffuse and specular light in the log and in a text file beside
// the project. The photo import filter runs it too after adding photos.
#include "core/run/coverage_run.h"
#include "plugin_filter.h"

namespace vbrdf_plugin {

class CoverageFilter : public PluginFilter {
public:
  QString name() const override;
  QString info() const override;
  host::FilterInterface::FilterClass filterClass() const override;
  int requirements() const override;
  int preConditions() const override;
  int postConditions() const override;
  void initParameters(const MeshDocument &document, RichParameterList &params) const override;
  void apply(FilterRun &run) const override;

  // Filter parameters -> core settings (paths not yet resolved). Throws vbrdf::InputError naming
  // the parameter when a value is out of range.
  static vbrdf::CoverageSettings settings_from(const RichParameterList &params);
  // settings_from the filter's default parameters: what the photo import filter runs.
  static vbrdf::CoverageSettings default_settings();

  struct Display {
    bool color_by_class = true;     // vertex colours = coverage classes
    bool select_new_view = true;    // select the vertices only a new viewpoint can cover
    bool use_fit_quality = true;    // take DQ/SQ from the mesh's "dq"/"sq" attributes when present
    bool only_selected = false;     // only the selected vertices are considered and changed
  };
  // The display parameters (colorByCoverage, selectNewViewVertices, useFitQuality, onlySelectedVertices).
  static Display display_from(const RichParameterList &params);
  // Runs the coverage on the current mesh and every raster of the document (paths in `settings`
  // relative to the project folder; viewpoint_raster -1 = the document's current raster) and
  // stores the results in the mesh as `display` says. Throws vbrdf::InputError / ProcessingError.
  static vbrdf::CoverageResult run_on_document(FilterRun &run, vbrdf::CoverageSettings settings,
                                               const Display &display);
};

} // namespace vbrdf_plugin
