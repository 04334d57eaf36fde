// GLB read-back check (web_glb_check.h).
#include "web_glb_check.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include <tiny_gltf.h>

#include "io/result_ply.h"

namespace vbrdf {

namespace {

// The floats of accessor `index` (tightly packed float VEC3 / SCALAR), or why not.
std::string read_floats(const tinygltf::Model &m, int index, int components, std::vector<float> &out) {
  if (index < 0 || size_t(index) >= m.accessors.size()) return "no such accessor";
  const tinygltf::Accessor &a = m.accessors[size_t(index)];
  if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT) return "not float";
  if (tinygltf::GetNumComponentsInType(uint32_t(a.type)) != components) return "wrong component count";
  const tinygltf::BufferView &v = m.bufferViews[size_t(a.bufferView)];
  const size_t stride = v.byteStride ? v.byteStride : size_t(components) * 4;
  const unsigned char *base = m.buffers[size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset;
  out.resize(a.count * size_t(components));
  for (size_t i = 0; i < a.count; ++i) std::memcpy(&out[i * size_t(components)], base + i * stride, size_t(components) * 4);
  return "";
}

bool same_bits(const std::vector<float> &a, const std::vector<float> &b, size_t *first) {
  if (a.size() != b.size()) return *first = 0, false;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i], &b[i], 4) != 0) return *first = i, false;
  return true;
}

} // namespace

std::string check_glb_bytes_against_result(const std::string &result_path, const std::vector<uint8_t> &glb) {
  const ResultPly result = read_result_ply(result_path);
  tinygltf::Model m;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  if (!loader.LoadBinaryFromMemory(&m, &err, &warn, glb.data(), unsigned(glb.size())))
    return "tinygltf cannot read it: " + err;
  if (m.meshes.size() != 1 || m.meshes[0].primitives.size() != 1) return "not one mesh with one primitive";
  const tinygltf::Primitive &p = m.meshes[0].primitives[0];
  const size_t n = result.mesh.positions.size() / 3;
  auto attribute = [&](const std::string &name, int components, std::vector<float> &out) -> std::string {
    const auto it = p.attributes.find(name);
    if (it == p.attributes.end()) return name + " missing";
    const std::string why = read_floats(m, it->second, components, out);
    return why.empty() ? "" : name + ": " + why;
  };
  auto compare = [&](const std::string &name, int components, const std::vector<float> &expected) -> std::string {
    std::vector<float> got;
    const std::string why = attribute(name, components, got);
    if (!why.empty()) return why;
    size_t i = 0;
    if (!same_bits(got, expected, &i))
      return name + " differs at vertex " + std::to_string(i / size_t(components)) + " (" +
             (i < got.size() ? std::to_string(got[i]) : "-") + " for " +
             (i < expected.size() ? std::to_string(expected[i]) : "-") + ")";
    return "";
  };
  std::string why;
  if (!(why = compare("POSITION", 3, result.mesh.positions)).empty()) return why;
  if (!(why = compare("NORMAL", 3, result.mesh.normals)).empty()) return why;
  const auto &props = result.vertex_properties;
  const std::vector<float> &kd = props.at("kd");
  std::vector<float> rho(3 * n), clamped(3 * n);
  bool above = false;
  for (size_t v = 0; v < n; ++v)
    for (int k = 0; k < 3; ++k) {
      const float c = props.at(std::string("color_") + "rgb"[k])[v];
      rho[3 * v + size_t(k)] = kd[v] * c;
      clamped[3 * v + size_t(k)] = std::min(std::max(kd[v] * c, 0.0f), 1.0f);
      above = above || kd[v] * c > 1.0f;
    }
  if (!(why = compare("COLOR_0", 3, clamped)).empty()) return why;
  if (above) {
    if (!(why = compare("_ALBEDO", 3, rho)).empty()) return why;
  } else if (p.attributes.count("_ALBEDO")) {
    return "_ALBEDO present although no k_d C channel exceeds 1";
  }
  const char *scalars[6][2] = {{"_KS", "ks"}, {"_SHININESS", "shininess"}, {"_DIFFUSE_FORM", "diffuse_form"},
                               {"_FIT_STATUS", "fit_status"}, {"_DQ", "dq"}, {"_SQ", "sq"}};
  for (const auto &s : scalars)
    if (!(why = compare(s[0], 1, props.at(s[1]))).empty()) return why;
  // Indices.
  const tinygltf::Accessor &ia = m.accessors[size_t(p.indices)];
  if (ia.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT || ia.count != result.mesh.indices.size())
    return "indices: not uint32 or wrong count";
  const tinygltf::BufferView &iv = m.bufferViews[size_t(ia.bufferView)];
  if (std::memcmp(m.buffers[size_t(iv.buffer)].data.data() + iv.byteOffset + ia.byteOffset, result.mesh.indices.data(),
                  ia.count * 4) != 0)
    return "indices differ";
  // The model's declaration.
  const tinygltf::Value &model = p.extras.Get("vbrdf_model");
  if (!model.IsObject()) return "primitive extras.vbrdf_model missing";
  for (const char *key : {"lobe_form", "diffuse_form", "coat_index", "typical_shininess", "attributes", "legends"})
    if (!model.Has(key)) return std::string("extras.vbrdf_model.") + key + " missing";
  for (size_t v = 0; v < n; ++v)
    if (props.at("fit_status")[v] > 0.5f && props.count("lobe_form")) {
      if (model.Get("lobe_form").GetNumberAsInt() != int(std::lround(props.at("lobe_form")[v])))
        return "extras.vbrdf_model.lobe_form differs from the result's lobe_form";
      break;
    }
  return "";
}

std::string check_glb_against_result(const std::string &result_ply, const std::string &glb_path) {
  std::ifstream f(glb_path, std::ios::binary);
  if (!f) return "cannot read " + glb_path;
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  return check_glb_bytes_against_result(result_ply, bytes);
}

} // namespace vbrdf
