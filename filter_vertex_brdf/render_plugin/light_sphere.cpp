// The light sphere (light_sphere.h).
#include <GL/glew.h>

#include "light_sphere.h"

#include <cmath>

#include "core/base/angles.h"

namespace vbrdf_render {

void draw_light_sphere(const std::array<float, 3> &c, float r, const std::vector<std::array<float, 3>> &photo_lights,
                       const std::array<float, 3> &current) {
  glPushAttrib(GL_ENABLE_BIT | GL_CURRENT_BIT | GL_POINT_BIT | GL_LINE_BIT);
  GLint program = 0;
  glGetIntegerv(GL_CURRENT_PROGRAM, &program);
  glUseProgram(0);
  glDisable(GL_LIGHTING);
  glDisable(GL_TEXTURE_2D);
  glEnable(GL_DEPTH_TEST);
  glEnable(GL_POINT_SMOOTH);
  // Three great circles give the sphere its shape.
  glLineWidth(1.0f);
  glColor3f(0.55f, 0.55f, 0.6f);
  for (int axis = 0; axis < 3; ++axis) {
    glBegin(GL_LINE_LOOP);
    for (int i = 0; i < 96; ++i) {
      const float a = 2.0f * vbrdf::kPiF * float(i) / 96.0f;
      float p[3] = {0, 0, 0};
      p[(axis + 1) % 3] = r * std::cos(a);
      p[(axis + 2) % 3] = r * std::sin(a);
      glVertex3f(c[0] + p[0], c[1] + p[1], c[2] + p[2]);
    }
    glEnd();
  }
  glPointSize(7.0f);
  glColor3f(1.0f, 0.85f, 0.1f);
  glBegin(GL_POINTS);
  for (const auto &d : photo_lights) glVertex3f(c[0] + r * d[0], c[1] + r * d[1], c[2] + r * d[2]);
  glEnd();
  glLineWidth(2.0f);
  glColor3f(1.0f, 0.35f, 0.1f);
  glBegin(GL_LINES);
  glVertex3f(c[0], c[1], c[2]);
  glVertex3f(c[0] + r * current[0], c[1] + r * current[1], c[2] + r * current[2]);
  glEnd();
  glPointSize(12.0f);
  glBegin(GL_POINTS);
  glVertex3f(c[0] + r * current[0], c[1] + r * current[1], c[2] + r * current[2]);
  glEnd();
  glUseProgram(GLuint(program));
  glPopAttrib();
}

} // namespace vbrdf_render
