#pragma once
// A viewpoint's camera checked and refined by the fitted model's residual, after registration.h
// has measured and corrected it from the photos' Lambertian normal map.
//
// Why: the normal map is biased by what a Lambertian per-pixel fit cannot explain (broad lobes,
// open mesh borders, shadows), by 0.02-0.07 px on the shared scenes and by up to 1.3 px on
// synthetic ones, and a fit is sensitive at that scale (0.07 px costs spot and bunny 15 % of their
// relit error). When the photos are shifted against the mesh, each vertex's samples come from a
// neighbouring surface point whose shading its mesh normal does not predict; no per-vertex model
// explains that, so the residual of per-vertex fits made with the mesh's normals is least at the
// true camera (within 0.015 px on the shared scenes: docs/decisions/registration.md).
//
// Contract:
// - Pilot vertices: every k-th vertex seen by at least 4 of the viewpoint's photos and on no
//   silhouette or contact in any of them (mixed pixels move with the camera in a way the masks,
//   made from one camera, do not follow), k chosen for about `pilot_vertices`.
// - Residual at a shot: the viewpoint's photos, taking that shot, are sampled at the pilot
//   vertices (the caller's masks, PhotoCache and `prepare`: colour correction and light fall-off
//   as the fit applies them); each vertex is fitted by the CPU reference (fit_vertex_cpu, the
//   mesh's normals) and its usable samples (lit, unsaturated, clean, d > 0) scored by their mean
//   absolute RGB error. The residual is the trimmed mean over all of them: the `trimmed_share`
//   the models explain best. The samples no per-vertex model explains (interreflections, shadow
//   edges, the tails of broad lobes) do not move with the camera as the others do and pull the
//   minimum off the true camera (spot: 0.06 px with every sample, 0.02 px with the best half).
//   Non-finite samples are skipped; with no scored sample it is +infinity.
// - Refinement: a quadratic in (dx, dy) fitted to the residual on a 3x3 grid of image shifts of
//   `step_px`; its minimum when the quadratic is convex and the minimum lies within 1.5 steps of the
//   grid's centre, else the best grid point and a new grid about it; at most `max_rounds` grids,
//   and the shift never beyond `max_shift_px` from the start. The refined shift is kept only when its
//   residual is below the start's and it lies within `trusted_shift_px` of the start; else the start
//   is kept (`beyond_trust` says when the residual's minimum lay farther). Then the roll about the
//   optical axis (refine_roll_by_residual), which the normal map reads to within a few hundredths of
//   a degree; the caller refines no roll with a residual whose shift was beyond trust.
// - The masks may come from a camera a few pixels away (the fit makes them at the given camera and
//   checks the correction against it): the pilot leaves out the rims, where that would matter.
#include <cstddef>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "base/mesh_view.h"
#include "fit/reflectance_fit.h"
#include "inputs/camera.h"
#include "inputs/light_source.h"
#include "inputs/photo.h"
#include "samples/samples.h"
#include "visibility/visibility_masks.h"

namespace vbrdf {

struct ResidualAlignmentSettings {
  bool enabled = true;
  size_t pilot_vertices = 4000;  // per viewpoint (docs/decisions/registration.md: fewer read noisier)
  double step_px = 0.1;          // grid spacing: the residual is a clean quadratic over +-0.2 px
  double max_shift_px = 0.3;     // the refinement's search reach from the start camera
  // A minimum found farther than this from the start camera is not taken: the normal map's own
  // bias on meshes with the surface's normals is at most 0.07 px, and a residual made with normals
  // that are off (a scan smoothed by a few degrees) pulls 0.18-0.42 px away from the true camera
  // (docs/decisions/registration.md). The residual is then taken to be biased and the start kept.
  double trusted_shift_px = 0.12;
  // A correction is refused when its residual exceeds the given camera's by more than this share.
  // The false readings of synthetic captures (open borders, broad lobes) raise it by 50-610 %; on a
  // scan smoothed by a few degrees the residual cannot tell the true camera from one a pixel off
  // (Seitz owl: the true correction 1.6 % above the given camera) and the normal map's reading stands.
  double refuse_margin = 0.05;
  int max_rounds = 3;
  double trimmed_share = 0.5;    // of the scored samples, the best explained (docs/decisions/registration.md)
};

// The residual of one viewpoint's photos at any shot of its camera (see the contract above).
class ViewpointResidual {
public:
  ViewpointResidual(const MeshView &mesh, const std::vector<Raster> &rasters, const std::vector<size_t> &viewpoint,
                    const std::vector<LightSource> &lights, const VisibilityMasks &masks, const GatherSettings &gather,
                    const ReflectanceFitOptions &fit, PhotoCache &photos,
                    const std::function<void(SampleChunk &)> &prepare, size_t pilot_vertices,
                    double trimmed_share);
  size_t pilot_vertices() const { return pilot_count_; }
  double at(const Shot &shot);
  // RMS distance (pixels) of the pilot vertices' projections from the principal point of `shot`.
  double rms_radius(const Shot &shot) const;

private:
  const MeshView &mesh_;
  std::vector<Raster> rasters_;  // every raster; the viewpoint's take the shot being scored
  std::vector<size_t> viewpoint_;
  const std::vector<LightSource> &lights_;
  size_t pilot_count_ = 0;       // before pilot_, whose initialisation sets it
  VisibilityMasks pilot_;        // the viewpoint's photos and the pilot vertices only
  GatherSettings gather_;
  const ReflectanceFitOptions &fit_;
  PhotoCache &photos_;
  const std::function<void(SampleChunk &)> &prepare_;
  double trimmed_share_;
};

struct ResidualShift {
  double dx = 0, dy = 0;                 // image shift from the start camera (pixels)
  double residual_start = 0, residual_end = 0;
  bool moved = false;                    // false: the start camera had the lower residual, or beyond trust
  bool beyond_trust = false;             // the residual's minimum lay beyond trusted_shift_px: not taken
  double found_dx = 0, found_dy = 0;     // where that minimum lay (pixels from the start)
};

// Minimises the residual over image shifts of `start` (see the contract above).
// `start_residual`: residual.at(start) when the caller has it (NaN: computed here).
ResidualShift refine_shift_by_residual(ViewpointResidual &residual, const Shot &start,
                                       const ResidualAlignmentSettings &settings,
                                       double start_residual = std::numeric_limits<double>::quiet_NaN());

struct ResidualRoll {
  double roll = 0;                       // radians about the optical axis (ImageWarp::roll), from the start camera
  double residual_start = 0, residual_end = 0;
  bool moved = false;
};

// Refines the roll about the optical axis after the shift: a parabola through the residual at the
// start and at rolls of +-delta, delta moving the pilot vertices by `step_px` (RMS) about the
// principal point; its minimum when convex and within 2 delta, kept only when its residual is
// lower. `start_residual`: residual.at(start) when the caller has it (NaN: computed here).
ResidualRoll refine_roll_by_residual(ViewpointResidual &residual, const Shot &start,
                                     const ResidualAlignmentSettings &settings,
                                     double start_residual = std::numeric_limits<double>::quiet_NaN());

// `shot` turned about its optical axis by `roll` radians (ImageWarp::roll).
Shot rolled_shot(const Shot &shot, double roll);

// `shot` turned about its centre so that its image moves by (dx, dy) pixels at the principal point
// (x right, y down): pitch and yaw, as registration.h applies a shift.
Shot shifted_shot(const Shot &shot, double dx, double dy);

} // namespace vbrdf
