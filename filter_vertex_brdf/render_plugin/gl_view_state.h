#pragma once
// The view MeshLab has set up when it calls a render plugin, read from the fixed-function state:
// GL_MODELVIEW_MATRIX (view and trackball, without the layer matrix: our arrays carry it),
// GL_PROJECTION_MATRIX and GL_LIGHT0's position, which GLArea::drawLight sets from its light
// trackball (Ctrl+Shift+drag) and GL stores in eye coordinates. Needs MeshLab's (compatibility)
// context current and GLEW initialised.
#include "core/relight/live_relight.h"

namespace vbrdf_render {

// The view, light, with display/exposure left at their defaults.
vbrdf::LiveView current_gl_view();

} // namespace vbrdf_render
