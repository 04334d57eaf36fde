// The filters only the MeshLab 2025.07 / PyMeshLab build offers: none. The web export stays with
// the 2020.09 build (its GLB writer links Debian's shared tinygltf, which a PyMeshLab install
// lacks); vbrdf-web-export writes the same files from a result this build fitted.
#include "plugin_filters.h"

namespace vbrdf_plugin {

void add_host_filters(std::vector<std::unique_ptr<PluginFilter>> &) {}

} // namespace vbrdf_plugin
