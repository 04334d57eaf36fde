#pragma once
// Runs a filter and turns what it throws into the one message every host shows (the 2020.09
// plugin's errorMessage and log line, the 2025.07 plugin's MLException, PyMeshLab's
// PyMeshLabException): the same words under every MeshLab.
#include <string>

#include "plugin_filter.h"

namespace vbrdf_plugin {

// Applies `filter`; "" when it succeeded, else the reason, with fields named as the dialog labels
// them (the script name in brackets).
std::string apply_filter(const PluginFilter &filter, FilterRun &run);

} // namespace vbrdf_plugin
