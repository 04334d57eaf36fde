#pragma once
// Every filter of the plugin, in menu / FilterIDType order: the plugin registers this list and the
// plugin tests check each of its filters, so a new filter is covered by both once appended here.
#include <memory>
#include <vector>

#include "plugin_filter.h"

namespace vbrdf_plugin {

// Append new filters at the end: a filter's index is its FilterIDType.
std::vector<std::unique_ptr<PluginFilter>> make_plugin_filters();

// Appends the filters only this host's build offers, after the shared ones (defined by the host
// adapter's folder: meshlab_<version>/host_filters.cpp).
void add_host_filters(std::vector<std::unique_ptr<PluginFilter>> &filters);

} // namespace vbrdf_plugin
