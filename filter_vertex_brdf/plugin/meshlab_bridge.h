#pragma once
// MeshLab document <-> core types. No algorithm here: plain copies and index maps.
#include <functional>
#include <string>
#include <vector>

#include <common/interfaces.h>

#include "core/inputs/camera.h"
#include "core/base/mesh_view.h"
#include "core/io/output_ply.h"
#include "core/samples/samples.h"

namespace vbrdf_plugin {

// The mesh as plain arrays in world coordinates (cm.Tr applied, as MeshLab displays it), with
// deleted vertices and faces skipped. vertex_index[i] is the CMeshO vertex of array vertex i.
struct MeshArrays {
  vbrdf::MeshData data;              // positions, normals, indices, colors (RGBA8)
  std::vector<size_t> vertex_index;
  bool transformed = false;          // the layer's matrix (cm.Tr) is not the identity
};

// Throws vbrdf::InputError when a face references a deleted vertex or when no vertex has a
// normal (the message names the mesh and the MeshLab filter that computes normals).
MeshArrays mesh_arrays(const MeshModel &mesh);

// Every raster of the document with its shot and the path of its first image plane.
// Throws vbrdf::InputError naming a raster without image.
std::vector<vbrdf::Raster> document_rasters(const MeshDocument &document);

// The .mlp of the document when it has one, else the mesh file (its folder is used for the
// default .lp search and output path). May be empty for a mesh never saved.
std::string project_path(const MeshDocument &document, const MeshModel &mesh);

// The UTF-8 bytes of a Qt string (paths and labels handed to the core).
std::string utf8(const QString &s);

// The canonical path of an existing file (links resolved), else the absolute path: for "is this
// the same file" tests.
std::string canonical_path(const std::string &path);

// Absolute path of `path` (relative paths are taken relative to the project's folder, not to
// the process's working directory, which meshlabserver changes while loading). "" stays "".
std::string resolve_path(const std::string &path, const std::string &project_path);

// Sets the mesh's per-vertex colours (enabling the colour attribute), its vertex quality when
// `quality` has one value per vertex (enabling the quality attribute), and stores every attribute
// as a float per-vertex attribute of the same name.
void store_results(MeshModel &mesh, const MeshArrays &arrays, const std::vector<uint8_t> &colors_rgba,
                   const std::vector<float> &quality, const std::vector<vbrdf::VertexAttribute> &attributes);

// Makes MeshLab's plugin GL context current for its lifetime and gives its get-proc-address.
// Without a context (or if it cannot be made current) get_proc() is empty: CPU visibility.
class GlContextScope {
public:
  GlContextScope(MLPluginGLContext *context, const std::function<void(const std::string &)> &log);
  ~GlContextScope();
  GlContextScope(const GlContextScope &) = delete;
  GlContextScope &operator=(const GlContextScope &) = delete;
  std::function<void *(const char *)> get_proc() const;

private:
  MLPluginGLContext *context_ = nullptr;  // non-null only while current
};

// Maps the core's progress (fraction, stage) onto MeshLab's callback: integer percent, called
// only when the percent or the stage changes, and only from the filter's own thread (the GUI
// callback processes Qt events).
vbrdf::ProgressFn progress_adapter(vcg::CallBackPos *cb, const std::string &prefix);

// --- Acquisition feedback (coverage and photo import filters) ---

// Values of the float per-vertex attribute `name` (e.g. "dq", "sq" stored by the fit filter) for
// the vertices of `arrays`, in array order; empty when the mesh has no such float attribute.
std::vector<float> vertex_float_attribute(MeshModel &mesh, const MeshArrays &arrays, const std::string &name);

// Selects exactly the given array vertices (indices into `arrays`); every other vertex is
// deselected.
void select_vertices(MeshModel &mesh, const MeshArrays &arrays, const std::vector<uint32_t> &vertices);

// Appends a raster layer labelled `label` with `shot` and the photo `image_path` as its only
// plane (as File > Import Raster does, without the EXIF guess). Throws vbrdf::InputError naming
// the file when Qt cannot read the image; the document is unchanged then.
void add_raster(MeshDocument &document, const std::string &image_path, const vbrdf::Shot &shot,
                const std::string &label);

} // namespace vbrdf_plugin
