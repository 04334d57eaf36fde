#pragma once
// "Vertex BRDF: fit per-vertex reflectance": parameters and the mapping of the MeshLab document
// onto vbrdf::run_fit.
#include "core/run/fit_run.h"
#include "plugin_filter.h"

namespace vbrdf_plugin {

class FitFilter : public PluginFilter {
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
  static vbrdf::FitSettings settings_from(const RichParameterList &params);
};

} // namespace vbrdf_plugin
