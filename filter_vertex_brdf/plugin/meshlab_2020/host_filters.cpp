// The filters only the MeshLab 2020.09 build offers: the web export, whose GLB writer links
// Debian's shared tinygltf (a PyMeshLab install has no such library; there, vbrdf-web-export of
// the 2020.09 build writes the same files).
#include "plugin_filters.h"
#include "web_export_filter.h"

namespace vbrdf_plugin {

void add_host_filters(std::vector<std::unique_ptr<PluginFilter>> &filters) { filters.emplace_back(new WebExportFilter()); }

} // namespace vbrdf_plugin
