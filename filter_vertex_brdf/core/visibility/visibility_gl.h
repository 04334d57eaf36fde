#pragma once
// GL back end of the visibility contract (visibility.h): depth passes rendered with OpenGL in the
// caller's current context (MeshLab's context in the plugin, OSMesa in unit tests). The core does
// not link any GL library: entry points are resolved through the caller's get-proc-address.
#include <functional>
#include <memory>

#include "gl/gl_context.h"
#include "visibility/visibility.h"

namespace vbrdf {

// Requires a current OpenGL >= 3.3 context (core or compatibility) for the whole lifetime of the
// returned object. Throws ProcessingError (naming the missing entry point or GL error) when the
// context cannot run the passes; callers then fall back to make_cpu_visibility.
std::unique_ptr<VisibilityBackend> make_gl_visibility(const MeshView &mesh, const GetProcAddressFn &get_proc,
                                                      const VisibilitySettings &settings);

} // namespace vbrdf
