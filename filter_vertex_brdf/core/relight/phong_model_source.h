#pragma once
// The shared Phong model shader (shaders/phong_model.glsl, embedded in the library) and what its
// users share on the CPU side: the relight renderer (relight_render.h) and the live view
// (live_relight.h) build their fragment shaders as phong_program_source(their main), set the
// model's uniforms with set_phong_model_uniforms and give k_s = 0 vertices typical_shininess.
#include <string>
#include <vector>

#include "fit/phong_fit.h"
#include "samples/diffuse_form.h"
#include "samples/lobe.h"

namespace vbrdf {

struct GlApi;

// "#version 330 core", the model's functions (phong_terms, diffuse_factor, lobe_cosine, ...), then
// `body` (#line directives keep compiler messages pointing into the right part). Throws
// ProcessingError when the library was built without the embedded shader.
std::string phong_program_source(const char *body);

// Sets phong_model.glsl's uniforms of `program` (which must be in use) for the fit's lobe form and
// the coat's constants (the diffuse form is a per-vertex attribute of the callers).
void set_phong_model_uniforms(const GlApi &gl, unsigned program, LobeForm lobe);

// The shininess given to k_s = 0 vertices: the median of the fitted lobes (k_s > 0, alpha > 0,
// finite), 1 when there is none.
float typical_shininess(const std::vector<VertexFit> &fits);

} // namespace vbrdf
