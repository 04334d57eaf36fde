#pragma once
// "Vertex BRDF: relight and compare": renders the fitted per-vertex Phong model (the attributes the
// fit filter stores on the mesh, or a saved result PLY) from every raster's camera under its light
// and compares it with the photos (images, contact sheet, CSV table), and/or renders a novel
// viewpoint under a light the user gives. The mesh is not changed.
#include "plugin_filter.h"

namespace vbrdf_plugin {

class RelightFilter : public PluginFilter {
public:
  QString name() const override;
  QString info() const override;
  MeshFilterInterface::FilterClass filterClass() const override;
  int preConditions() const override;
  int postConditions() const override;
  void initParameters(const MeshDocument &document, RichParameterList &params) const override;
  void apply(FilterRun &run) const override;
};

} // namespace vbrdf_plugin
