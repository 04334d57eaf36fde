#include "osmesa_context.h"

#include <GL/osmesa.h>

#include <stdexcept>
#include <utility>
#include <vector>

namespace vbrdf {
namespace test {

namespace {

OSMesaContext create_context(int profile, int major, int minor) {
  const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA,
                         OSMESA_DEPTH_BITS, 24,
                         OSMESA_STENCIL_BITS, 8,
                         OSMESA_PROFILE, profile,
                         OSMESA_CONTEXT_MAJOR_VERSION, major,
                         OSMESA_CONTEXT_MINOR_VERSION, minor,
                         0};
  return OSMesaCreateContextAttribs(attribs, nullptr);
}

std::string gl_string(GLenum name) {
  const GLubyte *s = glGetString(name);
  return s ? reinterpret_cast<const char *>(s) : "";
}

} // namespace

OsMesaContext::OsMesaContext(Profile profile, int width, int height)
    : buffer_(size_t(width > 0 ? width : 1) * size_t(height > 0 ? height : 1) * 4),
      width_(width > 0 ? width : 1), height_(height > 0 ? height : 1) {
  const bool core = profile == Profile::kCore;
  // Compatibility: "at least 3.0", Mesa returns its highest compatibility version.
  const std::vector<std::pair<int, int>> versions =
      core ? std::vector<std::pair<int, int>>{{4, 5}, {4, 3}, {3, 3}} : std::vector<std::pair<int, int>>{{3, 0}};
  std::string tried;
  for (const auto &v : versions) {
    context_ = create_context(core ? OSMESA_CORE_PROFILE : OSMESA_COMPAT_PROFILE, v.first, v.second);
    if (context_) break;
    tried += (tried.empty() ? "" : ", ") + std::to_string(v.first) + "." + std::to_string(v.second);
  }
  if (!context_)
    throw std::runtime_error(std::string("OSMesa: OSMesaCreateContextAttribs refused every ") +
                             (core ? "core" : "compatibility") + " profile (" + tried + ")");
  try {
    make_current();
  } catch (...) {
    OSMesaDestroyContext(context_);  // the destructor does not run when the constructor throws
    throw;
  }
  version_ = gl_string(GL_VERSION);
  renderer_ = gl_string(GL_RENDERER);
  glGetIntegerv(GL_MAJOR_VERSION, &major_);
  glGetIntegerv(GL_MINOR_VERSION, &minor_);
}

OsMesaContext::~OsMesaContext() {
  if (OSMesaGetCurrentContext() == context_) OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
  OSMesaDestroyContext(context_);
}

std::unique_ptr<OsMesaContext> OsMesaContext::try_create(std::string *why, Profile profile, int width, int height) {
  try {
    return std::unique_ptr<OsMesaContext>(new OsMesaContext(profile, width, height));
  } catch (const std::exception &e) {
    if (why) *why = e.what();
    return nullptr;
  }
}

void OsMesaContext::make_current() {
  if (!OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, width_, height_))
    throw std::runtime_error("OSMesa: OSMesaMakeCurrent failed for a " + std::to_string(width_) + "x" +
                             std::to_string(height_) + " RGBA buffer");
}

GetProcAddressFn OsMesaContext::get_proc_address() const {
  return [](const char *name) -> void * { return reinterpret_cast<void *>(OSMesaGetProcAddress(name)); };
}

} // namespace test
} // namespace vbrdf
