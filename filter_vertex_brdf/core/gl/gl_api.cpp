#include "gl/gl_api.h"

#include <cstdio>
#include <vector>

#include "base/errors.h"

namespace vbrdf {

namespace {

std::string hex_code(unsigned code) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04X", code);
  return buf;
}

std::string named_code(const char *name, unsigned code) {
  return std::string(name) + " (" + hex_code(code) + ")";
}

// Capabilities that alter rasterisation, saved by GlStateGuard and cleared by
// set_plain_raster_state (GL_DEPTH_TEST is saved too; passes enable it themselves).
const GLenum kCoreCaps[] = {GL_DEPTH_TEST,        GL_CULL_FACE,         GL_BLEND,
                            GL_SCISSOR_TEST,      GL_STENCIL_TEST,      GL_DEPTH_CLAMP,
                            GL_RASTERIZER_DISCARD, GL_POLYGON_OFFSET_FILL, GL_PRIMITIVE_RESTART,
                            GL_POLYGON_SMOOTH,    GL_CLIP_DISTANCE0,    GL_CLIP_DISTANCE1,
                            GL_CLIP_DISTANCE2,    GL_CLIP_DISTANCE3,    GL_CLIP_DISTANCE4,
                            GL_CLIP_DISTANCE5,    GL_CLIP_DISTANCE6,    GL_CLIP_DISTANCE7};
// Compatibility-profile only (not in glcorearb.h): they still apply with shaders bound.
const GLenum kGlAlphaTest = 0x0BC0, kGlPolygonStipple = 0x0B42;
const GLenum kCompatCaps[] = {kGlAlphaTest, kGlPolygonStipple};

int raster_caps(const GlApi &gl, GLenum *out) {
  int n = 0;
  for (GLenum cap : kCoreCaps) out[n++] = cap;
  if (gl.compatibility_profile)
    for (GLenum cap : kCompatCaps) out[n++] = cap;
  return n;
}

std::string shader_log(const GlApi &gl, GLuint shader) {
  GLint len = 0;
  gl.GetShaderiv(shader, GL_INFO_LOG_LENGTH, &len);
  std::vector<char> log(size_t(len > 1 ? len : 1), '\0');
  gl.GetShaderInfoLog(shader, GLsizei(log.size()), nullptr, log.data());
  return log.data();
}

std::string program_log(const GlApi &gl, GLuint program) {
  GLint len = 0;
  gl.GetProgramiv(program, GL_INFO_LOG_LENGTH, &len);
  std::vector<char> log(size_t(len > 1 ? len : 1), '\0');
  gl.GetProgramInfoLog(program, GLsizei(log.size()), nullptr, log.data());
  return log.data();
}

const char *stage_name(GLenum stage) {
  switch (stage) {
  case GL_VERTEX_SHADER: return "vertex";
  case GL_FRAGMENT_SHADER: return "fragment";
  case GL_GEOMETRY_SHADER: return "geometry";
  case GL_COMPUTE_SHADER: return "compute";
  default: return "unknown-stage";
  }
}

// Some loaders hand out non-null stubs for unknown names, so the version is what really decides.
void read_version(GlApi &gl) {
  gl.GetIntegerv(GL_MAJOR_VERSION, &gl.major_version);
  gl.GetIntegerv(GL_MINOR_VERSION, &gl.minor_version);
  if (gl.GetError() != GL_NO_ERROR) gl.major_version = gl.minor_version = 0;  // pre-3.0 context
  GLint mask = 0;
  if (gl.version_at_least(3, 2)) gl.GetIntegerv(GL_CONTEXT_PROFILE_MASK, &mask);
  // Without a profile mask (3.0/3.1) everything deprecated is still there.
  gl.compatibility_profile = !gl.version_at_least(3, 2) || (mask & GL_CONTEXT_COMPATIBILITY_PROFILE_BIT);
  gl.GetError();
}

} // namespace

std::string GlApi::version_string() const {
  const char *version = GetString ? reinterpret_cast<const char *>(GetString(GL_VERSION)) : nullptr;
  const char *renderer = GetString ? reinterpret_cast<const char *>(GetString(GL_RENDERER)) : nullptr;
  return std::string(version ? version : "?") + " (" + (renderer ? renderer : "?") + ")";
}

GlApi load_gl_api(const GetProcAddressFn &get_proc) {
  if (!get_proc) throw ProcessingError("OpenGL: no get-proc-address function was given to load the GL entry points.");
  GlApi gl;
  const char *missing = nullptr;
#define VBRDF_GL_LOAD_REQUIRED(type, name)                                                         \
  gl.name = reinterpret_cast<type>(get_proc("gl" #name));                                          \
  if (!gl.name && !missing) missing = "gl" #name;
  VBRDF_GL_CORE_33(VBRDF_GL_LOAD_REQUIRED)
#undef VBRDF_GL_LOAD_REQUIRED
  if (missing)
    throw ProcessingError(std::string("OpenGL: entry point ") + missing +
                          " is missing from the current context (an OpenGL 3.3 context is required).");

  read_version(gl);
  if (!gl.version_at_least(3, 3))
    throw ProcessingError("OpenGL: the current context is " + gl.version_string() +
                          "; the GPU passes need OpenGL 3.3 or newer.");

  bool all_compute = true;
#define VBRDF_GL_LOAD_OPTIONAL(type, name)                                                         \
  gl.name = reinterpret_cast<type>(get_proc("gl" #name));                                          \
  all_compute = all_compute && gl.name;
  VBRDF_GL_COMPUTE_43(VBRDF_GL_LOAD_OPTIONAL)
#undef VBRDF_GL_LOAD_OPTIONAL
  gl.has_compute = all_compute && gl.version_at_least(4, 3);
  return gl;
}

void require_compute(const GlApi &gl, const std::string &what) {
  if (gl.has_compute) return;
  std::string missing;
#define VBRDF_GL_FIND_MISSING(type, name)                                                          \
  if (!gl.name && missing.empty()) missing = "gl" #name;
  VBRDF_GL_COMPUTE_43(VBRDF_GL_FIND_MISSING)
#undef VBRDF_GL_FIND_MISSING
  throw ProcessingError(what + " needs OpenGL 4.3 compute shaders, but the context is " + gl.version_string() +
                        (missing.empty() ? std::string() : " (entry point " + missing + " is missing)") + ".");
}

std::string gl_error_name(GLenum error) {
  switch (error) {
  case GL_NO_ERROR: return named_code("GL_NO_ERROR", error);
  case GL_INVALID_ENUM: return named_code("GL_INVALID_ENUM", error);
  case GL_INVALID_VALUE: return named_code("GL_INVALID_VALUE", error);
  case GL_INVALID_OPERATION: return named_code("GL_INVALID_OPERATION", error);
  case GL_INVALID_FRAMEBUFFER_OPERATION: return named_code("GL_INVALID_FRAMEBUFFER_OPERATION", error);
  case GL_OUT_OF_MEMORY: return named_code("GL_OUT_OF_MEMORY", error);
  case GL_STACK_UNDERFLOW: return named_code("GL_STACK_UNDERFLOW", error);
  case GL_STACK_OVERFLOW: return named_code("GL_STACK_OVERFLOW", error);
  default: return "GL error " + hex_code(error);
  }
}

std::string gl_framebuffer_status_name(GLenum status) {
  switch (status) {
  case GL_FRAMEBUFFER_COMPLETE: return named_code("GL_FRAMEBUFFER_COMPLETE", status);
  case GL_FRAMEBUFFER_UNDEFINED: return named_code("GL_FRAMEBUFFER_UNDEFINED", status);
  case GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT: return named_code("GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT", status);
  case GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT:
    return named_code("GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT", status);
  case GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER: return named_code("GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER", status);
  case GL_FRAMEBUFFER_INCOMPLETE_READ_BUFFER: return named_code("GL_FRAMEBUFFER_INCOMPLETE_READ_BUFFER", status);
  case GL_FRAMEBUFFER_UNSUPPORTED: return named_code("GL_FRAMEBUFFER_UNSUPPORTED", status);
  case GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE: return named_code("GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE", status);
  case GL_FRAMEBUFFER_INCOMPLETE_LAYER_TARGETS:
    return named_code("GL_FRAMEBUFFER_INCOMPLETE_LAYER_TARGETS", status);
  default: return "framebuffer status " + hex_code(status);
  }
}

void clear_gl_errors(const GlApi &gl) {
  // Bounded: a lost context may report an error forever.
  for (int i = 0; i < 32 && gl.GetError() != GL_NO_ERROR; ++i) {
  }
}

void check_gl_error(const GlApi &gl, const std::string &what) {
  const GLenum first = gl.GetError();
  if (first == GL_NO_ERROR) return;
  clear_gl_errors(gl);
  throw ProcessingError("OpenGL error " + gl_error_name(first) + " during " + what + ".");
}

void check_framebuffer(const GlApi &gl, GLenum target, const std::string &what) {
  const GLenum status = gl.CheckFramebufferStatus(target);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw ProcessingError("OpenGL framebuffer for " + what + " is incomplete: " + gl_framebuffer_status_name(status) +
                          ".");
}

GLuint compile_shader(const GlApi &gl, GLenum stage, const char *source, const std::string &label) {
  const GLuint shader = gl.CreateShader(stage);
  if (!shader)
    throw ProcessingError("OpenGL: cannot create the " + std::string(stage_name(stage)) + " shader of " + label + ".");
  gl.ShaderSource(shader, 1, &source, nullptr);
  gl.CompileShader(shader);
  GLint ok = GL_FALSE;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    const std::string log = shader_log(gl, shader);
    gl.DeleteShader(shader);
    throw ProcessingError("OpenGL: the " + std::string(stage_name(stage)) + " shader of " + label +
                          " does not compile: " + log);
  }
  return shader;
}

GLuint link_program(const GlApi &gl, const GLuint *shaders, size_t count, const std::string &label) {
  const GLuint program = gl.CreateProgram();
  if (!program) throw ProcessingError("OpenGL: cannot create the program of " + label + ".");
  for (size_t i = 0; i < count; ++i) gl.AttachShader(program, shaders[i]);
  gl.LinkProgram(program);
  for (size_t i = 0; i < count; ++i) gl.DetachShader(program, shaders[i]);
  GLint ok = GL_FALSE;
  gl.GetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    const std::string log = program_log(gl, program);
    gl.DeleteProgram(program);
    throw ProcessingError("OpenGL: the program of " + label + " does not link: " + log);
  }
  return program;
}

GLuint build_program(const GlApi &gl, const char *vertex_src, const char *fragment_src, const std::string &label) {
  const GLuint vs = compile_shader(gl, GL_VERTEX_SHADER, vertex_src, label);
  GLuint fs = 0;
  try {
    fs = compile_shader(gl, GL_FRAGMENT_SHADER, fragment_src, label);
    const GLuint stages[] = {vs, fs};
    const GLuint program = link_program(gl, stages, 2, label);
    gl.DeleteShader(vs);
    gl.DeleteShader(fs);
    return program;
  } catch (...) {
    gl.DeleteShader(vs);
    if (fs) gl.DeleteShader(fs);
    throw;
  }
}

GLuint build_compute_program(const GlApi &gl, const char *compute_src, const std::string &label) {
  require_compute(gl, label);
  const GLuint cs = compile_shader(gl, GL_COMPUTE_SHADER, compute_src, label);
  try {
    const GLuint program = link_program(gl, &cs, 1, label);
    gl.DeleteShader(cs);
    return program;
  } catch (...) {
    gl.DeleteShader(cs);
    throw;
  }
}

void set_plain_raster_state(const GlApi &gl) {
  GLenum caps[GlStateGuard::kMaxCaps];
  const int n = raster_caps(gl, caps);
  for (int i = 0; i < n; ++i) gl.Disable(caps[i]);
  gl.DepthFunc(GL_LESS);
  gl.DepthMask(GL_TRUE);
  gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  gl.PolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  gl.ClampColor(GL_CLAMP_READ_COLOR, GL_FALSE);
}

GlStateGuard::GlStateGuard(const GlApi &gl) : gl_(gl) {
  static_assert(sizeof(kCoreCaps) / sizeof(kCoreCaps[0]) + sizeof(kCompatCaps) / sizeof(kCompatCaps[0]) <= kMaxCaps,
                "kMaxCaps too small");
  gl.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw_fbo_);
  gl.GetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &read_fbo_);
  gl.GetIntegerv(GL_RENDERBUFFER_BINDING, &renderbuffer_);
  gl.GetIntegerv(GL_CURRENT_PROGRAM, &program_);
  gl.GetIntegerv(GL_VERTEX_ARRAY_BINDING, &vao_);
  gl.GetIntegerv(GL_ARRAY_BUFFER_BINDING, &array_buffer_);
  gl.GetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &pack_buffer_);
  gl.GetIntegerv(GL_PIXEL_UNPACK_BUFFER_BINDING, &unpack_buffer_);
  gl.GetIntegerv(GL_VIEWPORT, viewport_);
  gl.GetIntegerv(GL_PACK_ALIGNMENT, &pack_alignment_);
  gl.GetIntegerv(GL_PACK_ROW_LENGTH, &pack_row_length_);
  gl.GetIntegerv(GL_PACK_SKIP_ROWS, &pack_skip_rows_);
  gl.GetIntegerv(GL_PACK_SKIP_PIXELS, &pack_skip_pixels_);
  gl.GetIntegerv(GL_UNPACK_ALIGNMENT, &unpack_alignment_);
  gl.GetIntegerv(GL_UNPACK_ROW_LENGTH, &unpack_row_length_);
  gl.GetIntegerv(GL_UNPACK_SKIP_ROWS, &unpack_skip_rows_);
  gl.GetIntegerv(GL_UNPACK_SKIP_PIXELS, &unpack_skip_pixels_);
  gl.GetIntegerv(GL_ACTIVE_TEXTURE, &active_texture_);
  gl.GetIntegerv(GL_TEXTURE_BINDING_2D, &texture_2d_);
  gl.GetIntegerv(GL_DEPTH_FUNC, &depth_func_);
  gl.GetIntegerv(GL_POLYGON_MODE, polygon_mode_);
  gl.GetBooleanv(GL_DEPTH_WRITEMASK, &depth_mask_);
  gl.GetBooleanv(GL_COLOR_WRITEMASK, color_mask_);
  gl.GetIntegerv(GL_CLAMP_READ_COLOR, &clamp_read_color_);
  cap_count_ = raster_caps(gl, cap_names_);
  for (int i = 0; i < cap_count_; ++i) caps_[i] = gl.IsEnabled(cap_names_[i]);
}

GlStateGuard::~GlStateGuard() {
  const GlApi &gl = gl_;
  for (int i = 0; i < cap_count_; ++i) (caps_[i] ? gl.Enable : gl.Disable)(cap_names_[i]);
  gl.ClampColor(GL_CLAMP_READ_COLOR, GLenum(clamp_read_color_));
  gl.ColorMask(color_mask_[0], color_mask_[1], color_mask_[2], color_mask_[3]);
  gl.DepthMask(depth_mask_);
  gl.DepthFunc(GLenum(depth_func_));
  if (polygon_mode_[0] == polygon_mode_[1]) {
    gl.PolygonMode(GL_FRONT_AND_BACK, GLenum(polygon_mode_[0]));
  } else {  // only possible (and legal) in a compatibility context
    gl.PolygonMode(GL_FRONT, GLenum(polygon_mode_[0]));
    gl.PolygonMode(GL_BACK, GLenum(polygon_mode_[1]));
  }
  gl.BindTexture(GL_TEXTURE_2D, GLuint(texture_2d_));
  gl.ActiveTexture(GLenum(active_texture_));
  gl.PixelStorei(GL_UNPACK_SKIP_PIXELS, unpack_skip_pixels_);
  gl.PixelStorei(GL_UNPACK_SKIP_ROWS, unpack_skip_rows_);
  gl.PixelStorei(GL_UNPACK_ROW_LENGTH, unpack_row_length_);
  gl.PixelStorei(GL_UNPACK_ALIGNMENT, unpack_alignment_);
  gl.PixelStorei(GL_PACK_SKIP_PIXELS, pack_skip_pixels_);
  gl.PixelStorei(GL_PACK_SKIP_ROWS, pack_skip_rows_);
  gl.PixelStorei(GL_PACK_ROW_LENGTH, pack_row_length_);
  gl.PixelStorei(GL_PACK_ALIGNMENT, pack_alignment_);
  gl.Viewport(viewport_[0], viewport_[1], viewport_[2], viewport_[3]);
  gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, GLuint(unpack_buffer_));
  gl.BindBuffer(GL_PIXEL_PACK_BUFFER, GLuint(pack_buffer_));
  gl.BindBuffer(GL_ARRAY_BUFFER, GLuint(array_buffer_));
  gl.BindVertexArray(GLuint(vao_));
  gl.UseProgram(GLuint(program_));
  gl.BindRenderbuffer(GL_RENDERBUFFER, GLuint(renderbuffer_));
  gl.BindFramebuffer(GL_READ_FRAMEBUFFER, GLuint(read_fbo_));
  gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, GLuint(draw_fbo_));
}

SsboBindingGuard::SsboBindingGuard(const GlApi &gl) : gl_(gl) {
  gl.GetIntegerv(GL_SHADER_STORAGE_BUFFER_BINDING, &generic_);
  for (GLuint i = 0; i < kCount; ++i) {
    gl.GetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, i, &buffer_[i]);
    gl.GetIntegeri_v(GL_SHADER_STORAGE_BUFFER_START, i, &start_[i]);
    gl.GetIntegeri_v(GL_SHADER_STORAGE_BUFFER_SIZE, i, &size_[i]);
  }
}

SsboBindingGuard::~SsboBindingGuard() {
  for (GLuint i = 0; i < kCount; ++i) {
    if (buffer_[i] && size_[i] > 0)
      gl_.BindBufferRange(GL_SHADER_STORAGE_BUFFER, i, GLuint(buffer_[i]), start_[i], size_[i]);
    else
      gl_.BindBufferBase(GL_SHADER_STORAGE_BUFFER, i, GLuint(buffer_[i]));
  }
  gl_.BindBuffer(GL_SHADER_STORAGE_BUFFER, GLuint(generic_));
}

} // namespace vbrdf
