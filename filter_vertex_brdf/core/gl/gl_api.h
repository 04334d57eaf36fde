#pragma once
// A small OpenGL function table for the core's GPU passes, resolved through the caller's
// get-proc-address (MeshLab's context in the plugin, OSMesa in tests): the core links no GL library
// and does not use GLEW. Internal to the core: include it only from .cpp files, never together with
// glew.h / gl.h in one translation unit (glcorearb.h and those headers redefine each other's
// tokens). Members carry no "gl" prefix so that GLEW's macros (#define glBindBuffer ...) could not
// rewrite them even if that ever happened.
//
// To add an entry point: append X(PFNGL<NAME>PROC, <Name>) to the right list below.
#include <GL/glcorearb.h>

#include <cstddef>
#include <string>

#include "gl/gl_context.h"  // GetProcAddressFn

// OpenGL 3.3 core: required by every pass.
#define VBRDF_GL_CORE_33(X)                                                                        \
  X(PFNGLGETERRORPROC, GetError)                                                                   \
  X(PFNGLGETINTEGERVPROC, GetIntegerv)                                                             \
  X(PFNGLGETINTEGERI_VPROC, GetIntegeri_v)                                                         \
  X(PFNGLGETBOOLEANVPROC, GetBooleanv)                                                             \
  X(PFNGLGETFLOATVPROC, GetFloatv)                                                                 \
  X(PFNGLGETSTRINGPROC, GetString)                                                                 \
  X(PFNGLGETSTRINGIPROC, GetStringi)                                                               \
  X(PFNGLENABLEPROC, Enable)                                                                       \
  X(PFNGLDISABLEPROC, Disable)                                                                     \
  X(PFNGLISENABLEDPROC, IsEnabled)                                                                 \
  X(PFNGLVIEWPORTPROC, Viewport)                                                                   \
  X(PFNGLDEPTHFUNCPROC, DepthFunc)                                                                 \
  X(PFNGLDEPTHMASKPROC, DepthMask)                                                                 \
  X(PFNGLCOLORMASKPROC, ColorMask)                                                                 \
  X(PFNGLCLAMPCOLORPROC, ClampColor)                                                               \
  X(PFNGLPOLYGONMODEPROC, PolygonMode)                                                             \
  X(PFNGLCLEARBUFFERFVPROC, ClearBufferfv)                                                         \
  X(PFNGLPIXELSTOREIPROC, PixelStorei)                                                             \
  X(PFNGLREADPIXELSPROC, ReadPixels)                                                               \
  X(PFNGLREADBUFFERPROC, ReadBuffer)                                                               \
  X(PFNGLDRAWBUFFERSPROC, DrawBuffers)                                                             \
  X(PFNGLFINISHPROC, Finish)                                                                       \
  X(PFNGLFLUSHPROC, Flush)                                                                         \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                                                               \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                                                         \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                                                               \
  X(PFNGLBUFFERDATAPROC, BufferData)                                                               \
  X(PFNGLBUFFERSUBDATAPROC, BufferSubData)                                                         \
  X(PFNGLGETBUFFERSUBDATAPROC, GetBufferSubData)                                                   \
  X(PFNGLMAPBUFFERRANGEPROC, MapBufferRange)                                                       \
  X(PFNGLUNMAPBUFFERPROC, UnmapBuffer)                                                             \
  X(PFNGLBINDBUFFERBASEPROC, BindBufferBase)                                                       \
  X(PFNGLBINDBUFFERRANGEPROC, BindBufferRange)                                                     \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                                                     \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                                               \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                                                     \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)                                             \
  X(PFNGLVERTEXATTRIBIPOINTERPROC, VertexAttribIPointer)                                           \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)                                     \
  X(PFNGLDRAWARRAYSPROC, DrawArrays)                                                               \
  X(PFNGLDRAWELEMENTSPROC, DrawElements)                                                           \
  X(PFNGLGENTEXTURESPROC, GenTextures)                                                             \
  X(PFNGLDELETETEXTURESPROC, DeleteTextures)                                                       \
  X(PFNGLBINDTEXTUREPROC, BindTexture)                                                             \
  X(PFNGLACTIVETEXTUREPROC, ActiveTexture)                                                         \
  X(PFNGLTEXIMAGE2DPROC, TexImage2D)                                                               \
  X(PFNGLTEXSUBIMAGE2DPROC, TexSubImage2D)                                                         \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri)                                                         \
  X(PFNGLGETTEXIMAGEPROC, GetTexImage)                                                             \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                                                     \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                                               \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                                                     \
  X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)                                           \
  X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer)                                     \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)                                       \
  X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers)                                                   \
  X(PFNGLDELETERENDERBUFFERSPROC, DeleteRenderbuffers)                                             \
  X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer)                                                   \
  X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage)                                             \
  X(PFNGLCREATESHADERPROC, CreateShader)                                                           \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                                                           \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                                                         \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                                                             \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                                                   \
  X(PFNGLDELETESHADERPROC, DeleteShader)                                                           \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)                                                         \
  X(PFNGLATTACHSHADERPROC, AttachShader)                                                           \
  X(PFNGLDETACHSHADERPROC, DetachShader)                                                           \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                                                             \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                                           \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                                                 \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                                                               \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                                                         \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                                               \
  X(PFNGLGETUNIFORMBLOCKINDEXPROC, GetUniformBlockIndex)                                           \
  X(PFNGLUNIFORMBLOCKBINDINGPROC, UniformBlockBinding)                                             \
  X(PFNGLUNIFORM1IPROC, Uniform1i)                                                                 \
  X(PFNGLUNIFORM1UIPROC, Uniform1ui)                                                               \
  X(PFNGLUNIFORM1FPROC, Uniform1f)                                                                 \
  X(PFNGLUNIFORM2FPROC, Uniform2f)                                                                 \
  X(PFNGLUNIFORM3FPROC, Uniform3f)                                                                 \
  X(PFNGLUNIFORM4FPROC, Uniform4f)                                                                 \
  X(PFNGLUNIFORM3FVPROC, Uniform3fv)                                                               \
  X(PFNGLUNIFORM4FVPROC, Uniform4fv)                                                               \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)                                                   \
  X(PFNGLFENCESYNCPROC, FenceSync)                                                                 \
  X(PFNGLCLIENTWAITSYNCPROC, ClientWaitSync)                                                       \
  X(PFNGLDELETESYNCPROC, DeleteSync)

// OpenGL 4.3: compute shaders, SSBOs, image load/store. Optional (null when the context is older).
#define VBRDF_GL_COMPUTE_43(X)                                                                     \
  X(PFNGLDISPATCHCOMPUTEPROC, DispatchCompute)                                                     \
  X(PFNGLMEMORYBARRIERPROC, MemoryBarrier)                                                         \
  X(PFNGLBINDIMAGETEXTUREPROC, BindImageTexture)                                                   \
  X(PFNGLTEXSTORAGE2DPROC, TexStorage2D)                                                           \
  X(PFNGLGETPROGRAMRESOURCEINDEXPROC, GetProgramResourceIndex)                                     \
  X(PFNGLSHADERSTORAGEBLOCKBINDINGPROC, ShaderStorageBlockBinding)                                 \
  X(PFNGLCLEARBUFFERDATAPROC, ClearBufferData)                                                     \
  X(PFNGLCOPYBUFFERSUBDATAPROC, CopyBufferSubData)

namespace vbrdf {

struct GlApi {
#define VBRDF_GL_MEMBER(type, name) type name = nullptr;
  VBRDF_GL_CORE_33(VBRDF_GL_MEMBER)
  VBRDF_GL_COMPUTE_43(VBRDF_GL_MEMBER)
#undef VBRDF_GL_MEMBER

  int major_version = 0;  // context version (GL_MAJOR_VERSION / GL_MINOR_VERSION)
  int minor_version = 0;
  bool compatibility_profile = false;  // MeshLab's context is; OSMesa's test context is core
  // True when the context is >= 4.3 and every VBRDF_GL_COMPUTE_43 entry point resolved.
  bool has_compute = false;

  bool version_at_least(int major, int minor) const {
    return major_version > major || (major_version == major && minor_version >= minor);
  }
  // GL_VERSION and GL_RENDERER strings, for messages and logs.
  std::string version_string() const;
};

// Resolves the table in the current context. Throws ProcessingError naming the first missing 3.3
// entry point, or when the context is older than 3.3. Missing 4.3 entry points only clear
// has_compute.
GlApi load_gl_api(const GetProcAddressFn &get_proc);

// Throws ProcessingError (naming `what` and the first missing entry point or the version) when the
// context cannot run compute shaders.
void require_compute(const GlApi &gl, const std::string &what);

// "GL_INVALID_OPERATION (0x0502)"; unknown codes in hex.
std::string gl_error_name(GLenum error);
// "GL_FRAMEBUFFER_UNSUPPORTED (0x8CDD)".
std::string gl_framebuffer_status_name(GLenum status);

// Drains glGetError; throws ProcessingError "OpenGL error ... during <what>." if any was pending.
void check_gl_error(const GlApi &gl, const std::string &what);
// Clears pending errors without reporting them (e.g. errors left by the host before our pass).
void clear_gl_errors(const GlApi &gl);
// Throws ProcessingError when the framebuffer bound to `target` is not complete.
void check_framebuffer(const GlApi &gl, GLenum target, const std::string &what);

// Compiles one shader stage; throws ProcessingError with the info log on failure.
GLuint compile_shader(const GlApi &gl, GLenum stage, const char *source, const std::string &label);
// Links the given stages into a program (stages are detached, not deleted); throws with the log.
GLuint link_program(const GlApi &gl, const GLuint *shaders, size_t count, const std::string &label);
// Vertex + fragment program from sources; intermediate shaders are deleted.
GLuint build_program(const GlApi &gl, const char *vertex_src, const char *fragment_src,
                     const std::string &label);
// Compute program from source (requires has_compute).
GLuint build_compute_program(const GlApi &gl, const char *compute_src, const std::string &label);

// Switches off every capability the host may have left on that would alter a pass's rasterisation
// (blending, culling, scissor, stencil, polygon offset, clip distances, and alpha test / polygon
// stipple in compatibility contexts), sets filled polygons, full colour/depth writes with
// GL_LESS, and unclamped read-back. Call it inside a GlStateGuard.
void set_plain_raster_state(const GlApi &gl);

// Saves the GL state the core's passes change and restores it on destruction, so that the host's
// rendering (MeshLab's) is unaffected: framebuffer and buffer bindings, program, VAO, viewport,
// pixel pack/unpack parameters, active texture and its 2D binding, depth/colour write state,
// polygon mode, read clamping and the capabilities set_plain_raster_state switches off.
class GlStateGuard {
public:
  explicit GlStateGuard(const GlApi &gl);
  ~GlStateGuard();
  GlStateGuard(const GlStateGuard &) = delete;
  GlStateGuard &operator=(const GlStateGuard &) = delete;

  static constexpr int kMaxCaps = 24;  // capabilities tracked (see set_plain_raster_state)

private:
  const GlApi &gl_;
  GLint draw_fbo_ = 0, read_fbo_ = 0, renderbuffer_ = 0, program_ = 0, vao_ = 0;
  GLint array_buffer_ = 0, pack_buffer_ = 0, unpack_buffer_ = 0;
  GLint viewport_[4] = {0, 0, 0, 0};
  GLint pack_alignment_ = 4, pack_row_length_ = 0, pack_skip_rows_ = 0, pack_skip_pixels_ = 0;
  GLint unpack_alignment_ = 4, unpack_row_length_ = 0, unpack_skip_rows_ = 0, unpack_skip_pixels_ = 0;
  GLint active_texture_ = GL_TEXTURE0, texture_2d_ = 0;
  GLint depth_func_ = GL_LESS;
  GLint polygon_mode_[2] = {GL_FILL, GL_FILL};  // front, back (they differ only in compatibility contexts)
  GLboolean depth_mask_ = GL_TRUE;
  GLboolean color_mask_[4] = {GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE};
  GLint clamp_read_color_ = GL_FIXED_ONLY;
  GLenum cap_names_[kMaxCaps] = {};
  GLboolean caps_[kMaxCaps] = {};
  int cap_count_ = 0;
};

// Saves and restores the shader-storage buffer bindings 0..3 and the generic SSBO binding of a
// compute pass (GlStateGuard does not cover them). Needs has_compute.
class SsboBindingGuard {
public:
  explicit SsboBindingGuard(const GlApi &gl);
  ~SsboBindingGuard();
  SsboBindingGuard(const SsboBindingGuard &) = delete;
  SsboBindingGuard &operator=(const SsboBindingGuard &) = delete;

private:
  static constexpr GLuint kCount = 4;  // bindings 0..3
  const GlApi &gl_;
  GLint generic_ = 0, buffer_[kCount] = {}, start_[kCount] = {}, size_[kCount] = {};
};

} // namespace vbrdf
