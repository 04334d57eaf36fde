#pragma once
// Reads back a result PLY written by write_result_ply (binary little endian): geometry plus every
// per-vertex scalar property as floats, so that later steps (evaluation, coverage from an existing
// fit, relighting) can start from a saved result. vcglib's importer cannot load custom
// properties, hence this small reader.
#include <map>
#include <string>
#include <vector>

#include "base/mesh_view.h"
#include "fit/reflectance_fit.h"

namespace vbrdf {

struct ResultPly {
  MeshData mesh;  // positions, normals (zero when absent), indices, colors (RGBA8 when present)
  std::map<std::string, std::vector<float>> vertex_properties;  // every vertex property, as float
};

// Throws InputError naming the file when it is missing, not a binary little-endian PLY, or
// truncated.
ResultPly read_result_ply(const std::string &path);

// Per-vertex fits from the properties named in the result schema (result_schema.h), by name:
// every model attribute present is read (dq, sq, fit_rmse and fit_iterations may be absent: 0).
// Throws InputError naming the first missing attribute needed for the model (kd, ks, shininess,
// color_r/g/b, fit_status), or a column of the wrong length.
// `lobe` and `diffuse` (optional) receive the result's lobe and diffuse forms (lobe_form_of,
// diffuse_forms_of); `deconvolved` (optional) one flag per vertex: its k_d C was deconvolved through
// the pixel footprints (diffuse_deconvolved; absent: 0).
std::vector<VertexFit> fits_from_result(const ResultPly &result, const std::string &path, LobeForm *lobe = nullptr,
                                        DiffuseForms *diffuse = nullptr, std::vector<uint8_t> *deconvolved = nullptr);

} // namespace vbrdf
