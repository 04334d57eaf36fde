#pragma once
// Chooses the diffuse term's form (diffuse_form.h) from the scene's own photos: a pilot fit of a
// subset of the vertices under each form, every 4th photo held out; the forms whose fits predict
// the held-out photos best are used for the real fit. Light-side evidence suffices: by reciprocity
// the coat's transmission has the same curve for light and view, and the held-out photos differ
// from the training ones in their lights.
//
// Three candidates: Lambert everywhere, coated everywhere, and a coat map: coated where the photos
// favour the coat, Lambert elsewhere (a scene may hold both, e.g. a varnished part beside bare stone,
// or the two materials of bunny_two_materials_dir32).
//
// Contract:
// - Pilot vertices: every k-th vertex among those seen by at least 4 photos, k chosen for about
//   `pilot_vertices` of them (all when fewer). No pilot (Lambert, the thesis's form, with the
//   reason in `note`) when fewer than 50 such vertices exist or fewer than 4 photos see the mesh.
// - Each form's samples are gathered for the pilot vertices only (the caller's PhotoCache: with
//   every photo in memory this costs no decoding), passed through `prepare` (the same colour
//   correction and light fall-off as the fit), fitted on the photos with raster % 4 != f by the
//   CPU reference (fit_vertex_cpu), and scored on the usable samples (lit, unsaturated, clean,
//   d > 0) of the photos with raster % 4 == f: mean absolute RGB error. Folds f = 3, 1, 2, 0 in
//   turn until at least 8 photos were held out (heldout_folds.h, shared with the material stage).
// - Shading normals (`normals.enabled`, as the fit refines them: fit/shading_normals.h): each
//   pilot vertex's normal is refined from its training samples with its fitted model, its samples
//   shaded again and the vertex fitted again (one round), and the held-out samples (the same ones
//   under every form) are predicted with that normal. A scan's smoothed normals would otherwise
//   decide the form: the form that best absorbs a wrong normal is not the one the fit needs.
// - Coat map: a pilot vertex is labelled coated when its 9 nearest other pilot vertices (3-D
//   distance; itself left out) together predict their held-out photos better coated than
//   Lambertian; every mesh vertex then takes the label of the nearest pilot vertex over the mesh's
//   edges (components no pilot vertex reaches: the uniform choice). The map's held-out error is
//   that of each pilot vertex under its own label, which its own error did not decide.
// - Choice: coated everywhere only when its error is below (1 - margin) x Lambert's; the coat map
//   only when it holds both labels on >= 5 % of the pilot vertices each and its error is below
//   (1 - map_margin) x the uniform choice's. Errors are finite sums (non-finite samples are skipped
//   by the fit's rules and the scoring's); with no scored sample Lambert is kept.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "fit/heldout_folds.h"
#include "fit/reflectance_fit.h"
#include "fit/shading_normals.h"
#include "inputs/light_source.h"
#include "base/mesh_view.h"
#include "inputs/photo.h"
#include "samples/samples.h"

namespace vbrdf {

struct DiffuseChoice {
  DiffuseForms forms;            // the choice (uniform, or a per-vertex coat map)
  bool piloted = false;          // false: no pilot ran (note says why)
  size_t pilot_vertices = 0;
  size_t scored_samples = 0;     // held-out samples scored (the same set for every candidate)
  double heldout_error[3] = {0, 0, 0};  // Lambert, coated, coat map: mean absolute RGB error (map: 0 if not tried)
  double seconds = 0;
  std::string note;              // one line for the report and the log
};

struct DiffuseChoiceOptions {
  size_t pilot_vertices = 3000;
  double margin = 0.10;      // relative improvement coated everywhere must show over Lambert
                             //   (docs/decisions/diffuse_form.md)
  double map_margin = 0.05;  // relative improvement the coat map must show over the uniform choice
  ShadingNormalSettings normals = unrefined();  // the fit's shading-normal settings (enabled: refine as it does)

  static ShadingNormalSettings unrefined() {
    ShadingNormalSettings s;
    s.enabled = false;
    return s;
  }
};

DiffuseChoice choose_diffuse_forms(const MeshView &mesh, const std::vector<Raster> &rasters,
                                   const std::vector<LightSource> &lights, const VisibilityMasks &masks,
                                   const GatherSettings &gather, const ReflectanceFitOptions &phong, PhotoCache &photos,
                                   const std::function<void(SampleChunk &)> &prepare,
                                   const DiffuseChoiceOptions &options = DiffuseChoiceOptions());

} // namespace vbrdf
