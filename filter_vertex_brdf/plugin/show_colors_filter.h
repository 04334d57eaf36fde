#pragma once
// "Vertex BRDF: show vertex colours": switches the displayed vertex colours between the colour
// layers the filters keep (meshlab_bridge.h, ColorLayer): the colours before any Vertex BRDF filter,
// the last fit's albedo, the last coverage's classes. Nothing else changes.
#include "plugin_filter.h"

namespace vbrdf_plugin {

class ShowColorsFilter : public PluginFilter {
public:
  QString name() const override;
  QString info() const override;
  host::FilterInterface::FilterClass filterClass() const override;
  int requirements() const override;
  int postConditions() const override;
  void initParameters(const MeshDocument &document, RichParameterList &params) const override;
  void apply(FilterRun &run) const override;
};

} // namespace vbrdf_plugin
