#pragma once
// "Vertex BRDF: import new photos of a viewpoint": the between-shots step of an acquisition.
// New photos taken from an already registered camera position become raster layers that copy that
// raster's shot (the photographer never re-aligns within a viewpoint); their lights come from an
// .lp or are estimated from the reflective sphere in the photos (core/sphere_lights.h); then the
// coverage and the next-light suggestions are updated (CoverageFilter::run_on_document).
#include "plugin_filter.h"

namespace vbrdf_plugin {

class ImportPhotosFilter : public PluginFilter {
public:
  QString name() const override;
  QString info() const override;
  MeshFilterInterface::FilterClass filterClass() const override;
  int requirements() const override;
  int preConditions() const override;
  int postConditions() const override;
  void initParameters(const MeshDocument &document, RichParameterList &params) const override;
  void apply(FilterRun &run) const override;
};

} // namespace vbrdf_plugin
