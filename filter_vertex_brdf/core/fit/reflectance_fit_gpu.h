#pragma once
// GPU back end of the per-vertex reflectance fit: the contract of reflectance_fit.h (same model, objective,
// remedies, method, safeguards, normalisation and sentinels as fit_chunk_cpu), evaluated in
// float32 by a GLSL 4.30 compute shader (shaders/reflectance_fit.comp), one invocation per vertex.
// Results agree with the double-precision reference to ~1e-3 relative on well-conditioned
// vertices; on ill-conditioned ones float rounding can change a step decision (see
// tests/unit/test_reflectance_fit_gpu.cpp for the measured spread).
//
// GL: entry points come from the caller's get-proc-address (no GL library, no GLEW). The pass
// leaves the context's bindings as it found them (GlStateGuard plus the SSBO bindings it uses).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "fit/reflectance_fit.h"
#include "samples/samples.h"
#include "gl/gl_context.h"  // GetProcAddressFn

namespace vbrdf {

class ReflectanceFitGpu {
public:
  // Compiles the shader in the context current on the calling thread, which must be OpenGL >= 4.3
  // with compute shaders. Throws ProcessingError naming what is missing (version, entry point,
  // compile log) so that callers can fall back to fit_chunk_cpu. The same context must be current
  // for every later call and for the destructor.
  explicit ReflectanceFitGpu(const GetProcAddressFn &get_proc);
  ~ReflectanceFitGpu();
  ReflectanceFitGpu(const ReflectanceFitGpu &) = delete;
  ReflectanceFitGpu &operator=(const ReflectanceFitGpu &) = delete;

  // Fits every vertex of `chunk` into out[0 .. chunk.vertex_count) (same contract as
  // fit_chunk_cpu). The chunk is streamed in dispatches of at most batch_vertices() vertices and
  // batch_bytes() bytes of samples. Throws ProcessingError on a malformed chunk (offsets not
  // monotone or past the samples), on a vertex whose samples exceed the GL storage-block limit,
  // or on a GL error; `out` is then partly written.
  void fit_chunk(const SampleChunk &chunk, const ReflectanceFitOptions &options, VertexFit *out);

  // Vertices per dispatch (default 65536): bounds one dispatch's run time, since display GPUs
  // reset after ~2 s (watchdog). Values < 64 are raised to 64.
  void set_batch_vertices(uint32_t vertices);
  uint32_t batch_vertices() const;
  // Sample bytes per dispatch (default: min(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, 64 MiB)); a
  // request above the GL limit is lowered to it. Tests lower it to exercise the splitting.
  void set_batch_bytes(size_t bytes);
  size_t batch_bytes() const;

  // GL_VERSION (GL_RENDERER) of the context, for logs.
  std::string device() const;
  // Dispatches issued by the last fit_chunk.
  size_t last_dispatch_count() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace vbrdf
