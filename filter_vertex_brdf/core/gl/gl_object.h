#pragma once
// An owned GL object: its name and the GL call that frees it, called once when the handle is
// destroyed, reset or assigned. A class that owns GL objects holds them in GlObjects and needs no
// release code of its own; a constructor that throws half-way frees what it had made.
//
// The handle keeps a pointer to the GlApi it was made with: that GlApi must outlive it (declare it
// before the handles in a class), and its context must be current whenever a handle frees (as for
// every GL call). No GL header here (gl_api.h is for .cpp files only): names are unsigned (GLuint).
namespace vbrdf {

struct GlApi;

enum class GlKind { Buffer, VertexArray, Texture, Framebuffer, Renderbuffer, Program, Shader };

class GlObject {
public:
  GlObject() = default;  // no object: name 0, nothing to free
  // A new name of `kind` from glGen* (Buffer, VertexArray, Texture, Framebuffer, Renderbuffer).
  static GlObject generate(const GlApi &gl, GlKind kind);
  // Takes ownership of `name` (0: none), e.g. a program that build_program linked.
  static GlObject adopt(const GlApi &gl, GlKind kind, unsigned name);

  ~GlObject() { reset(); }
  GlObject(GlObject &&other) noexcept : gl_(other.gl_), kind_(other.kind_), name_(other.name_) { other.name_ = 0; }
  GlObject &operator=(GlObject &&other) noexcept;
  GlObject(const GlObject &) = delete;
  GlObject &operator=(const GlObject &) = delete;

  unsigned get() const { return name_; }
  operator unsigned() const { return name_; }  // the GLuint, wherever GL takes one; 0 when none
  void reset();                                // frees the object (if any); the name is 0 after

private:
  GlObject(const GlApi *gl, GlKind kind, unsigned name) : gl_(gl), kind_(kind), name_(name) {}
  const GlApi *gl_ = nullptr;
  GlKind kind_ = GlKind::Buffer;
  unsigned name_ = 0;
};

} // namespace vbrdf
