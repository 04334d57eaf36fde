#include "gl/gl_object.h"

#include <stdexcept>

#include "gl/gl_api.h"

namespace vbrdf {

GlObject GlObject::generate(const GlApi &gl, GlKind kind) {
  GLuint name = 0;
  switch (kind) {
  case GlKind::Buffer: gl.GenBuffers(1, &name); break;
  case GlKind::VertexArray: gl.GenVertexArrays(1, &name); break;
  case GlKind::Texture: gl.GenTextures(1, &name); break;
  case GlKind::Framebuffer: gl.GenFramebuffers(1, &name); break;
  case GlKind::Renderbuffer: gl.GenRenderbuffers(1, &name); break;
  case GlKind::Program:
  case GlKind::Shader: throw std::logic_error("GlObject::generate: programs and shaders are adopted");
  }
  return GlObject(&gl, kind, name);
}

GlObject GlObject::adopt(const GlApi &gl, GlKind kind, unsigned name) { return GlObject(&gl, kind, name); }

GlObject &GlObject::operator=(GlObject &&other) noexcept {
  if (this != &other) {
    reset();
    gl_ = other.gl_, kind_ = other.kind_, name_ = other.name_;
    other.name_ = 0;
  }
  return *this;
}

void GlObject::reset() {
  if (name_ == 0 || gl_ == nullptr) return;
  const GlApi &gl = *gl_;
  const GLuint name = name_;
  name_ = 0;
  switch (kind_) {
  case GlKind::Buffer: gl.DeleteBuffers(1, &name); break;
  case GlKind::VertexArray: gl.DeleteVertexArrays(1, &name); break;
  case GlKind::Texture: gl.DeleteTextures(1, &name); break;
  case GlKind::Framebuffer: gl.DeleteFramebuffers(1, &name); break;
  case GlKind::Renderbuffer: gl.DeleteRenderbuffers(1, &name); break;
  case GlKind::Program: gl.DeleteProgram(name); break;
  case GlKind::Shader: gl.DeleteShader(name); break;
  }
}

} // namespace vbrdf
