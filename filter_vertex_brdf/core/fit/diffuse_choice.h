#pragma once
// Chooses the diffuse term's form (diffuse_form.h) for a scene from its own photos: a pilot fit of
// a subset of the vertices under each form, every 4th photo held out, and the form whose fits
// predict the held-out photos better is used for the real fit. Light-side evidence suffices: by
// reciprocity the coat's transmission has the same curve for light and view, and the held-out
// photos differ from the training ones in their lights.
//
// Contract:
// - Pilot vertices: every k-th vertex among those seen by at least 4 photos, k chosen for about
//   `pilot_vertices` of them (all when fewer). No pilot (Lambert, the thesis's form, with the
//   reason in `note`) when fewer than 50 such vertices exist or fewer than 4 photos see the mesh.
// - Each form's samples are gathered for the pilot vertices only (the caller's PhotoCache: with
//   every photo in memory this costs no decoding), passed through `prepare` (the same colour
//   correction and light fall-off as the fit), fitted on the photos with raster % 4 != 3 by the
//   CPU reference (fit_vertex_cpu), and scored on the usable samples (lit, unsaturated, clean,
//   d > 0) of the photos with raster % 4 == 3: mean absolute RGB error over all pilot vertices.
// - Coated is chosen only when its held-out error is below (1 - margin) x Lambert's: the thesis's
//   form stays where the data do not ask for the coat. Errors are finite sums (non-finite samples
//   are skipped by the fit's rules and the scoring's); with no scored sample Lambert is kept.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "fit/phong_fit.h"
#include "inputs/light_source.h"
#include "base/mesh_view.h"
#include "inputs/photo.h"
#include "samples/samples.h"

namespace vbrdf {

struct DiffuseChoice {
  DiffuseForm form = DiffuseForm::Lambert;
  bool piloted = false;          // false: no pilot ran (note says why)
  size_t pilot_vertices = 0;
  size_t scored_samples = 0;     // held-out samples scored (the same set for both forms)
  double heldout_error[2] = {0, 0};  // per form (index = DiffuseForm): mean absolute RGB error
  double seconds = 0;
  std::string note;              // one line for the report and the log
};

struct DiffuseChoiceOptions {
  size_t pilot_vertices = 3000;
  double margin = 0.10;  // relative improvement the coated form must show (see README "The diffuse term's form")
};

DiffuseChoice choose_diffuse_form(const MeshView &mesh, const std::vector<Raster> &rasters,
                                  const std::vector<LightSource> &lights, const VisibilityMasks &masks,
                                  const GatherSettings &gather, const PhongFitOptions &phong, PhotoCache &photos,
                                  const std::function<void(SampleChunk &)> &prepare,
                                  const DiffuseChoiceOptions &options = DiffuseChoiceOptions());

} // namespace vbrdf
