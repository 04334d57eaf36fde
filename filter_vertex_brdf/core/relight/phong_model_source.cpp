// Assembly of the shared Phong model shader (contract in phong_model_source.h).
#include "relight/phong_model_source.h"

#include <algorithm>
#include <cmath>

#include "base/errors.h"
#include "gl/gl_api.h"
#include "vbrdf_shaders.h"

namespace vbrdf {

std::string phong_program_source(const char *body) {
  const char *model = shaders::find("phong_model.glsl");
  if (model == nullptr)
    throw ProcessingError("The Phong model shader (phong_model.glsl) is not embedded in this build: rebuild the plugin.");
  // #line <line> <source string>: 1 = the model, 2 = the caller's main.
  return std::string("#version 330 core\n#line 1 1\n") + model + "\n#line 1 2\n" + body;
}

void set_phong_model_uniforms(const GlApi &gl, unsigned program, LobeForm lobe) {
  gl.Uniform1i(gl.GetUniformLocation(program, "u_half_angle_lobe"), lobe == LobeForm::BlinnNH ? 1 : 0);
  gl.Uniform1f(gl.GetUniformLocation(program, "u_coat_index"), kCoatIndex);
  gl.Uniform1f(gl.GetUniformLocation(program, "u_coat_min_n_dot_e"), kCoatMinNdotE);
}

float typical_shininess(const std::vector<VertexFit> &fits) {
  std::vector<float> a;
  for (const VertexFit &f : fits)
    if (f.ks > 0 && f.shininess > 0 && std::isfinite(f.shininess)) a.push_back(f.shininess);
  if (a.empty()) return 1.0f;
  std::nth_element(a.begin(), a.begin() + long(a.size() / 2), a.end());
  return a[a.size() / 2];
}

} // namespace vbrdf
