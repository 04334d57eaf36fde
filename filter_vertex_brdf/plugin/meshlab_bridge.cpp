#include "meshlab_bridge.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <thread>

#include <QDir>
#include <QFileInfo>

#include <vcg/complex/allocate.h>

#include "core/base/errors.h"

namespace vbrdf_plugin {

namespace {

bool is_identity(const Matrix44m &m) {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      if (m[r][c] != (r == c ? 1 : 0)) return false;
  return true;
}

// The vertex colours the mesh had before any of our filters painted it (fit albedo, coverage
// classes): saved once, at the first paint, so that "keep the input colour" keeps the user's
// colours, not the previous run's.
const char *const kInputColorAttribute = "vbrdf_input_color";
using ColorAlloc = vcg::tri::Allocator<CMeshO>;

bool has_input_colors(const CMeshO &cm) {
  CMeshO &m = const_cast<CMeshO &>(cm);  // vcglib's attribute lookup is not const
  return ColorAlloc::IsValidHandle(m, ColorAlloc::FindPerVertexAttribute<vcg::Color4b>(m, kInputColorAttribute));
}

void save_input_colors_once(CMeshO &cm) {
  if (has_input_colors(cm)) return;
  if (vcg::tri::HasPerVertexAttribute(cm, kInputColorAttribute))  // same name, other type
    ColorAlloc::DeletePerVertexAttribute(cm, kInputColorAttribute);
  auto saved = ColorAlloc::GetPerVertexAttribute<vcg::Color4b>(cm, kInputColorAttribute);
  for (size_t i = 0; i < cm.vert.size(); ++i) saved[i] = cm.vert[i].cC();
}

} // namespace

MeshArrays mesh_arrays(const MeshModel &mesh) {
  const CMeshO &cm = mesh.cm;
  const std::string name = utf8(mesh.label());
  MeshArrays out;
  std::vector<int64_t> array_index(cm.vert.size(), -1);
  const bool transformed = out.transformed = !is_identity(cm.Tr);
  // Normals transform with the inverse transpose of the linear part.
  Matrix44m normal_matrix = vcg::Inverse(cm.Tr);
  normal_matrix.transposeInPlace();

  CMeshO &mutable_cm = const_cast<CMeshO &>(cm);  // vcglib's attribute lookup is not const
  const bool saved_colors = has_input_colors(cm);
  auto input_colors = saved_colors ? ColorAlloc::FindPerVertexAttribute<vcg::Color4b>(mutable_cm, kInputColorAttribute)
                                   : CMeshO::PerVertexAttributeHandle<vcg::Color4b>();
  bool any_normal = false;
  for (size_t i = 0; i < cm.vert.size(); ++i) {
    const CVertexO &v = cm.vert[i];
    if (v.IsD()) continue;
    array_index[i] = int64_t(out.vertex_index.size());
    out.vertex_index.push_back(i);
    // In MeshLab's scalar (float in 2020.09, double in 2025.07); the core takes float.
    Point3m p = v.cP(), n = v.cN();
    if (transformed) {
      p = cm.Tr * p;
      const vcg::Point4<Scalarm> n4 = normal_matrix * vcg::Point4<Scalarm>(n[0], n[1], n[2], 0);
      n = Point3m(n4[0], n4[1], n4[2]);
      if (n.Norm() > 0) n.Normalize();
    }
    for (int k = 0; k < 3; ++k) {
      out.data.positions.push_back(float(p[k]));
      out.data.normals.push_back(float(n[k]));
    }
    if (n[0] != 0 || n[1] != 0 || n[2] != 0) any_normal = true;
    // Always present in CMeshO (white when never set); the colours from before our filters if saved.
    const vcg::Color4b c = saved_colors ? input_colors[i] : v.cC();
    for (int k = 0; k < 4; ++k) out.data.colors.push_back(c[k]);
  }
  if (!out.vertex_index.empty() && !any_normal)
    throw vbrdf::InputError("Mesh '" + name + "' has no per-vertex normals (all are zero). Compute them with "
                            "Filters > Normals, Curvatures and Orientation > \"Re-Compute Vertex Normals\" "
                            "(or \"Compute normals for point sets\"), then apply the filter again.");

  for (size_t f = 0; f < cm.face.size(); ++f) {
    const CFaceO &face = cm.face[f];
    if (face.IsD()) continue;
    for (int k = 0; k < 3; ++k) {
      const size_t vi = vcg::tri::Index(cm, face.cV(k));
      if (vi >= array_index.size() || array_index[vi] < 0)
        throw vbrdf::InputError("Mesh '" + name + "': face " + std::to_string(f) +
                                " references a deleted vertex (inconsistent mesh): save the layer, "
                                "reload it and try again.");
      out.data.indices.push_back(uint32_t(array_index[vi]));
    }
  }
  return out;
}

namespace {

vbrdf::Raster raster_of(const RasterModel &rm) {
  vbrdf::Raster r;
  r.label = utf8(rm.label());
  if (rm.planeList.empty() || rm.planeList.first() == nullptr)
    throw vbrdf::InputError("Raster '" + r.label + "' has no image: add its photo (a <Plane fileName=...> in the "
                            ".mlp) or remove the raster.");
  // The first plane is the photo (MeshLab's .mlp reader keeps only the first).
  r.image_path = utf8(rm.planeList.first()->fullPathFileName);
  r.shot = host::core_shot(rm.shot);
  return r;
}

} // namespace

std::vector<vbrdf::Raster> document_rasters(const MeshDocument &document) {
  std::vector<vbrdf::Raster> rasters;
  for (const RasterModel *rm : host::rasters(document)) rasters.push_back(raster_of(*rm));
  return rasters;
}

void apply_corrected_cameras(MeshDocument &document, const vbrdf::RegistrationResult &registration,
                             const std::function<void(const std::string &)> &log) {
  if (!registration.any_applied()) return;
  size_t moved = 0;
  for (RasterModel *rm : host::rasters(document))
    if (const vbrdf::Shot *corrected = registration.corrected_for(host::core_shot(rm->shot))) {
      rm->shot = host::host_shot(*corrected);
      ++moved;
    }
  log("Vertex BRDF: the corrected cameras were applied to " + std::to_string(moved) +
      " raster(s) of the document (save the project to keep them; the result's _registered.mlp has them too).");
}

ActiveRasters active_rasters(const MeshDocument &document) {
  ActiveRasters active;
  const std::vector<const RasterModel *> rasters = host::rasters(document);
  for (size_t i = 0; i < rasters.size(); ++i) {
    const RasterModel *rm = rasters[i];
    if (!host::raster_visible(*rm)) {
      ++active.hidden;
      continue;
    }
    active.rasters.push_back(raster_of(*rm));
    active.document_index.push_back(i);
  }
  if (active.rasters.empty() && active.hidden > 0)
    throw vbrdf::InputError("Every raster (" + std::to_string(active.hidden) + ") is hidden in the layer dialog: only "
                            "visible rasters take part, as in MeshLab's colour projection. Show the rasters to use "
                            "(the eye beside each raster layer).");
  return active;
}

std::string project_path(const MeshDocument &document, const MeshModel &mesh) {
  // The document's file name is private in 2020.09; both meshlabserver and the GUI set the
  // document label to the project's path when they open a project ("Project_N" otherwise). Under
  // PyMeshLab the label is empty: the 2025.07 adapter sets it from the 'Project file' parameter.
  const QFileInfo project(document.docLabel());
  const QString suffix = project.suffix().toLower();
  if (project.isAbsolute() && project.isFile() && (suffix == "mlp" || suffix == "mlb"))
    return utf8(project.absoluteFilePath());
  if (!mesh.fullName().isEmpty()) return utf8(QFileInfo(mesh.fullName()).absoluteFilePath());
  return std::string();
}

std::string utf8(const QString &s) { return s.toUtf8().toStdString(); }

std::string canonical_path(const std::string &path) {
  const QFileInfo info(QString::fromStdString(path));
  return utf8(info.exists() ? info.canonicalFilePath() : info.absoluteFilePath());
}

std::string resolve_path(const std::string &path, const std::string &project) {
  if (path.empty()) return path;
  const QString p = QString::fromStdString(path);
  if (QFileInfo(p).isAbsolute() || project.empty()) return utf8(QFileInfo(p).absoluteFilePath());
  const QDir base = QFileInfo(QString::fromStdString(project)).absoluteDir();
  return utf8(QDir::cleanPath(base.absoluteFilePath(p)));
}

const char *color_layer_attribute(ColorLayer layer) {
  switch (layer) {
  case ColorLayer::Input: return kInputColorAttribute;
  case ColorLayer::Fit: return "vbrdf_fit_color";
  default: return "coverage_color";
  }
}

const char *color_layer_label(ColorLayer layer) {
  switch (layer) {
  case ColorLayer::Input: return "the colours before any Vertex BRDF filter";
  case ColorLayer::Fit: return "the fitted albedo";
  default: return "the coverage classes";
  }
}

namespace {

// The colour attribute `name`, created (or re-created when a same-named attribute has another type).
CMeshO::PerVertexAttributeHandle<vcg::Color4b> color_attribute(CMeshO &cm, const char *name) {
  if (!ColorAlloc::IsValidHandle(cm, ColorAlloc::FindPerVertexAttribute<vcg::Color4b>(cm, name)) &&
      vcg::tri::HasPerVertexAttribute(cm, name))
    ColorAlloc::DeletePerVertexAttribute(cm, name);
  return ColorAlloc::GetPerVertexAttribute<vcg::Color4b>(cm, name);
}

} // namespace

void store_results(MeshModel &mesh, const MeshArrays &arrays, const StoredResults &results) {
  CMeshO &cm = mesh.cm;
  const size_t n = arrays.vertex_index.size();
  const bool masked = results.vertex_mask.size() == n;
  const auto changes = [&](size_t i) { return !masked || results.vertex_mask[i] != 0; };
  if (results.quality.size() == n) {  // "Colorize by vertex quality" then shows it
    mesh.updateDataMask(MeshModel::MM_VERTQUALITY);
    for (size_t i = 0; i < n; ++i)
      if (changes(i)) cm.vert[arrays.vertex_index[i]].Q() = results.quality[i];
  }
  mesh.updateDataMask(MeshModel::MM_VERTCOLOR);
  const std::vector<uint8_t> &rgba = results.colors_rgba;
  if (rgba.size() == 4 * n) {
    save_input_colors_once(cm);
    auto layer = color_attribute(cm, color_layer_attribute(results.layer));
    for (size_t i = 0; i < n; ++i) {
      if (!changes(i)) continue;
      const uint8_t *c = &rgba[4 * i];
      const vcg::Color4b color(c[0], c[1], c[2], c[3]);
      layer[arrays.vertex_index[i]] = color;
      if (results.paint) cm.vert[arrays.vertex_index[i]].C() = color;
    }
  }
  for (const vbrdf::VertexAttribute &attr : results.attributes) {
    if (attr.values.size() != n || attr.name.empty()) continue;
    using Alloc = vcg::tri::Allocator<CMeshO>;
    // A same-named attribute of another type would make GetPerVertexAttribute assert.
    const bool exists = Alloc::IsValidHandle(cm, Alloc::FindPerVertexAttribute<float>(cm, attr.name));
    if (!exists && vcg::tri::HasPerVertexAttribute(cm, attr.name)) Alloc::DeletePerVertexAttribute(cm, attr.name);
    auto handle = Alloc::GetPerVertexAttribute<float>(cm, attr.name);
    if (!exists)
      for (size_t v = 0; v < cm.vert.size(); ++v) handle[v] = 0.0f;
    for (size_t i = 0; i < n; ++i)
      if (changes(i)) handle[arrays.vertex_index[i]] = attr.values[i];
  }
}

void apply_shading_normals(MeshModel &mesh, const MeshArrays &arrays, const std::vector<float> &normals,
                           const std::vector<uint8_t> &vertex_mask) {
  CMeshO &cm = mesh.cm;
  const size_t n = arrays.vertex_index.size();
  if (normals.size() != 3 * n) return;
  const bool masked = vertex_mask.size() == n;
  // World normals back to the layer's frame: the transpose of the linear part undoes the inverse
  // transpose that mesh_arrays applied.
  Matrix44m to_local = cm.Tr;
  to_local.transposeInPlace();
  for (size_t i = 0; i < n; ++i) {
    if (masked && !vertex_mask[i]) continue;
    Point3m nw(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
    if (arrays.transformed) {
      const vcg::Point4<Scalarm> n4 = to_local * vcg::Point4<Scalarm>(nw[0], nw[1], nw[2], 0);
      nw = Point3m(n4[0], n4[1], n4[2]);
    }
    if (!(nw.Norm() > 0)) continue;
    cm.vert[arrays.vertex_index[i]].N() = nw.Normalize();
  }
}

size_t restore_mesh_normals(MeshModel &mesh, MeshArrays &arrays) {
  CMeshO &cm = mesh.cm;
  using Alloc = vcg::tri::Allocator<CMeshO>;
  auto x = Alloc::FindPerVertexAttribute<float>(cm, "mesh_nx");
  auto y = Alloc::FindPerVertexAttribute<float>(cm, "mesh_ny");
  auto z = Alloc::FindPerVertexAttribute<float>(cm, "mesh_nz");
  if (!Alloc::IsValidHandle(cm, x) || !Alloc::IsValidHandle(cm, y) || !Alloc::IsValidHandle(cm, z)) return 0;
  size_t restored = 0;
  for (size_t i = 0; i < arrays.vertex_index.size(); ++i) {
    const size_t v = arrays.vertex_index[i];
    const float n[3] = {x[v], y[v], z[v]};
    if (!(n[0] != 0 || n[1] != 0 || n[2] != 0) || !std::isfinite(n[0] + n[1] + n[2])) continue;
    for (int k = 0; k < 3; ++k) arrays.data.normals[3 * i + size_t(k)] = n[k];
    ++restored;
  }
  return restored;
}

bool show_color_layer(MeshModel &mesh, ColorLayer layer) {
  CMeshO &cm = mesh.cm;
  const char *name = color_layer_attribute(layer);
  auto handle = ColorAlloc::FindPerVertexAttribute<vcg::Color4b>(cm, name);
  if (!ColorAlloc::IsValidHandle(cm, handle)) return layer == ColorLayer::Input;
  mesh.updateDataMask(MeshModel::MM_VERTCOLOR);
  for (size_t v = 0; v < cm.vert.size(); ++v)
    if (!cm.vert[v].IsD()) cm.vert[v].C() = handle[v];
  return true;
}

std::vector<uint8_t> selected_vertices(const MeshModel &mesh, const MeshArrays &arrays, size_t &count) {
  std::vector<uint8_t> mask(arrays.vertex_index.size(), 0);
  count = 0;
  for (size_t i = 0; i < mask.size(); ++i)
    if (mesh.cm.vert[arrays.vertex_index[i]].IsS()) mask[i] = 1, ++count;
  return mask;
}

GlContextScope::GlContextScope(MLPluginGLContext *context, const std::function<void(const std::string &)> &log) {
  if (context == nullptr) return;  // CPU chosen, or no view: the core says which back end runs
  if (!context->isValid()) {
    log("MeshLab's OpenGL context is not valid: the GL passes and the compute-shader fit are unavailable; the CPU back ends run.");
    return;
  }
  context->makeCurrent();
  if (QGLContext::currentContext() != context) {
    log("MeshLab's OpenGL context could not be made current: the GL passes and the compute-shader fit are unavailable; the CPU back ends run.");
    return;
  }
  context_ = context;
}

GlContextScope::~GlContextScope() {
  if (context_ != nullptr) context_->doneCurrent();
}

std::function<void *(const char *)> GlContextScope::get_proc() const {
  if (context_ == nullptr) return {};
  // QGLContext::getProcAddress, not QOpenGLContext: QtGui's GL headers clash with GLEW's,
  // which MeshLab's headers include.
  const QGLContext *context = context_;
  return [context](const char *name) -> void * {
    return reinterpret_cast<void *>(context->getProcAddress(QString::fromLatin1(name)));
  };
}

vbrdf::ProgressFn progress_adapter(vcg::CallBackPos *cb, const std::string &prefix) {
  if (cb == nullptr) return {};
  struct State {
    std::thread::id owner = std::this_thread::get_id();
    int last_percent = -100;
    std::string last_stage, text;
  };
  auto state = std::make_shared<State>();
  return [cb, prefix, state](float fraction, const char *stage) -> bool {
    if (std::this_thread::get_id() != state->owner) return true;
    const float f = std::isfinite(fraction) ? std::min(1.0f, std::max(0.0f, fraction)) : 0.0f;
    const int percent = int(f * 100.0f);
    const std::string stage_name = stage != nullptr ? stage : "";
    // meshlabserver prints every call: report stage changes and 5% steps only.
    if (stage_name == state->last_stage && percent < state->last_percent + 5 && percent != 100) return true;
    if (stage_name == state->last_stage && percent == state->last_percent) return true;
    state->last_percent = percent;
    state->last_stage = stage_name;
    // Trailing newline: meshlabserver prints the text as is; the GUI status bar ignores it.
    state->text = prefix + stage_name + " (" + std::to_string(percent) + "%)\n";
    return cb(percent, state->text.c_str());
  };
}

// --- Acquisition feedback (coverage and photo import filters) ---

std::vector<float> vertex_float_attribute(MeshModel &mesh, const MeshArrays &arrays, const std::string &name) {
  using Alloc = vcg::tri::Allocator<CMeshO>;
  CMeshO &cm = mesh.cm;
  if (!vcg::tri::HasPerVertexAttribute(cm, name)) return {};
  auto handle = Alloc::FindPerVertexAttribute<float>(cm, name);
  if (!Alloc::IsValidHandle(cm, handle)) return {};  // same name, another type
  std::vector<float> values(arrays.vertex_index.size());
  for (size_t i = 0; i < values.size(); ++i) values[i] = handle[arrays.vertex_index[i]];
  return values;
}

void select_vertices(MeshModel &mesh, const MeshArrays &arrays, const std::vector<uint32_t> &vertices) {
  CMeshO &cm = mesh.cm;
  for (CVertexO &v : cm.vert)
    if (!v.IsD()) v.ClearS();
  for (uint32_t i : vertices)
    if (i < arrays.vertex_index.size()) cm.vert[arrays.vertex_index[i]].SetS();
}

void add_raster(MeshDocument &document, const std::string &image_path, const vbrdf::Shot &shot,
                const std::string &label) {
  const QString path = QString::fromStdString(image_path);
  std::unique_ptr<host::RasterPlane> plane(new host::RasterPlane(path, host::RasterPlane::RGBA));  // loads the image
  if (plane->image.isNull())
    throw vbrdf::InputError("Photo '" + image_path + "' cannot be read as an image (missing, unreadable or of an "
                            "unsupported format): check the file.");
  RasterModel *raster = document.addNewRaster();
  raster->setLabel(QString::fromStdString(label));
  raster->shot = host::host_shot(shot);
  raster->addPlane(plane.release());
}

} // namespace vbrdf_plugin
