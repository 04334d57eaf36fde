#pragma once
// "Vertex BRDF: load result attributes": puts the per-vertex values of a saved result PLY (kd, ks,
// shininess, color_*, dq, sq, fit_status, ...) back onto the current mesh as MeshLab per-vertex
// attributes, since MeshLab 2020.09 drops a PLY's custom properties when it opens the file. The
// matching (vertex count, positions) is vbrdf::attach_result's.
#include "plugin_filter.h"

namespace vbrdf_plugin {

class LoadResultFilter : public PluginFilter {
public:
  QString name() const override;
  QString info() const override;
  host::FilterInterface::FilterClass filterClass() const override;
  int requirements() const override;
  int preConditions() const override;
  int postConditions() const override;
  void initParameters(const MeshDocument &document, RichParameterList &params) const override;
  void apply(FilterRun &run) const override;
};

} // namespace vbrdf_plugin
