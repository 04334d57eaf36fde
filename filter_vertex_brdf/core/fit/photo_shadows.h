#pragma once
// Shadows the photos show but the mesh does not cast. A scan coarser than the photos, a relief
// made from normals, or an occluder left out of the mesh (a support, a hand) leaves samples the
// shadow passes call lit although the photo is dark there. Fitted as lit, they pull the vertex's
// k_d down and its lobe wide. After the per-vertex fit (either back end) each vertex's samples are
// held against its model: a sample far darker than the model's diffuse part predicts is flagged
// kCastShadow (a shadow cast by something the mesh lacks; every later stage leaves shadowed
// samples out) and the vertex is fitted again on the CPU. Safeguards: only where the model
// predicts clearly more than noise, never more than half of a vertex's usable samples, and never
// leaving fewer than kPhotoShadowMinRemaining; one pass.
#include <cstddef>

#include "fit/reflectance_fit.h"
#include "samples/samples.h"

namespace vbrdf {

struct PhotoShadowSettings {
  bool enabled = true;
  float darker_than = 0.3f;       // observed below this fraction of the model's diffuse part: a shadow
  float min_predicted = 0.02f;    // ... where that part is at least this (linear, mean of R, G, B)
  float max_share = 0.5f;         // at most this share of a vertex's usable samples is flagged
};
constexpr size_t kPhotoShadowMinRemaining = 3;

// Flags (kCastShadow) the samples of one vertex that `fit` (its model) says should be lit and the
// photo shows in shadow (darker than darker_than x the model's diffuse part k_d C d, so that a lobe
// that overshoots a sample does not make it a "shadow"), under the safeguards above. Usable: not
// shadowed, saturated or unseen, diffuse factor d > 0, finite. Returns how many were flagged; 0
// leaves the samples as they were.
size_t flag_photo_shadows(const VertexFit &fit, Sample *samples, size_t count, const PhotoShadowSettings &settings);

// Per chunk (after the fit): flags every modelled vertex's photo shadows and refits the vertices
// that had any, with the CPU reference (fit_vertex_cpu; the fallback rules of fit_vertex_weak for
// fit_status 4, or when the strict rules find nothing left). `fits` has one entry per chunk vertex.
// Adds the flagged samples and refitted vertices to the counters.
void refit_photo_shadows(SampleChunk &chunk, const ReflectanceFitOptions &options, const PhotoShadowSettings &settings,
                         VertexFit *fits, size_t &flagged_samples, size_t &refitted_vertices);

} // namespace vbrdf
