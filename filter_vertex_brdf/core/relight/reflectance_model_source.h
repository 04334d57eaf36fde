#pragma once
// The shared reflectance model shader (shaders/reflectance_model.glsl, embedded in the library) and what its
// users share on the CPU side: the relight renderer (relight_render.h) and the live view
// (live_relight.h) build their fragment shaders as reflectance_program_source(their main), set the
// model's uniforms with set_reflectance_model_uniforms, and draw the fit from one vertex buffer
// (upload_model_mesh; k_s = 0 vertices get typical_shininess).
#include <cstddef>
#include <string>
#include <vector>

#include "base/mesh_view.h"
#include "fit/reflectance_fit.h"
#include "gl/gl_object.h"
#include "model/diffuse_form.h"
#include "model/lobe.h"

namespace vbrdf {

struct GlApi;

// "#version 330 core", the model's functions (reflectance_terms, diffuse_factor, lobe_cosine, ...), then
// `body` (#line directives keep compiler messages pointing into the right part). Throws
// ProcessingError when the library was built without the embedded shader.
std::string reflectance_program_source(const char *body);

// "#version 330 core", shaders/subpixel_grid.glsl (snap_to_subpixel_grid), then `body`: the vertex
// shader of every renderer of the model (the relight renderer's and the live view's; the web viewer
// starts its own with the same file), so that all place vertices alike. Throws ProcessingError when
// the library was built without the shader.
std::string vertex_program_source(const char *body);

// Sets reflectance_model.glsl's uniforms of `program` (which must be in use) for the fit's lobe form and
// the coat's constants (the diffuse form is a per-vertex attribute of the callers).
void set_reflectance_model_uniforms(const GlApi &gl, unsigned program, LobeForm lobe);

// The shininess given to k_s = 0 vertices: the median of the fitted lobes (k_s > 0, alpha > 0,
// finite), 1 when there is none.
float typical_shininess(const std::vector<VertexFit> &fits);

// The fitted mesh as both renderers draw it: one interleaved buffer, 16 floats per vertex, at
// attribute locations
//   0 vec3 position, relative to `origin` (precision of far-from-origin coordinates)
//   1 vec3 normal (as stored)
//   2 vec4 (k_d C, fitted: 0 for fit_status 0, else 1)
//   3 vec3 (k_s, alpha: typical_shininess where k_s = 0, coated: 1 where diffuse[v] is Coated)
//   4 vec3 (fit_status, DQ, SQ; NaN quality as 0): the live view's false colours
// and the mesh's indices, recorded in a new vertex array object (left bound). `fits` and
// `diffuse` have one entry per vertex.
// The objects free themselves (GlObject).
struct ModelMeshBuffers {
  GlObject vao, vbo, ibo;
  size_t index_count = 0;
};
ModelMeshBuffers upload_model_mesh(const GlApi &gl, const MeshView &mesh, const double origin[3],
                                   const std::vector<VertexFit> &fits, const DiffuseForms &diffuse);
// Deletes what upload_model_mesh created now (the context must be current) and zeroes `buffers`.
void release_model_mesh(const GlApi &gl, ModelMeshBuffers &buffers);

} // namespace vbrdf
