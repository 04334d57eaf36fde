#pragma once
// Shading normals refined from the photos, jointly with the reflectance (alternating, as
// photometric stereo with spatially varying reflectance does: Goldman et al. 2005/2010, Alldrin et
// al. 2008). A scanned mesh is smoother than the surface (its normals a few degrees off); the
// photos under many lights see the surface's own shading, so each vertex's normal is moved to the
// one its fitted model explains its samples best with, as far as the samples determine it.
//
// Per vertex (the chunk's vertices with a model fitted from their own samples, fit_status 1 or 2):
//   minimise  sum_i w_i rho(|P_i - f(n; L_i, E_i)| / sigma) + |x|^2 / sigma_m^2
//   over n = normalise(n_mesh + x_1 t_1 + x_2 t_2) (t_1, t_2: the mesh normal's tangent plane),
//   f the vertex's model (reflectance_fit.h) with its fitted shininess held and k_d C and k_s solved in
//   closed form at each trial normal (variable projection: brightness and tilt trade against each
//   other, so solving them together converges where alternating crawls), w_i the sample's
//   resolution weight, rho Huber at 2 sigma, sigma the samples' residual per channel at the
//   current normal, floored at noise_floor x their mean brightness, sigma_m = mesh_normal_degrees
//   (the prior: the mesh normal is right to within a few degrees). Highlight samples are left out
//   unless use_highlights (and the vertex has a lobe): a lobe fitted with the wrong normal would
//   otherwise pull the normal towards it. Gauss-Newton with Levenberg-Marquardt damping on numeric
//   derivatives (double precision). The mesh normal is kept unless the solution lowers the cost by
//   more than min_gain (noise alone does not move a right normal).
// Then over the mesh: the corrections x (as tangent vectors) are smoothed towards the neighbours'
//   with strength 1 / neighbour_degrees^2 against each vertex's own information matrix (Jacobi
//   sweeps within the chunk), so a vertex the samples determine weakly in one direction (lights all
//   to one side) takes its neighbours' correction there, and one they determine well keeps its own.
// Safeguards: fewer than min_samples usable samples (lit by the mesh's shadow test, unsaturated,
// clean pixel) or no direction the data determine better than the prior: the mesh normal is kept
// (counted as undetermined). A correction is bounded by max_degrees. A singular or non-finite
// system leaves the mesh normal. Visibility and shadows keep the mesh's geometry: only shading
// (Sample::d, Sample::lobe_cos and the flags that follow from them, samples/reshade.h) uses the
// refined normal.
#include <cstdint>
#include <vector>

#include "base/mesh_adjacency.h"
#include "base/mesh_view.h"
#include "fit/reflectance_fit.h"
#include "inputs/light_source.h"
#include "inputs/photo.h"
#include "samples/samples.h"

namespace vbrdf {

struct ShadingNormalSettings {
  bool enabled = true;
  float mesh_normal_degrees = 8.0f;  // the prior's spread: how far a scan's normal may be off
  float neighbour_degrees = 6.0f;    // how far neighbouring vertices' corrections may differ
  float max_degrees = 30.0f;         // bound on a correction
  int min_samples = 6;               // fewer usable samples: the mesh normal is kept
  float noise_floor = 0.01f;         // residual spread never below this fraction of the mean brightness
  int iterations = 8;                // Gauss-Newton steps per vertex
  int neighbour_sweeps = 8;          // Jacobi sweeps of the neighbour smoothing
  float min_gain = 4.6f;             // cost fall that moves a normal (half the 99 % chi-square of 2 dof)
  bool use_highlights = false;       // highlight samples inform the normal too (where the vertex has a lobe)
  int rounds = 3;                    // alternations: refine the normals, shade again, fit again
  float converged_degrees = 0.05f;   // a normal that moves less in a round is converged: kept, not refitted
};

struct ShadingNormalCounts {
  size_t refined = 0;       // vertices whose normal the samples determine (moved or not)
  size_t undetermined = 0;  // modelled vertices that keep the mesh normal (too few samples / lights)
};

// Refines the shading normals of the chunk's vertices from their samples (shaded with the normals
// in `normals`, 3 per mesh vertex: the mesh's in the first round, the previous round's after) and
// fits (fits[i] for chunk vertex i); the prior is on mesh.normals. Writes, for the chunk's vertices
// only: `normals` (unit), `moved_degrees` (per mesh vertex: angle from the mesh normal, -1 where
// not determined) and `changed` (per chunk vertex: 1 where the normal moved by more than
// converged_degrees; a smaller move is not made). `active` (per chunk vertex; null: all) limits the
// solve to the vertices still moving; the others keep their normals and count as fixed neighbours.
ShadingNormalCounts refine_shading_normals(const SampleChunk &chunk, const MeshView &mesh, const MeshAdjacency &adjacency,
                                           const std::vector<Raster> &rasters, const std::vector<LightSource> &lights,
                                           const DiffuseForms &forms, LobeForm lobe, const VertexFit *fits,
                                           const ShadingNormalSettings &settings, const uint8_t *active, float *normals,
                                           float *moved_degrees, uint8_t *changed);

// One vertex's shading normal from its own samples alone (no neighbour term): the solve of
// refine_shading_normals (prior on `mesh_normal`, min_gain, max_degrees) for a caller that fits
// vertices one by one, such as the diffuse form's pilot (fit/diffuse_choice.h), which must score
// a model shaded as the product's fit shades it. `normal` (unit) is where the solve starts and,
// on return, the refined normal; samples at `position` (camera centres 3 per raster). Returns
// true when it moved by more than converged_degrees; false (normal unchanged) when the fit has no
// model, there are fewer than min_samples usable samples, or they do not determine the normal.
bool refine_vertex_normal(const Sample *samples, size_t count, const float position[3], const float mesh_normal[3],
                          const float *centres, const std::vector<LightSource> &lights, const VertexFit &fit,
                          DiffuseForm form, LobeForm lobe, const ShadingNormalSettings &settings, float normal[3]);

// Median and 95th percentile of the values >= 0 of `moved_degrees` at the vertices with select[v]
// != 0 (all when `select` is empty); count = how many there were.
struct MovedSummary {
  size_t count = 0;
  float median = 0, p95 = 0;
};
MovedSummary summarise_moved(const std::vector<float> &moved_degrees, const std::vector<uint8_t> &select = {});

} // namespace vbrdf
