#include "io/result_schema.h"

#include <algorithm>
#include <cmath>

#include "base/errors.h"

namespace vbrdf {

namespace {
// A stored float as a whole number in [0, max] (NaN gives 0).
float whole(float v, float max) { return std::isnan(v) ? 0.0f : std::min(max, std::max(0.0f, std::round(v))); }

using K = AttributeKind;
using G = AttributeGroup;
using R = VertexRecord;

std::vector<ResultAttribute> make_schema() {
  return {
      {"diffuse_r", K::Real, G::Always, false, "linear diffuse reflectance k_d C, red (0 without a model)",
       [](const R &r) { return r.diffuse[0]; }, [](R &r, float v) { r.diffuse[0] = v; }},
      {"diffuse_g", K::Real, G::Always, false, "linear diffuse reflectance k_d C, green",
       [](const R &r) { return r.diffuse[1]; }, [](R &r, float v) { r.diffuse[1] = v; }},
      {"diffuse_b", K::Real, G::Always, false, "linear diffuse reflectance k_d C, blue",
       [](const R &r) { return r.diffuse[2]; }, [](R &r, float v) { r.diffuse[2] = v; }},
      {"n_visible", K::Count, G::Always, false, "photos that see the vertex",
       [](const R &r) { return r.n_visible; }, [](R &r, float v) { r.n_visible = v; }},
      {"n_diffuse", K::Count, G::Always, false, "usable diffuse samples",
       [](const R &r) { return r.n_diffuse; }, [](R &r, float v) { r.n_diffuse = v; }},
      {"n_specular", K::Count, G::Always, false, "clean highlight samples",
       [](const R &r) { return r.n_specular; }, [](R &r, float v) { r.n_specular = v; }},
      {"coloured", K::Code, G::Always, false,
       "0 kept its input colour, 1 from clean pixels, 2 only from pixels at a silhouette or contact, 3 from neighbours",
       [](const R &r) { return r.coloured; }, [](R &r, float v) { r.coloured = v; }},
      {"kd", K::Real, G::ReflectanceFit, true, "k_d", [](const R &r) { return r.fit.kd; },
       [](R &r, float v) { r.fit.kd = v; }},
      {"ks", K::Real, G::ReflectanceFit, true, "k_s", [](const R &r) { return r.fit.ks; },
       [](R &r, float v) { r.fit.ks = v; }},
      {"shininess", K::Real, G::ReflectanceFit, true, "shininess alpha (0: not determined, k_s = 0)",
       [](const R &r) { return r.fit.shininess; }, [](R &r, float v) { r.fit.shininess = v; }},
      {"color_r", K::Real, G::ReflectanceFit, true, "colour C, red (linear, largest channel 1)",
       [](const R &r) { return r.fit.color[0]; }, [](R &r, float v) { r.fit.color[0] = v; }},
      {"color_g", K::Real, G::ReflectanceFit, true, "colour C, green",
       [](const R &r) { return r.fit.color[1]; }, [](R &r, float v) { r.fit.color[1] = v; }},
      {"color_b", K::Real, G::ReflectanceFit, true, "colour C, blue",
       [](const R &r) { return r.fit.color[2]; }, [](R &r, float v) { r.fit.color[2] = v; }},
      {"dq", K::Real, G::ReflectanceFit, false, "diffuse quality (0..2, higher is better; thesis 4.7.1)",
       [](const R &r) { return r.fit.dq; }, [](R &r, float v) { r.fit.dq = v; }},
      {"sq", K::Real, G::ReflectanceFit, false, "specular quality (0..2, higher is better)",
       [](const R &r) { return r.fit.sq; }, [](R &r, float v) { r.fit.sq = v; }},
      {"fit_rmse", K::Real, G::ReflectanceFit, false, "N.L-weighted RMS residual of the fit per channel",
       [](const R &r) { return r.fit.rmse; }, [](R &r, float v) { r.fit.rmse = v; }},
      {"fit_status", K::Code, G::ReflectanceFit, true,
       "0 none, 1 diffuse-only, 2 full fit, 3 from neighbours, 4 from weak samples",
       [](const R &r) { return float(r.fit.status); }, [](R &r, float v) { r.fit.status = uint8_t(whole(v, 255.0f)); }},
      {"fit_iterations", K::Count, G::ReflectanceFit, false, "shininess iterations run",
       [](const R &r) { return float(r.fit.iterations); },
       [](R &r, float v) { r.fit.iterations = uint16_t(whole(v, 65535.0f)); }},
      {"material", K::Code, G::ReflectanceFit, false,
       "material found from the data (materials = on): 1..K, listed in the report; 0 none (stage off, or no model)",
       [](const R &r) { return r.material; }, [](R &r, float v) { r.material = whole(v, 65535.0f); }},
      {"lobe_form", K::Code, G::ReflectanceFit, false,
       "the specular lobe's form that shininess applies to: 0 Phong on R.E (the thesis), 1 Blinn-Phong on N.H, "
       "2 GGX on N.H with roughness sqrt(2 / (shininess + 2)) (absent: 0)",
       [](const R &r) { return r.lobe_form; }, [](R &r, float v) { r.lobe_form = whole(v, float(kLobeFormCount - 1)); }},
      {"diffuse_form", K::Code, G::ReflectanceFit, false,
       "the diffuse term's form that kd multiplies at the vertex: 0 Lambert (N.L, the thesis), 1 coated (N.L with "
       "a clear coat's Fresnel transmission in and out, index 1.5) (absent: 0)",
       [](const R &r) { return r.diffuse_form; }, [](R &r, float v) { r.diffuse_form = whole(v, 1.0f); }},
      {"diffuse_deconvolved", K::Code, G::ReflectanceFit, false,
       "1: k_d C is the vertex's own reflectance, deconvolved from the photos' pixel footprints (a photo's sample is "
       "predicted through the footprint's weights over the neighbouring vertices); 0: as the photos' samples show "
       "it (absent: 0)",
       [](const R &r) { return r.diffuse_deconvolved; },
       [](R &r, float v) { r.diffuse_deconvolved = whole(v, 1.0f); }},
      {"mesh_nx", K::Real, G::ReflectanceFit, false,
       "the mesh's own normal, x (nx ny nz are the shading normals the model was fitted with: refined from the "
       "photos where they determine it, else these)",
       [](const R &r) { return r.mesh_normal[0]; }, [](R &r, float v) { r.mesh_normal[0] = v; }},
      {"mesh_ny", K::Real, G::ReflectanceFit, false, "the mesh's own normal, y", [](const R &r) { return r.mesh_normal[1]; },
       [](R &r, float v) { r.mesh_normal[1] = v; }},
      {"mesh_nz", K::Real, G::ReflectanceFit, false, "the mesh's own normal, z", [](const R &r) { return r.mesh_normal[2]; },
       [](R &r, float v) { r.mesh_normal[2] = v; }},
      {"normal_moved", K::Real, G::ReflectanceFit, false,
       "degrees between the shading normal and the mesh's normal; -1: the photos do not determine it (the mesh's "
       "normal kept, or refinement off) (absent: -1)",
       [](const R &r) { return r.normal_moved; }, [](R &r, float v) { r.normal_moved = v; }},
  };
}
} // namespace

const std::vector<ResultAttribute> &result_schema() {
  static const std::vector<ResultAttribute> schema = make_schema();
  return schema;
}

const ResultAttribute *find_result_attribute(const std::string &name) {
  for (const ResultAttribute &a : result_schema())
    if (name == a.name) return &a;
  return nullptr;
}

std::string result_attribute_names() {
  std::string names;
  for (const ResultAttribute &a : result_schema()) names += (names.empty() ? "" : ", ") + std::string(a.name);
  return names;
}

std::vector<VertexAttribute> result_attributes(const std::vector<VertexRecord> &records, bool with_fit) {
  std::vector<VertexAttribute> out;
  for (const ResultAttribute &a : result_schema()) {
    if (a.group == AttributeGroup::ReflectanceFit && !with_fit) continue;
    out.push_back({a.name, std::vector<float>(records.size())});
    for (size_t v = 0; v < records.size(); ++v) out.back().values[v] = a.get(records[v]);
  }
  return out;
}

std::string first_missing_model_attribute(const ResultColumns &columns) {
  for (const ResultAttribute &a : result_schema())
    if (a.needed_for_model && columns.find(a.name) == columns.end()) return a.name;
  return "";
}

std::vector<VertexRecord> records_from_columns(const ResultColumns &columns, const std::string &source) {
  size_t n = 0;
  for (const ResultAttribute &a : result_schema()) {
    const auto it = columns.find(a.name);
    if (it != columns.end()) n = std::max(n, it->second.size());
  }
  std::vector<VertexRecord> records(n);
  for (const ResultAttribute &a : result_schema()) {
    const auto it = columns.find(a.name);
    if (it == columns.end()) continue;
    if (it->second.size() != n)
      throw InputError("Result '" + source + "': per-vertex '" + a.name + "' has " + std::to_string(it->second.size()) +
                       " values for " + std::to_string(n) + " vertices.");
    for (size_t v = 0; v < n; ++v) a.set(records[v], it->second[v]);
  }
  return records;
}

LobeForm lobe_form_of(const std::vector<VertexRecord> &records, const std::string &source) {
  bool seen[kLobeFormCount] = {};
  for (const VertexRecord &r : records)
    if (has_model(r.fit)) seen[int(std::lround(std::min(std::max(r.lobe_form, 0.0f), float(kLobeFormCount - 1))))] = true;
  int form = 0, forms = 0;
  for (int f = 0; f < kLobeFormCount; ++f)
    if (seen[f]) form = f, ++forms;
  if (forms > 1)
    throw InputError("Result '" + source + "' mixes lobe forms (per-vertex 'lobe_form' takes several of 0, 1, 2): refit it in one run.");
  return LobeForm(form);
}

DiffuseForms diffuse_forms_of(const std::vector<VertexRecord> &records) {
  bool seen[2] = {false, false};
  auto coated = std::make_shared<std::vector<uint8_t>>(records.size(), 0);
  for (size_t v = 0; v < records.size(); ++v) {
    (*coated)[v] = records[v].diffuse_form > 0.5f ? 1 : 0;
    if (has_model(records[v].fit)) seen[(*coated)[v]] = true;
  }
  if (seen[0] && seen[1]) return DiffuseForms{DiffuseForm::Lambert, coated};
  return DiffuseForms::everywhere(seen[1] ? DiffuseForm::Coated : DiffuseForm::Lambert);
}

} // namespace vbrdf
