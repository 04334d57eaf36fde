#pragma once
// MeshLab document <-> core types. No algorithm here: plain copies and index maps.
#include <functional>
#include <string>
#include <vector>

#include "meshlab_host.h"

#include "core/inputs/camera.h"
#include "core/base/mesh_view.h"
#include "core/io/output_ply.h"
#include "core/samples/samples.h"
#include "core/registration/registration.h"

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

// Gives every raster of the document (hidden ones too) whose shot is a viewpoint that registration
// corrected the corrected shot, as MeshLab's own alignment filters move the rasters; logs how many.
void apply_corrected_cameras(MeshDocument &document, const vbrdf::RegistrationResult &registration,
                             const std::function<void(const std::string &)> &log);

// The rasters the fit and the coverage use: the visible ones (the eye in MeshLab's layer dialog),
// as MeshLab's own "Project active rasters color to current mesh" takes them. document_index[i] is
// the document's raster index of rasters[i]; `hidden` counts those left out. Throws InputError
// naming a visible raster without image.
struct ActiveRasters {
  std::vector<vbrdf::Raster> rasters;
  std::vector<size_t> document_index;
  size_t hidden = 0;
};
ActiveRasters active_rasters(const MeshDocument &document);

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

// Per-vertex colour layers the filters keep beside the displayed colours, so that the user can
// switch between them ("Vertex BRDF: show vertex colours") and no filter's colours leak into
// another's output: the colours before any Vertex BRDF filter painted the mesh (saved once, at the
// first paint), the last fit's albedo, the last coverage's classes. Each is a vcg::Color4b
// per-vertex attribute of the name color_layer_attribute() gives.
enum class ColorLayer { Input, Fit, Coverage };
const char *color_layer_attribute(ColorLayer layer);  // "vbrdf_input_color", "vbrdf_fit_color", "coverage_color"
const char *color_layer_label(ColorLayer layer);      // for messages: "the colours before Vertex BRDF", ...

// What a filter stores on the mesh. Only vertices with vertex_mask[i] != 0 change when the mask is
// given (one entry per array vertex; "only selected vertices"); new attributes start at 0 elsewhere.
struct StoredResults {
  ColorLayer layer = ColorLayer::Fit;
  std::vector<uint8_t> colors_rgba;  // RGBA8 per array vertex, kept in the layer's attribute; empty: none
  bool paint = true;                 // also show them as the vertex colours
  std::vector<float> quality;        // vertex quality when it has one value per vertex
  std::vector<vbrdf::VertexAttribute> attributes;  // float per-vertex attributes, by name
  std::vector<uint8_t> vertex_mask;  // empty: every vertex
};
// Stores `results` in the mesh (enabling the colour and quality attributes as needed). The input
// colours are saved before the first paint.
void store_results(MeshModel &mesh, const MeshArrays &arrays, const StoredResults &results);
// The fit's shading normals (3 per array vertex, world frame; empty: none) become the layer's vertex
// normals (in its own frame), so that the relight filter and the live view shade with them; the
// mesh's own normals stay in the result's mesh_nx/ny/nz attributes. Only masked-in vertices change.
void apply_shading_normals(MeshModel &mesh, const MeshArrays &arrays, const std::vector<float> &normals,
                           const std::vector<uint8_t> &vertex_mask);
// Where an earlier fit left the mesh's own normals in mesh_nx/ny/nz (world frame), the arrays take
// them back, so that a fit always starts from the scan's normals, not from an earlier refinement.
// Returns the number of vertices restored.
size_t restore_mesh_normals(MeshModel &mesh, MeshArrays &arrays);

// Copies the colour layer onto the vertex colours. False (mesh unchanged) when the mesh has no
// such layer. The input layer, when never saved, is the current colours: nothing to do, true.
bool show_color_layer(MeshModel &mesh, ColorLayer layer);

// Per array vertex: 1 when the vertex is selected in MeshLab, else 0; `count` gets the number.
std::vector<uint8_t> selected_vertices(const MeshModel &mesh, const MeshArrays &arrays, size_t &count);

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
