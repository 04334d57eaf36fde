#pragma once
// What the live view ("Vertex BRDF: relight", render_plugin/) needs from a MeshLab mesh: its
// arrays and the per-vertex reflectance model read from the mesh's float attributes by their schema
// names (kd, ks, shininess, color_r/g/b, fit_status, dq, sq, lobe_form, diffuse_form), as the fit
// filter stores them and "Vertex BRDF: load result attributes" re-attaches them from a result PLY.
// No GL here.
#include <cstdint>
#include <string>
#include <vector>

#include "core/fit/reflectance_fit.h"
#include "core/model/diffuse_form.h"
#include "core/model/defaults.h"
#include "core/model/lobe.h"
#include "meshlab_bridge.h"

namespace vbrdf_plugin {

struct RelightModel {
  MeshArrays arrays;
  std::vector<vbrdf::VertexFit> fits;  // one per array vertex
  vbrdf::LobeForm lobe = vbrdf::kDefaultLobe;
  vbrdf::DiffuseForms diffuse;  // per vertex where the fit made a coat map
  size_t modelled = 0;                 // vertices with fit_status != 0
};

// The model of `mesh`. Throws vbrdf::InputError with the message the live view shows when an
// attribute the model needs is missing (naming it, the mesh and the remedy: run the fit, or load
// the result PLY with "Vertex BRDF: load result attributes"), when no vertex has a model, or when
// the mesh has no normals.
RelightModel relight_model(MeshModel &mesh);

// A cheap fingerprint of the mesh's model attributes (vertex and face counts, and a sample of the
// kd, ks and shininess values): changes when a filter re-fits or re-attaches them, so that the
// live view re-uploads. 0 when the mesh has no kd attribute.
uint64_t relight_model_fingerprint(MeshModel &mesh);

} // namespace vbrdf_plugin
