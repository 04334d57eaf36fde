#pragma once
// The next light to take: suggestions robust to where the photographer puts the light, that learn
// from the lights already taken (a light predicted to cover a vertex that still lacks the sample
// failed it: a cast shadow or a clipped pixel), and the per-vertex needs they serve.
#include <array>
#include <cstdint>
#include <vector>

#include "coverage/coverage.h"
#include "inputs/light_source.h"
#include "inputs/viewpoints.h"
#include "base/mesh_view.h"

namespace vbrdf {

struct CoverageSettings;

// Suggestions robust to where the photographer actually puts the light: the thresholds tightened
// by `tolerance_deg` (diffuse: N.L >= cos(acos(T_d) - tol) and R.E <= cos(acos(T_s) + tol);
// specular: R.E >= cos(acos(T_s) - tol)), so that a light placed up to that far from the
// suggestion still covers what it promises. Falls back to the exact thresholds when no light is
// robust. `covered_vertices` of the result counts with the exact thresholds; `robust_covered`
// (optional) receives the count that holds within the tolerance (0 after a fallback).
// `brute_force`: suggest_next_light_brute_force instead of the binned search (tests, Table 4.1).
LightSuggestion suggest_light_with_tolerance(const MeshView &mesh, const Shot &viewpoint, const uint8_t *visible,
                                             const float *needs, CoverageKind kind, const LightSuggestionSettings &s,
                                             float tolerance_deg, size_t *robust_covered = nullptr,
                                             bool brute_force = false);

// The next light, learning from the photos taken so far: a vertex that still needs samples
// although a photo's light near the suggestion (within `failure_cone_deg`) was predicted to give
// it one (a cast shadow or a clipped pixel prevented it; the prediction cannot know) does not
// count for that suggestion. Otherwise the vertex's ideal light (Algorithms 1/3) would bring the
// same failed light back again and again. So: failed vertices whose own best direction (normal,
// mirror direction) lies near a light that failed them are left out of the binned search; a
// suggestion that still counts many failed vertices is recomputed without them (at most 4
// rounds); if nothing is left, 600 directions over the placeable hemisphere are scored with the
// failures taken into account. When every light predicted to help has failed, the plain
// suggestion is returned and *repeats_failed (optional) is set. Without taken lights or failures
// this is suggest_light_with_tolerance. `taken_lights`: world directions of the photos of this
// viewpoint (and of suggestions that were followed). Needs and tolerance as above.
LightSuggestion suggest_light_learning(const MeshView &mesh, const Shot &viewpoint, const uint8_t *visible,
                                       const float *needs, CoverageKind kind, const LightSuggestionSettings &s,
                                       float tolerance_deg, const std::vector<std::array<float, 3>> &taken_lights,
                                       float failure_cone_deg = 20.0f, size_t *robust_covered = nullptr,
                                       bool *repeats_failed = nullptr, bool brute_force = false);

// Weight factor of a vertex that still needs samples although `failures` photos of its viewpoint
// had a light predicted to give it such a sample (a cast shadow or a saturated pixel prevented
// it; the prediction cannot know): 0.2^failures, so that the next suggestion moves on instead of
// repeating a light whose shadow hides the vertex.
float prediction_failure_weight(int failures);

// Per-vertex weights of the vertices that need samples (0: needs none). See CoverageSettings.
struct CoverageNeeds {
  std::vector<float> diffuse, specular;
  size_t poor_diffuse = 0, poor_specular = 0;  // covered vertices that need samples for a poor fit
};

// Needs from coverage counts and, when `dq`/`sq` are non-null, fit quality (see CoverageSettings).
// Only vertices with at least one diffuse sample can need specular samples (the fit needs the
// diffuse part first). `diffuse_failures`/`specular_failures` (optional, per vertex) scale the
// weights of uncovered vertices by prediction_failure_weight.
CoverageNeeds coverage_needs(const std::vector<CoverageCounts> &counts, const float *dq, const float *sq,
                             const CoverageSettings &settings, const uint16_t *diffuse_failures = nullptr,
                             const uint16_t *specular_failures = nullptr);

// Per vertex, how many photos of `viewpoint` had a light that the suggestions' geometry
// (light_covers_diffuse / light_covers_specular) says covers it while the vertex still lacks
// that kind of sample (class kSeenNotDiffuse / kDiffuseNoSpecular); 0 elsewhere.
void prediction_failures(const MeshView &mesh, const std::vector<uint8_t> &classes, const Viewpoint &viewpoint,
                         const std::vector<LightSource> &lights, const LightSuggestionSettings &s,
                         std::vector<uint16_t> &diffuse, std::vector<uint16_t> &specular);

} // namespace vbrdf
