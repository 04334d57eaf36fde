#pragma once
// Off-screen OpenGL for unit tests and tools: an OSMesa (Mesa llvmpipe) core-profile context,
// created and made current on the calling thread for the object's lifetime. The GL passes render
// into their own FBOs, so the window-system buffer is tiny. Does not include any GL header (the
// core's gl_api.h uses glcorearb.h; mixing it with osmesa.h / gl.h in one file breaks).
#include <memory>
#include <string>
#include <vector>

#include "visibility/visibility_gl.h"  // vbrdf::GetProcAddressFn

struct osmesa_context;  // OSMesaContext is `struct osmesa_context *`

namespace vbrdf {
namespace test {

class OsMesaContext {
public:
  enum class Profile {
    kCore,           // 4.5, else 4.3, else 3.3
    kCompatibility,  // what MeshLab's filters get (Mesa hands out its highest compatibility version)
  };

  // Throws std::runtime_error listing every attempt when no context can be created or made current.
  explicit OsMesaContext(Profile profile = Profile::kCore, int width = 8, int height = 8);
  ~OsMesaContext();
  OsMesaContext(const OsMesaContext &) = delete;
  OsMesaContext &operator=(const OsMesaContext &) = delete;

  // Same as the constructor, but returns null and the reason in *why (for GTEST_SKIP).
  static std::unique_ptr<OsMesaContext> try_create(std::string *why, Profile profile = Profile::kCore,
                                                   int width = 8, int height = 8);

  // Makes this context current again on the calling thread.
  void make_current();
  // Resolves GL entry points with OSMesaGetProcAddress (for make_gl_visibility / load_gl_api).
  GetProcAddressFn get_proc_address() const;

  const std::string &version() const { return version_; }    // GL_VERSION
  const std::string &renderer() const { return renderer_; }  // GL_RENDERER
  int major_version() const { return major_; }
  int minor_version() const { return minor_; }

private:
  osmesa_context *context_ = nullptr;
  std::vector<unsigned char> buffer_;  // RGBA8 colour buffer OSMesa renders the default FB into
  int width_ = 0, height_ = 0, major_ = 0, minor_ = 0;
  std::string version_, renderer_;
};

} // namespace test
} // namespace vbrdf
