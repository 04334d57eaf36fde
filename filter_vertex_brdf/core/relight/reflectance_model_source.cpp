// Assembly of the shared reflectance model shader (contract in reflectance_model_source.h).
#include "relight/reflectance_model_source.h"

#include <algorithm>
#include <cmath>

#include "base/errors.h"
#include "gl/gl_api.h"
#include "vbrdf_shaders.h"

namespace vbrdf {

namespace {

// "#version 330 core", the embedded shader `file`, then `body`; #line <line> <source string>:
// 1 = the file, 2 = the caller's main.
std::string program_source(const char *file, const char *body) {
  const char *text = shaders::find(file);
  if (text == nullptr)
    throw ProcessingError(std::string("The shader ") + file + " is not embedded in this build: rebuild the plugin.");
  return std::string("#version 330 core\n#line 1 1\n") + text + "\n#line 1 2\n" + body;
}

} // namespace

std::string reflectance_program_source(const char *body) { return program_source("reflectance_model.glsl", body); }

std::string vertex_program_source(const char *body) { return program_source("subpixel_grid.glsl", body); }

void set_reflectance_model_uniforms(const GlApi &gl, unsigned program, LobeForm lobe) {
  gl.Uniform1i(gl.GetUniformLocation(program, "u_half_angle_lobe"), lobe != LobeForm::PhongRE ? 1 : 0);
  gl.Uniform1i(gl.GetUniformLocation(program, "u_ggx_lobe"), lobe == LobeForm::GgxNH ? 1 : 0);
  gl.Uniform1f(gl.GetUniformLocation(program, "u_coat_index"), kCoatIndex);
  gl.Uniform1f(gl.GetUniformLocation(program, "u_coat_min_cosine"), kCoatMinCosine);
}

float typical_shininess(const std::vector<VertexFit> &fits) {
  std::vector<float> a;
  for (const VertexFit &f : fits)
    if (f.ks > 0 && f.shininess > 0 && std::isfinite(f.shininess)) a.push_back(f.shininess);
  if (a.empty()) return 1.0f;
  std::nth_element(a.begin(), a.begin() + long(a.size() / 2), a.end());
  return a[a.size() / 2];
}

ModelMeshBuffers upload_model_mesh(const GlApi &gl, const MeshView &mesh, const double origin[3],
                                   const std::vector<VertexFit> &fits, const DiffuseForms &diffuse) {
  constexpr int kFloats = 16;
  const float alpha_default = typical_shininess(fits);
  std::vector<float> data(mesh.vertex_count * kFloats);
  for (size_t v = 0; v < mesh.vertex_count; ++v) {
    float *o = &data[v * kFloats];
    const VertexFit &f = fits[v];
    for (int k = 0; k < 3; ++k) {
      o[k] = float(double(mesh.positions[3 * v + k]) - origin[k]);
      o[3 + k] = mesh.normals[3 * v + k];
      o[6 + k] = f.kd * f.color[k];
    }
    o[9] = f.status == kFitNone ? 0.0f : 1.0f;
    o[10] = f.ks;
    o[11] = f.ks > 0 && f.shininess > 0 ? f.shininess : alpha_default;
    o[12] = diffuse.at(v) == DiffuseForm::Coated ? 1.0f : 0.0f;
    o[13] = float(f.status);
    o[14] = std::isfinite(f.dq) ? f.dq : 0.0f;
    o[15] = std::isfinite(f.sq) ? f.sq : 0.0f;
  }
  ModelMeshBuffers b;
  b.index_count = mesh.index_count;
  b.vao = GlObject::generate(gl, GlKind::VertexArray);
  gl.BindVertexArray(b.vao);
  b.vbo = GlObject::generate(gl, GlKind::Buffer);
  gl.BindBuffer(GL_ARRAY_BUFFER, b.vbo);
  gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(), GL_STATIC_DRAW);
  const GLsizei stride = kFloats * sizeof(float);
  const int sizes[5] = {3, 3, 4, 3, 3}, offsets[5] = {0, 3, 6, 10, 13};
  for (GLuint a = 0; a < 5; ++a) {
    gl.VertexAttribPointer(a, sizes[a], GL_FLOAT, GL_FALSE, stride,
                           reinterpret_cast<const void *>(size_t(offsets[a]) * sizeof(float)));
    gl.EnableVertexAttribArray(a);
  }
  b.ibo = GlObject::generate(gl, GlKind::Buffer);
  gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, b.ibo);  // recorded in our VAO only
  gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(mesh.index_count * sizeof(uint32_t)), mesh.indices,
                GL_STATIC_DRAW);
  return b;
}

void release_model_mesh(const GlApi &, ModelMeshBuffers &b) {
  b.vao.reset(), b.vbo.reset(), b.ibo.reset();
  b = ModelMeshBuffers();
}

} // namespace vbrdf
