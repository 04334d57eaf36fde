#pragma once
// "Vertex BRDF: estimate light directions from a reflective sphere": finds the mirror sphere(s) in
// the photos of one viewpoint (or takes their outlines from the parameters), turns each photo's
// highlight into a light direction and writes an RTI .lp for the fit filter. The mesh is not changed.
#include "plugin_filter.h"

namespace vbrdf_plugin {

class SphereFilter : public PluginFilter {
public:
  QString name() const override;
  QString info() const override;
  MeshFilterInterface::FilterClass filterClass() const override;
  int postConditions() const override;
  void initParameters(const MeshDocument &document, RichParameterList &params) const override;
  void apply(FilterRun &run) const override;
};

} // namespace vbrdf_plugin
