#pragma once
// "Vertex BRDF: export for the web": a saved fit result (the result PLY) as a GLB and the viewer
// pages beside it (core: publish/web_export.h; docs/web.md), with the photo lights and viewpoints
// of the document's visible rasters. The same as the command-line tool vbrdf-web-export.
#include "plugin_filter.h"

namespace vbrdf_plugin {

class WebExportFilter : public PluginFilter {
public:
  QString name() const override;
  QString info() const override;
  host::FilterInterface::FilterClass filterClass() const override;
  int postConditions() const override;
  void initParameters(const MeshDocument &document, RichParameterList &params) const override;
  void apply(FilterRun &run) const override;
};

} // namespace vbrdf_plugin
