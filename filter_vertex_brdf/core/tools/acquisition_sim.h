#pragma once
// The thesis's Table 4.1 experiment (4.4.1): how many photos an acquisition needs when the
// photographer follows the next-light suggestions, simulated on a dense set of candidate photos of
// one viewpoint (photos already taken under many lights). Start from one photo; then repeatedly
// ask for the next light and take the not yet used candidate whose light is nearest to it, until
// every vertex is covered. Baselines: random order, an exact (O(n^2)) suggestion instead of the
// binned one, every candidate light tested with the same coverage prediction as the suggestions,
// and an oracle that takes the candidate adding the most actually covered vertices (greedy set
// cover on the measured samples: a lower bound no prediction can beat).
//
// Targets: a vertex counts for diffuse coverage when at least one candidate gives it a diffuse
// sample, and for specular coverage when it is a diffuse target and some candidate gives it a
// specular sample; vertices no candidate can cover are left out (they need another viewpoint).
// Full coverage = every diffuse target has a diffuse sample and every specular target a specular
// one (min 1 each), i.e. every target vertex is "fully covered" in coverage_run's classes. By
// default each strategy first completes diffuse coverage, then specular coverage (the thesis's
// order); SimGoal::Both considers both kinds at every photo. The suggestions see only the target
// vertices still uncovered, weighted down by prediction_failure_weight for each taken photo whose
// light (or whose suggestion) promised to cover them and did not, and they learn from those
// failures (suggest_light_learning) as run_coverage does with the photos taken so far.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "inputs/camera.h"
#include "coverage/coverage.h"
#include "base/mesh_view.h"
#include "samples/samples.h"
#include "visibility/visibility.h"

namespace vbrdf {

// Candidate photos with their coverage, gathered once. Bitsets are candidate-major:
// word (c * words + v / 64), bit v % 64.
struct CandidateSet {
  MeshView mesh;                                  // not owned: the caller keeps it alive
  Shot shot;                                      // the shared viewpoint
  std::vector<uint8_t> visible;                   // per vertex: seen and clean from the viewpoint
  std::vector<std::array<float, 3>> lights_world; // per candidate, unit, towards the light
  std::vector<std::string> names;                 // per candidate (raster labels)
  size_t words = 0;
  std::vector<uint64_t> diffuse, specular;        // vertices each candidate covers
  bool covers_diffuse(size_t c, size_t v) const { return (diffuse[c * words + v / 64] >> (v % 64)) & 1u; }
  bool covers_specular(size_t c, size_t v) const { return (specular[c * words + v / 64] >> (v % 64)) & 1u; }
  size_t size() const { return lights_world.size(); }
};

// Runs visibility and gathers the samples of every candidate once. All rasters must share one
// shot (InputError naming the first raster of another viewpoint); photos are read with
// `gather`'s settings. `lights_world` has one unit direction per raster.
CandidateSet gather_candidates(const MeshView &mesh, const std::vector<Raster> &rasters,
                               const std::vector<std::array<float, 3>> &lights_world, VisibilityBackend &visibility,
                               const GatherSettings &gather, const ProgressFn &progress = {});

enum class SimStrategy {
  Binned,      // suggest_next_light (latitude/longitude bins), nearest candidate
  BruteForce,  // suggest_next_light_brute_force (exact, O(n^2)), nearest candidate
  Predicted,   // every candidate light tested with the suggestions' coverage prediction
  Oracle,      // candidate adding the most measured coverage
  Random,      // random order (SimSettings::seed)
};
const char *sim_strategy_name(SimStrategy s);

enum class SimGoal {
  DiffuseThenSpecular,  // complete diffuse coverage first (the thesis's Table 4.1), then specular
  Both,                 // at every photo, whichever kind promises more (the tool shows both)
};

struct SimSettings {
  SimGoal goal = SimGoal::DiffuseThenSpecular;
  LightSuggestionSettings suggest;  // thresholds should be the gather's
  float tolerance_deg = 0;          // suggestions robust to this placement error (suggest_light_with_tolerance)
  float failure_cone_deg = 20;      // suggest_light_learning's cone; 0: plain suggestions (the thesis's)
  size_t start = 0;                 // candidate taken first
  uint32_t seed = 1;                // Random's permutation
};

struct SimRun {
  SimStrategy strategy = SimStrategy::Binned;
  size_t start = 0;
  std::vector<size_t> order;          // candidates taken, start first
  std::vector<size_t> uncovered;      // after each photo: uncovered diffuse + specular targets
  // Per decision of a suggestion strategy (empty for the others): vertices the suggestion predicts
  // to cover, vertices the chosen photo actually covered, and its angle from the suggestion.
  std::vector<size_t> predicted, gained;
  std::vector<float> offset_deg;
  std::vector<std::array<float, 3>> answered;  // the suggested lights the photos answered (world)
  size_t target_diffuse = 0, target_specular = 0;
  size_t photos_diffuse = 0;          // photos taken when diffuse coverage was complete (0: never)
  size_t photos_full = 0;             // photos taken when coverage was complete (0: never)
  size_t left_diffuse = 0, left_specular = 0;  // targets still uncovered at the end
  bool stalled = false;               // stopped early: no suggestion, or no candidate left
  size_t choices = 0;                 // next-photo decisions made
  double seconds = 0;                 // time of all decisions (suggestion + nearest candidate)
  double seconds_max_choice = 0;      // slowest decision
};

// Simulates one acquisition. Throws InputError when settings.start is not a candidate.
SimRun simulate_acquisition(const CandidateSet &set, SimStrategy strategy, const SimSettings &settings);

// Index of the candidate not in `taken` whose light is nearest (largest cosine) to `dir_world`;
// returns set.size() when every candidate is taken.
size_t nearest_candidate(const CandidateSet &set, const std::vector<uint8_t> &taken, const float dir_world[3]);

} // namespace vbrdf
