#pragma once
// "Vertex BRDF: import new photos of a viewpoint": the between-shots step of an acquisition.
// New photos taken from an already registered camera position become raster layers that copy that
// raster's shot (the photographer never re-aligns within a viewpoint); their lights come from an
// .lp or are estimated from the reflective sphere in the photos (core/sphere_lights.h); then the
// coverage and the next-light suggestions are updated (CoverageFilter::run_on_document).
#include <string>
#include <vector>

#include "core/calibration/sphere_lights.h"
#include "plugin_filter.h"

namespace vbrdf_plugin {

class ImportPhotosFilter : public PluginFilter {
public:
  QString name() const override;
  QString info() const override;
  host::FilterInterface::FilterClass filterClass() const override;
  int requirements() const override;
  int preConditions() const override;
  int postConditions() const override;
  void initParameters(const MeshDocument &document, RichParameterList &params) const override;
  void apply(FilterRun &run) const override;

  struct Settings {
    std::vector<std::string> photo_files;  // as given (resolved later); empty: the photo folder's new images
    std::string photo_folder;              // "": the reference raster's photo folder
    int reference_raster = -1;             // -1: the last raster (checked against the document later)
    bool lights_from_sphere = false;       // false: from the light file
    std::string light_file;                // "": the default light-file rule
    vbrdf::SphereCircle sphere;            // r == 0: find the sphere
    std::string output_light_file;         // sphere mode; "": <project>_lights.lp
    bool update_coverage = true;           // then run the coverage filter's defaults
  };
  // Filter parameters -> settings. Throws vbrdf::InputError naming the parameter when a value is
  // out of range.
  static Settings settings_from(const RichParameterList &params);
};

} // namespace vbrdf_plugin
