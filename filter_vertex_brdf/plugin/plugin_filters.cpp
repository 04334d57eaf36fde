#include "plugin_filters.h"

#include "coverage_filter.h"
#include "fit_filter.h"
#include "import_photos_filter.h"
#include "load_result_filter.h"
#include "relight_filter.h"
#include "show_colors_filter.h"
#include "sphere_filter.h"

namespace vbrdf_plugin {

std::vector<std::unique_ptr<PluginFilter>> make_plugin_filters() {
  std::vector<std::unique_ptr<PluginFilter>> filters;
  filters.emplace_back(new FitFilter());
  filters.emplace_back(new RelightFilter());
  filters.emplace_back(new SphereFilter());
  filters.emplace_back(new CoverageFilter());
  filters.emplace_back(new ImportPhotosFilter());
  filters.emplace_back(new LoadResultFilter());
  filters.emplace_back(new ShowColorsFilter());
  add_host_filters(filters);
  return filters;
}

} // namespace vbrdf_plugin
