#pragma once
// The two back-end choices of a fit run, each with its factory: visibility (GL depth passes or the
// CPU ray caster) and the per-vertex reflectance fit (GPU compute shader or CPU reference). Both keep one
// contract whichever runs (visibility.h, reflectance_fit.h); the factories log which one runs and why.
#include <memory>
#include <string>

#include "base/callbacks.h"
#include "base/mesh_view.h"
#include "fit/reflectance_fit.h"
#include "gl/gl_context.h"  // GetProcAddressFn
#include "visibility/visibility.h"

namespace vbrdf {

enum class VisibilityChoice { Auto = 0, GL = 1, CPU = 2 };
enum class FitBackendChoice { Auto = 0, GPU = 1, CPU = 2 };

// GL when `get_proc` is given and the context supports it (unless CPU is forced), else CPU.
// Throws ProcessingError when GL was asked for explicitly and cannot run.
std::unique_ptr<VisibilityBackend> make_visibility_backend(const MeshView &mesh, VisibilityChoice choice,
                                                           const VisibilitySettings &settings,
                                                           const GetProcAddressFn &get_proc, const LogFn &log);

// The per-vertex Reflectance fit back end (reflectance_fit.h): GPU compute shader or CPU reference.
class ReflectanceFitter {
public:
  virtual ~ReflectanceFitter() = default;
  virtual const char *name() const = 0;
  virtual void fit_chunk(const SampleChunk &chunk, const ReflectanceFitOptions &options, VertexFit *out) = 0;
};

// GPU when `get_proc` is given and the context has compute shaders (unless CPU is forced),
// else CPU. Auto also takes the CPU when the GL context is a software renderer (llvmpipe and
// the like), where the shader is slower than the CPU reference; the fitter's name (in the report)
// says so. Throws ProcessingError when GPU was asked for explicitly and cannot run. The GL
// context must stay current while the fitter is used.
std::unique_ptr<ReflectanceFitter> make_reflectance_fitter(FitBackendChoice choice, const GetProcAddressFn &get_proc,
                                               const LogFn &log);

} // namespace vbrdf
