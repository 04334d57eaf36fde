#pragma once
// The result schema: the one table of the per-vertex values a fit stores, as PLY properties
// (write_result_ply / read_result_ply) and as MeshLab per-vertex float attributes. Writers and
// readers go through this table by name, never by position, so reordering or adding an entry
// cannot feed one attribute's values to another.
//
// File order is the table's order (diffuse_r ... coloured, then the reflectance fit's kd ...
// fit_iterations); keep it: existing result files, tools and the README table (README.md#output)
// follow it.
// Every attribute is stored as a 32-bit float.
#include <map>
#include <string>
#include <vector>

#include "io/output_ply.h"
#include "fit/reflectance_fit.h"

namespace vbrdf {

// Everything the result stores for one vertex besides geometry and display colour.
struct VertexRecord {
  float diffuse[3] = {0.0f, 0.0f, 0.0f};  // linear k_d C shown (0 without a model)
  float n_visible = 0.0f, n_diffuse = 0.0f, n_specular = 0.0f;
  float coloured = 0.0f;  // 0 input colour kept, 1 clean pixels, 2 rim/mixed pixels only, 3 neighbours
  float material = 0.0f;  // material stage (materials.h): 1..K, 0 = none (stage off, or no model)
  float lobe_form = 0.0f;  // LobeForm of the fit (model/lobe.h): 0 R.E, 1 N.H; one value per result
  float diffuse_form = 0.0f;  // DiffuseForm at the vertex (model/diffuse_form.h): 0 Lambert, 1 coated
  float diffuse_deconvolved = 0.0f;  // 1: k_d C deconvolved through the pixel footprints (albedo_deconvolution.h)
  float mesh_normal[3] = {0.0f, 0.0f, 0.0f};  // the mesh's normal (the geometry's nx ny nz are the shading normal)
  float normal_moved = -1.0f;  // degrees from the mesh normal to the shading normal; -1 not determined (shading_normals.h)
  VertexFit fit = {{0.0f, 0.0f, 0.0f}, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0, kFitNone, 0};  // sentinels
};

enum class AttributeGroup { Always, ReflectanceFit };  // ReflectanceFit: stored only when the reflectance fit ran
enum class AttributeKind { Real, Count, Code };   // what the float holds (Count, Code: whole numbers)

struct ResultAttribute {
  const char *name;       // PLY property and MeshLab per-vertex attribute name
  AttributeKind kind;
  AttributeGroup group;
  bool needed_for_model;  // a reader cannot rebuild the reflectance model without it
  const char *meaning;    // one line, as in the README's output table
  float (*get)(const VertexRecord &);
  void (*set)(VertexRecord &, float);  // from a stored value; whole-number fields are clamped
                                       // into their type's range (NaN gives 0)
};

// The table, in file order.
const std::vector<ResultAttribute> &result_schema();

// The entry named `name`, or nullptr.
const ResultAttribute *find_result_attribute(const std::string &name);

// The names of the table, in file order, separated by ", " (for help texts).
std::string result_attribute_names();

// One VertexAttribute per schema entry of group Always, plus group ReflectanceFit when `with_fit`, in
// table order, each with one value per record. Values are copied as they are: the PLY writer
// refuses non-finite ones.
std::vector<VertexAttribute> result_attributes(const std::vector<VertexRecord> &records, bool with_fit);

// Named per-vertex columns, e.g. ResultPly::vertex_properties or a mesh's float attributes.
using ResultColumns = std::map<std::string, std::vector<float>>;

// Name of the first schema entry with needed_for_model missing from `columns`, "" when none is.
std::string first_missing_model_attribute(const ResultColumns &columns);

// Records from `columns`: every schema attribute present is read by its name; absent ones keep
// VertexRecord's defaults (iterations 0, converged 0 always: it is not stored). The vertex count
// is the longest column of the schema (0 when none). Throws InputError naming `source` and the
// attribute when a schema column has another length. Columns outside the schema are ignored.
std::vector<VertexRecord> records_from_columns(const ResultColumns &columns, const std::string &source);

// The lobe form of a result (the 'lobe_form' of its modelled vertices; PhongRE when absent, as in
// files written before the attribute existed). Throws InputError naming `source` when the
// modelled vertices disagree.
LobeForm lobe_form_of(const std::vector<VertexRecord> &records, const std::string &source);
// The diffuse forms of a result ('diffuse_form': Lambert when absent): uniform when every modelled
// vertex has the same, else per vertex (a coat map, diffuse_choice.h).
DiffuseForms diffuse_forms_of(const std::vector<VertexRecord> &records);

} // namespace vbrdf
