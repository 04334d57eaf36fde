// The GLB of a fit result and the files beside it (contract in web_export.h).
#include "publish/web_export.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include <tiny_gltf.h>

#include "base/errors.h"
#include "base/file_util.h"
#include "inputs/light_file.h"
#include "inputs/light_source.h"
#include "io/result_schema.h"
#include "publish/web_viewer.h"
#include "relight/live_legend.h"  // the live view's false colours
#include "relight/reflectance_model_source.h"  // typical_shininess: the renderers' rule for k_s = 0
#include "model/diffuse_form.h"

namespace vbrdf {

namespace {

using tinygltf::Value;

// The per-vertex scalars the viewer reads: glTF name, result attribute, meaning.
struct ScalarAttribute {
  const char *gltf, *result;
};
const ScalarAttribute kScalars[] = {
    {"_KS", "ks"},
    {"_SHININESS", "shininess"},
    {"_DIFFUSE_FORM", "diffuse_form"},
    {"_FIT_STATUS", "fit_status"},
    {"_DQ", "dq"},
    {"_SQ", "sq"},
};

Value num(double v) { return Value(v); }
Value str(const std::string &s) { return Value(s); }
Value vec(const float *v, int n) {
  Value::Array a;
  for (int i = 0; i < n; ++i) a.push_back(num(double(v[i])));
  return Value(std::move(a));
}

const std::vector<float> &column(const ResultPly &result, const std::string &name, const std::string &path) {
  const auto it = result.vertex_properties.find(name);
  if (it == result.vertex_properties.end())
    throw InputError("Result '" + path + "' has no per-vertex '" + name +
                     "': it is not a fit result with a reflectance model. Export the PLY written by 'Vertex BRDF: "
                     "fit per-vertex reflectance' (or vbrdf_fit).");
  if (it->second.size() != result.mesh.positions.size() / 3)
    throw InputError("Result '" + path + "': per-vertex '" + name + "' has " + std::to_string(it->second.size()) +
                     " values for " + std::to_string(result.mesh.positions.size() / 3) +
                     " vertices: the file is damaged; write it again with the fit.");
  return it->second;
}

void check_finite(const std::vector<float> &values, int per_vertex, const std::string &what, const std::string &path) {
  for (size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i]))
      throw InputError("Result '" + path + "': vertex " + std::to_string(i / size_t(per_vertex)) + "'s " + what +
                       " is not finite: a glTF file cannot carry it. Refit, or repair the file.");
}

// Appends `data` to the buffer as a tightly packed view (4-byte aligned); returns the view index.
int add_view(tinygltf::Model &m, const void *data, size_t bytes, int target) {
  std::vector<unsigned char> &buf = m.buffers[0].data;
  while (buf.size() % 4) buf.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buf.size();
  view.byteLength = bytes;
  view.target = target;
  const auto *p = static_cast<const unsigned char *>(data);
  buf.insert(buf.end(), p, p + bytes);
  m.bufferViews.push_back(view);
  return int(m.bufferViews.size() - 1);
}

int add_float_accessor(tinygltf::Model &m, const std::vector<float> &values, int components, bool with_bounds) {
  tinygltf::Accessor a;
  a.bufferView = add_view(m, values.data(), values.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER);
  a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  a.count = values.size() / size_t(components);
  a.type = components == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_SCALAR;
  if (with_bounds) {
    a.minValues.assign(size_t(components), 1e300);
    a.maxValues.assign(size_t(components), -1e300);
    for (size_t i = 0; i < values.size(); ++i) {
      const size_t k = i % size_t(components);
      a.minValues[k] = std::min(a.minValues[k], double(values[i]));
      a.maxValues[k] = std::max(a.maxValues[k], double(values[i]));
    }
  }
  m.accessors.push_back(a);
  return int(m.accessors.size() - 1);
}

std::string base_name(const std::string &path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

} // namespace

WebCapture web_capture_of(const std::vector<Raster> &rasters, const std::string &project_path,
                          const std::string &light_file, const MeshView &mesh) {
  WebCapture capture;
  // One camera per viewpoint (in raster order): the first raster of each group of equal shots.
  std::vector<const Raster *> firsts;
  for (const Raster &r : rasters) {
    if (!shot_is_valid(r.shot)) continue;
    size_t i = 0;
    while (i < firsts.size() && !same_shot(firsts[i]->shot, r.shot)) ++i;
    if (i < firsts.size()) {
      ++capture.cameras[i].photos;
      continue;
    }
    firsts.push_back(&r);
    WebCapture::Camera c;
    c.label = r.label;
    c.photos = 1;
    c.width = r.width();
    c.height = r.height();
    const auto &in = r.shot.Intrinsics;
    c.focal_px = in.FocalMm / in.PixelSizeMm[1];
    c.centre_px[0] = in.CenterPx[0];
    c.centre_px[1] = float(c.height) - in.CenterPx[1];
    camera_centre(r.shot, c.position.data());
    gl_view_matrix(r.shot, c.view);
    capture.cameras.push_back(c);
  }
  if (rasters.empty()) {
    capture.note = "no photos: the GLB has no photo lights or cameras";
    return capture;
  }
  std::string file = light_file;
  if (file.empty()) file = find_default_light_file(rasters, project_path);
  if (file.empty()) {
    capture.note = "no light file lists every photo: the GLB has no photo lights";
    return capture;
  }
  const std::vector<LightSource> lights = resolve_lights(rasters, file, light_placement_of(mesh, 0, 0));
  capture.light_file = file;
  for (size_t i = 0; i < lights.size() && i < rasters.size(); ++i) {
    WebCapture::Light l;
    l.image = base_name(rasters[i].image_path);
    l.direction = lights[i].direction;
    l.positional = lights[i].positional;
    l.position = lights[i].position;
    capture.lights.push_back(l);
  }
  return capture;
}

std::string WebGlb::summary() const {
  std::ostringstream s;
  s << vertices << " vertices (" << modelled << " with a model), " << triangles << " triangles, " << bytes.size()
    << " bytes (" << (vertices ? double(bytes.size()) / double(vertices) : 0.0) << " per vertex); lobe "
    << lobe_form_label(lobe) << (albedo_written ? "; k_d C above 1 kept in _ALBEDO" : "");
  return s.str();
}

WebGlb build_web_glb(const ResultPly &result, const std::string &path, const WebCapture &capture) {
  const MeshData &mesh = result.mesh;
  const size_t n = mesh.positions.size() / 3;
  if (n == 0 || mesh.indices.size() < 3)
    throw InputError("Result '" + path + "' has no triangles: export the result PLY of a triangle mesh.");
  for (uint32_t i : mesh.indices)
    if (i >= n) throw InputError("Result '" + path + "' has a face with vertex " + std::to_string(i) + " of " +
                                 std::to_string(n) + ": the file is damaged; write it again with the fit.");
  if (mesh.normals.size() != mesh.positions.size())
    throw InputError("Result '" + path + "' has no normals (nx ny nz): export the PLY the fit wrote.");
  check_finite(mesh.positions, 3, "position", path);
  check_finite(mesh.normals, 3, "normal", path);
  for (size_t v = 0; v < n; ++v) {
    const float *nv = &mesh.normals[3 * v];
    if (!(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2] > 0.25f))
      throw InputError("Result '" + path + "': vertex " + std::to_string(v) +
                       " has a zero or very short normal: glTF needs unit normals. Refit the mesh with normals.");
  }
  // The model, read as the renderers read it (fits_from_result: forms checked, the first missing
  // model attribute named).
  WebGlb out;
  DiffuseForms diffuse;
  const std::vector<VertexFit> fits = fits_from_result(result, path, &out.lobe, &diffuse);
  const std::vector<float> *scalars[6];
  for (int k = 0; k < 6; ++k) {
    scalars[k] = &column(result, kScalars[k].result, path);
    check_finite(*scalars[k], 1, std::string("'") + kScalars[k].result + "'", path);
  }
  std::vector<float> color(3 * n), albedo(3 * n);
  for (size_t v = 0; v < n; ++v)
    for (int k = 0; k < 3; ++k) {
      const float rho = fits[v].kd * fits[v].color[k];  // as upload_model_mesh: float product
      if (!std::isfinite(rho))
        throw InputError("Result '" + path + "': vertex " + std::to_string(v) +
                         "'s k_d C is not finite: a glTF file cannot carry it. Refit, or repair the file.");
      albedo[3 * v + k] = rho;
      color[3 * v + k] = std::min(std::max(rho, 0.0f), 1.0f);
      if (rho > 1.0f) out.albedo_written = true;
    }
  out.vertices = n;
  out.triangles = mesh.indices.size() / 3;
  for (const VertexFit &f : fits) out.modelled += has_model(f) ? 1 : 0;
  out.typical_shininess = typical_shininess(fits);
  out.roughness = float(std::pow(2.0 / (double(out.typical_shininess) + 2.0), 0.25));

  tinygltf::Model m;
  m.asset.version = "2.0";
  m.asset.generator = "filter_vertex_brdf (Vertex BRDF: export for the web)";
  m.buffers.resize(1);
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  prim.attributes["POSITION"] = add_float_accessor(m, mesh.positions, 3, true);
  prim.attributes["NORMAL"] = add_float_accessor(m, mesh.normals, 3, false);
  prim.attributes["COLOR_0"] = add_float_accessor(m, color, 3, false);
  if (out.albedo_written) prim.attributes["_ALBEDO"] = add_float_accessor(m, albedo, 3, false);
  for (int k = 0; k < 6; ++k) prim.attributes[kScalars[k].gltf] = add_float_accessor(m, *scalars[k], 1, false);
  {
    tinygltf::Accessor a;
    a.bufferView = add_view(m, mesh.indices.data(), mesh.indices.size() * sizeof(uint32_t),
                            TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    a.count = mesh.indices.size();
    a.type = TINYGLTF_TYPE_SCALAR;
    m.accessors.push_back(a);
    prim.indices = int(m.accessors.size() - 1);
  }
  prim.material = 0;

  // The model, declared.
  Value::Object attrs;
  auto meaning = [](const char *name) {
    const ResultAttribute *a = find_result_attribute(name);
    return std::string(a ? a->meaning : "");
  };
  attrs["COLOR_0"] = str("linear k_d C (Phong k_d times colour C), each channel clamped to [0, 1]");
  if (out.albedo_written) attrs["_ALBEDO"] = str("linear k_d C unclamped (some channel exceeds 1); read it instead of COLOR_0");
  attrs["NORMAL"] = str("the shading normal the model was fitted with (the result's nx ny nz)");
  for (const ScalarAttribute &s : kScalars) attrs[s.gltf] = str(std::string(s.result) + ": " + meaning(s.result));
  Value::Object model;
  model["model"] = str("f = k_d C d + k_s g(s, alpha), unit irradiance, linear RGB: shaders/reflectance_model.glsl");
  model["lobe_form"] = Value(int(out.lobe));
  model["lobe_form_name"] = str(lobe_form_name(out.lobe));
  model["diffuse_form"] = str(diffuse.varies() ? "per_vertex" :
                              diffuse.uniform == DiffuseForm::Coated ? "coated" : "lambert");
  model["coat_index"] = num(double(kCoatIndex));
  model["coat_min_cosine"] = num(double(kCoatMinCosine));
  model["typical_shininess"] = num(double(out.typical_shininess));
  model["typical_shininess_meaning"] =
      str("the shininess drawn where k_s = 0: the median of the fitted lobes, so a lobe fades with k_s across a triangle");
  model["unfitted"] = str("_FIT_STATUS 0: no model (the live view draws such vertices grey)");
  model["attributes"] = Value(std::move(attrs));
  auto legend = [](const std::vector<LegendEntry> &entries) {
    Value::Array a;
    for (const LegendEntry &e : entries) {
      Value::Object o;
      o["label"] = str(e.label);
      o["rgb"] = vec(e.rgb.data(), 3);
      a.push_back(Value(std::move(o)));
    }
    return Value(std::move(a));
  };
  Value::Object legends;
  legends["fit_status"] = legend(fit_status_legend());
  legends["quality"] = legend(quality_legend());
  model["legends"] = Value(std::move(legends));
  model["source"] = str(base_name(path));
  Value::Object prim_extras;
  prim_extras["vbrdf_model"] = Value(std::move(model));
  prim.extras = Value(std::move(prim_extras));

  tinygltf::Mesh gmesh;
  gmesh.name = "vertex_brdf";
  gmesh.primitives.push_back(prim);
  m.meshes.push_back(gmesh);

  tinygltf::Material mat;
  mat.name = "vertex_brdf_fallback";
  mat.pbrMetallicRoughness.baseColorFactor = {1.0, 1.0, 1.0, 1.0};
  mat.pbrMetallicRoughness.metallicFactor = 0.0;
  mat.pbrMetallicRoughness.roughnessFactor = double(out.roughness);
  mat.doubleSided = false;
  m.materials.push_back(mat);

  tinygltf::Node node;
  node.name = "vertex_brdf";
  node.mesh = 0;
  m.nodes.push_back(node);

  // The capture: photo lights and viewpoint cameras, world frame.
  Value::Array lights, cameras;
  for (const WebCapture::Light &l : capture.lights) {
    Value::Object o;
    o["image"] = str(l.image);
    o["direction"] = vec(l.direction.data(), 3);
    if (l.positional) o["position"] = vec(l.position.data(), 3);
    lights.push_back(Value(std::move(o)));
  }
  for (const WebCapture::Camera &c : capture.cameras) {
    Value::Object o;
    o["label"] = str(c.label);
    o["photos"] = Value(c.photos);
    o["width"] = Value(c.width);
    o["height"] = Value(c.height);
    o["focal_px"] = num(double(c.focal_px));
    o["centre_px"] = vec(c.centre_px, 2);
    o["position"] = vec(c.position.data(), 3);
    o["view_matrix"] = vec(c.view, 16);
    cameras.push_back(Value(std::move(o)));
  }
  Value::Object cap;
  cap["frame"] = str("the mesh's world frame; directions are unit vectors towards the light; view_matrix: world to "
                     "camera (OpenGL: looking down -z, y up), column-major; centre_px: principal point, pixels from the "
                     "top-left corner");
  cap["photo_lights"] = Value(std::move(lights));
  cap["cameras"] = Value(std::move(cameras));
  if (!capture.light_file.empty()) cap["light_file"] = str(base_name(capture.light_file));
  Value::Object scene_extras;
  scene_extras["vbrdf_capture"] = Value(std::move(cap));
  tinygltf::Scene scene;
  scene.name = "vertex_brdf";
  scene.nodes.push_back(0);
  scene.extras = Value(std::move(scene_extras));
  m.scenes.push_back(scene);
  m.defaultScene = 0;

  std::ostringstream stream(std::ios::binary);
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&m, stream, false, true))
    throw ProcessingError("Web export of '" + path + "': the GLB could not be serialised.");
  const std::string bytes = stream.str();
  out.bytes.assign(bytes.begin(), bytes.end());
  return out;
}

WebOutputPaths web_output_paths(const std::string &glb_path) {
  std::string stem = glb_path;
  if (stem.size() > 4 && stem.compare(stem.size() - 4, 4, ".glb") == 0) stem.resize(stem.size() - 4);
  return {stem + ".glb", stem + ".html", stem + "_hosted.html"};
}

namespace {
void write_bytes(const std::string &path, const char *data, size_t size) {
  AtomicOutput out(path);
  {
    std::ofstream f(out.temporary(), std::ios::binary);
    f.write(data, std::streamsize(size));
    f.flush();
    if (!f)
      throw ProcessingError("Cannot write '" + path + "' (" + out.failure_cause() + "); the previous file is unchanged.");
  }
  out.commit((long long)size);
}
} // namespace

WebOutputPaths write_web_outputs(const WebGlb &glb, const std::string &glb_path, bool with_viewer,
                                 OverwritePolicy policy, const std::string &title) {
  const WebOutputPaths paths = web_output_paths(glb_path);
  if (with_viewer && !web_viewer_available())
    throw InputError("This build has no web viewer (" + web_viewer_missing_reason() +
                     "): export the GLB alone (viewer off), or rebuild after 'npm ci' in filter_vertex_brdf/web.");
  check_output_path(paths.glb, policy, "output GLB");
  if (with_viewer) {
    check_output_path(paths.html, policy, "output GLB (its viewer page)");
    check_output_path(paths.hosted_html, policy, "output GLB (its hosted viewer page)");
  }
  std::string html, hosted;
  if (with_viewer) {
    html = web_viewer_page(glb.bytes, "", title);
    hosted = web_viewer_page({}, base_name(paths.glb), title);
  }
  remove_stale_temporaries(paths.glb);
  write_bytes(paths.glb, reinterpret_cast<const char *>(glb.bytes.data()), glb.bytes.size());
  if (with_viewer) {
    write_bytes(paths.html, html.data(), html.size());
    write_bytes(paths.hosted_html, hosted.data(), hosted.size());
  }
  return paths;
}

} // namespace vbrdf
