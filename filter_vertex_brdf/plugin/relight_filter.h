#pragma once
// "Vertex BRDF: relight and compare": renders the fitted per-vertex reflectance model (the attributes the
// fit filter stores on the mesh, or a saved result PLY) from every raster's camera under its light
// and compares it with the photos (images, contact sheet, CSV table), and/or renders a novel
// viewpoint under a light the user gives. The mesh is not changed.
#include <string>

#include "core/relight/orbit_camera.h"
#include "core/relight/relight_render.h"
#include "core/relight/relight_report.h"
#include "plugin_filter.h"

namespace vbrdf_plugin {

class RelightFilter : public PluginFilter {
public:
  QString name() const override;
  QString info() const override;
  host::FilterInterface::FilterClass filterClass() const override;
  int preConditions() const override;
  int postConditions() const override;
  void initParameters(const MeshDocument &document, RichParameterList &params) const override;
  void apply(FilterRun &run) const override;

  struct Settings {
    std::string fit_result_ply, raster_project, light_file, output_folder;  // as given ("" = default)
    float dome_radius = 0, light_unit_scale = 0;  // light_source.h LightPlacement
    bool render_rasters = true, novel_view = false;
    int view_raster = 0;
    float azimuth = 0, elevation = 0, distance_scale = 1;  // orbit of the novel view (degrees, factor)
    float novel_light[3] = {0, 0, 1};                       // unit, in the novel camera's frame
    vbrdf::RelightRenderSettings render;
    vbrdf::RelightOutputOptions output;
  };
  // Filter parameters -> settings (paths not yet resolved). Throws vbrdf::InputError naming the
  // parameter when a value is out of range or nothing is to be rendered.
  static Settings settings_from(const RichParameterList &params);
};

} // namespace vbrdf_plugin
