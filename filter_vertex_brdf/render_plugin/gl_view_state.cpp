// Reading MeshLab's fixed-function view state (gl_view_state.h).
#include <GL/glew.h>

#include "gl_view_state.h"

namespace vbrdf_render {

vbrdf::LiveView current_gl_view() {
  vbrdf::LiveView view;
  glGetDoublev(GL_MODELVIEW_MATRIX, view.modelview);
  glGetDoublev(GL_PROJECTION_MATRIX, view.projection);
  glGetLightfv(GL_LIGHT0, GL_POSITION, view.light_eye);
  return view;
}

} // namespace vbrdf_render
