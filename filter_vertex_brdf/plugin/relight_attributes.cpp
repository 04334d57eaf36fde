// Reading the live view's model from a MeshLab mesh (relight_attributes.h).
#include "relight_attributes.h"

#include <cstring>

#include "core/base/errors.h"
#include "core/io/result_schema.h"

namespace vbrdf_plugin {

RelightModel relight_model(MeshModel &mesh) {
  const std::string name = utf8(mesh.label());
  vbrdf::ResultColumns columns;
  RelightModel model;
  model.arrays = mesh_arrays(mesh);  // throws when the mesh has no normals
  for (const vbrdf::ResultAttribute &a : vbrdf::result_schema()) {
    std::vector<float> values = vertex_float_attribute(mesh, model.arrays, a.name);
    if (!values.empty()) columns[a.name] = std::move(values);
  }
  const std::string missing = vbrdf::first_missing_model_attribute(columns);
  if (!missing.empty())
    throw vbrdf::InputError("Vertex BRDF relight: the mesh '" + name + "' has no per-vertex attribute '" + missing +
                            "', so there is no reflectance model to draw; MeshLab's normal rendering is shown. Run "
                            "'Vertex BRDF: fit per-vertex reflectance' on it, or load its result PLY with "
                            "'Vertex BRDF: load result attributes'.");
  const std::vector<vbrdf::VertexRecord> records = vbrdf::records_from_columns(columns, "mesh '" + name + "'");
  model.fits.reserve(records.size());
  for (const vbrdf::VertexRecord &r : records) {
    model.fits.push_back(r.fit);
    model.modelled += r.fit.status != vbrdf::kFitNone;
  }
  if (model.modelled == 0)
    throw vbrdf::InputError("Vertex BRDF relight: no vertex of the mesh '" + name +
                            "' has a fitted model (fit_status 0 everywhere); MeshLab's normal rendering is shown. "
                            "Check the fit's log for why no vertex was fitted.");
  model.lobe = vbrdf::lobe_form_of(records, "mesh '" + name + "'");
  model.diffuse = vbrdf::diffuse_forms_of(records);
  return model;
}

uint64_t relight_model_fingerprint(MeshModel &mesh) {
  using Alloc = vcg::tri::Allocator<CMeshO>;
  CMeshO &cm = mesh.cm;
  if (!vcg::tri::HasPerVertexAttribute(cm, "kd")) return 0;
  uint64_t h = 1469598103934665603ull;  // FNV-1a
  auto mix = [&h](uint64_t v) {
    for (int b = 0; b < 8; ++b) h = (h ^ ((v >> (8 * b)) & 0xff)) * 1099511628211ull;
  };
  mix(uint64_t(cm.vn));
  mix(uint64_t(cm.fn));
  mix(uint64_t(cm.vert.size()));
  for (const char *attr : {"kd", "ks", "shininess", "fit_status"}) {
    if (!vcg::tri::HasPerVertexAttribute(cm, attr)) continue;
    auto handle = Alloc::FindPerVertexAttribute<float>(cm, attr);
    if (!Alloc::IsValidHandle(cm, handle)) continue;
    const size_t n = cm.vert.size(), step = n / 4096 + 1;
    for (size_t i = 0; i < n; i += step) {
      uint32_t bits = 0;
      const float v = handle[i];
      std::memcpy(&bits, &v, sizeof bits);
      mix(bits);
    }
  }
  return h == 0 ? 1 : h;
}

} // namespace vbrdf_plugin
