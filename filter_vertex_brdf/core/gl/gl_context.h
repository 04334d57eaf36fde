#pragma once
// How the core reaches the caller's OpenGL context: a get-proc-address function (MeshLab's
// context in the plugin, OSMesa in tests). The core links no GL library; every GL pass (gl_api.h
// and the passes built on it) resolves its entry points through this.
#include <functional>

namespace vbrdf {

using GetProcAddressFn = std::function<void *(const char *name)>;

} // namespace vbrdf
