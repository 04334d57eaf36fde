#include "fit/fit_backends.h"

#include <algorithm>
#include <cctype>

#include "base/errors.h"
#include "fit/reflectance_fit_gpu.h"
#include "visibility/visibility_gl.h"

namespace vbrdf {

std::unique_ptr<VisibilityBackend> make_visibility_backend(const MeshView &mesh, VisibilityChoice choice,
                                                           const VisibilitySettings &settings,
                                                           const GetProcAddressFn &get_proc, const LogFn &log) {
  if (choice != VisibilityChoice::CPU) {
    if (!get_proc) {
      if (choice == VisibilityChoice::GL)
        throw ProcessingError("'Visibility' is set to GPU (OpenGL), but no GL context is available: set 'Visibility' "
                              "to Auto or CPU (ray cast).");
      log("Visibility: no GL context, using the CPU ray caster.");
    } else {
      try {
        auto gl = make_gl_visibility(mesh, get_proc, settings);
        log(std::string("Visibility: ") + gl->name() + ".");
        return gl;
      } catch (const ProcessingError &e) {
        if (choice == VisibilityChoice::GL)
          throw ProcessingError(std::string("'Visibility' is set to GPU (OpenGL), but ") + e.what() +
                                " Set 'Visibility' to Auto or CPU (ray cast).");
        log(std::string("Visibility: GL depth passes unavailable (") + e.what() + "); using the CPU ray caster.");
      }
    }
  }
  auto cpu = make_cpu_visibility(mesh, settings);
  log(std::string("Visibility: ") + cpu->name() + ".");
  return cpu;
}

namespace {

class CpuFitter : public ReflectanceFitter {
public:
  // `why`: how it came to be chosen, appended to the name (the report shows it).
  explicit CpuFitter(const std::string &why = "") : name_("CPU (double, OpenMP)" + (why.empty() ? "" : "; " + why)) {}
  const char *name() const override { return name_.c_str(); }
  void fit_chunk(const SampleChunk &chunk, const ReflectanceFitOptions &o, VertexFit *out) override {
    fit_chunk_cpu(chunk, o, out);
  }

private:
  std::string name_;
};

class GpuFitter : public ReflectanceFitter {
public:
  explicit GpuFitter(const GetProcAddressFn &get_proc) : gpu_(get_proc), name_("GPU compute shader, " + gpu_.device()) {}
  const char *name() const override { return name_.c_str(); }
  std::string device() const { return gpu_.device(); }
  void fit_chunk(const SampleChunk &chunk, const ReflectanceFitOptions &o, VertexFit *out) override {
    gpu_.fit_chunk(chunk, o, out);
  }

private:
  ReflectanceFitGpu gpu_;
  std::string name_;
};

// True for GL implementations that rasterise on the CPU (Mesa llvmpipe/softpipe/swrast, lavapipe,
// Microsoft's GDI renderer), judged from GL_RENDERER. There the compute shader runs on the same
// cores as the CPU fit, and slower
// (tests/benchmark/FIT_PERFORMANCE.md: the CPU reference is 2.4-3.7x faster at the same error).
bool is_software_renderer(const std::string &gl_renderer) {
  std::string d = gl_renderer;
  std::transform(d.begin(), d.end(), d.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  for (const char *name : {"llvmpipe", "softpipe", "swrast", "software rasterizer", "lavapipe", "gdi generic"})
    if (d.find(name) != std::string::npos) return true;
  return false;
}

} // namespace


std::unique_ptr<ReflectanceFitter> make_reflectance_fitter(FitBackendChoice choice, const GetProcAddressFn &get_proc,
                                               const LogFn &log) {
  if (choice != FitBackendChoice::CPU) {
    if (get_proc) {
      try {
        std::unique_ptr<GpuFitter> gpu(new GpuFitter(get_proc));
        if (choice == FitBackendChoice::Auto && is_software_renderer(gpu->device())) {
          std::unique_ptr<ReflectanceFitter> cpu(new CpuFitter(
              "Auto chose it over the compute shader: the GL context is a software renderer (" + gpu->device() + ")"));
          log(std::string("Reflectance fit: ") + cpu->name() + ". Set 'Fit back end' to GPU to use the shader anyway.");
          return cpu;
        }
        log(std::string("Reflectance fit: ") + gpu->name() + ".");
        return std::unique_ptr<ReflectanceFitter>(gpu.release());
      } catch (const ProcessingError &e) {
        if (choice == FitBackendChoice::GPU)
          throw ProcessingError(std::string("'Fit back end' is set to GPU (compute shader), but ") + e.what() +
                                " Set 'Fit back end' to Auto or CPU (reference).");
        log(std::string("Reflectance fit: GPU back end unavailable (") + e.what() + "); using the CPU reference.");
      }
    } else if (choice == FitBackendChoice::GPU) {
      throw ProcessingError("'Fit back end' is set to GPU (compute shader), but no GL context is available: set "
                            "'Fit back end' to Auto or CPU (reference).");
    }
  }
  std::unique_ptr<ReflectanceFitter> cpu(new CpuFitter());
  log(std::string("Reflectance fit: ") + cpu->name() + ".");
  return cpu;
}

} // namespace vbrdf
