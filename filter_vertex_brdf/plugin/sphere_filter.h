#pragma once
// "Vertex BRDF: estimate light directions from a reflective sphere": finds the mirror sphere(s) in
// the photos of one viewpoint (or takes their outlines from the parameters), turns each photo's
// highlight into a light direction and writes an RTI .lp for the fit filter. The mesh is not changed.
#include <string>
#include <vector>

#include "core/inputs/photo.h"
#include "core/calibration/sphere_lights.h"
#include "plugin_filter.h"

namespace vbrdf_plugin {

class SphereFilter : public PluginFilter {
public:
  QString name() const override;
  QString info() const override;
  host::FilterInterface::FilterClass filterClass() const override;
  int postConditions() const override;
  void initParameters(const MeshDocument &document, RichParameterList &params) const override;
  void apply(FilterRun &run) const override;

  struct Settings {
    int viewpoint_raster = -1;                // -1: MeshLab's current raster
    std::vector<vbrdf::SphereCircle> manual;  // outlines given by hand; empty: detect
    int sphere_count = 1;                     // spheres to detect
    double radius_world = 0;                  // spheres' radius in mesh units; 0: unknown
    vbrdf::PhotoEncoding encoding = vbrdf::PhotoEncoding::Auto;
    std::string output;                       // output .lp as given (resolved later); "": default
  };
  // Filter parameters -> settings. Throws vbrdf::InputError naming the parameter when a value is
  // out of range or the second sphere is given without the first.
  static Settings settings_from(const RichParameterList &params);
};

} // namespace vbrdf_plugin
