#include "tools/acquisition_sim.h"
#include "base/vec3.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "run/coverage_run.h"
#include "base/errors.h"

namespace vbrdf {

namespace {

inline void set_bit(std::vector<uint64_t> &bits, size_t word0, size_t v) {
  bits[word0 + v / 64] |= uint64_t(1) << (v % 64);
}

size_t popcount_and(const uint64_t *a, const uint64_t *need, size_t words) {
  size_t n = 0;
  for (size_t w = 0; w < words; ++w) n += size_t(__builtin_popcountll(a[w] & need[w]));
  return n;
}

size_t popcount(const std::vector<uint64_t> &bits) {
  size_t n = 0;
  for (uint64_t w : bits) n += size_t(__builtin_popcountll(w));
  return n;
}

// What still needs coverage during one simulated acquisition (bitsets over vertices).
class CoverageState {
public:
  explicit CoverageState(const CandidateSet &set) : set_(set), need_d_(set.words, 0), need_s_(set.words, 0) {
    // Targets: diffuse where any candidate covers diffusely; specular where additionally any
    // candidate covers specularly.
    std::vector<uint64_t> any_s(set.words, 0);
    for (size_t c = 0; c < set.size(); ++c)
      for (size_t w = 0; w < set.words; ++w) {
        need_d_[w] |= set.diffuse[c * set.words + w];
        any_s[w] |= set.specular[c * set.words + w];
      }
    for (size_t w = 0; w < set.words; ++w) need_s_[w] = any_s[w] & need_d_[w];
    target_d_ = popcount(need_d_), target_s_ = popcount(need_s_);
    left_d_ = target_d_, left_s_ = target_s_;
    const size_t n = set.mesh.vertex_count;
    fail_d_.assign(n, 0), fail_s_.assign(n, 0), eyes_.resize(3 * n);
    float centre[3];
    camera_centre(set.shot, centre);
    for (size_t v = 0; v < n; ++v) {
      float *e = &eyes_[3 * v];
      for (int k = 0; k < 3; ++k) e[k] = centre[k] - set.mesh.positions[3 * v + size_t(k)];
      const float l = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
      for (int k = 0; k < 3; ++k) e[k] = l > 0 ? e[k] / l : 0.0f;
    }
  }

  // Remembers, per still uncovered target, the taken lights predicted to cover it that did not
  // (cast shadows are not predicted): the suggestions then weigh it less, as run_coverage does.
  // `suggested` (may be null): the light the photo answered; a vertex it promised counts as a
  // failure too, as when the photographer places the light exactly there.
  void take(size_t c, const float *suggested, bool suggested_diffuse, const LightSuggestionSettings &s) {
    const float *l = set_.lights_world[c].data();
    const float *sd = suggested && suggested_diffuse ? suggested : nullptr;
    const float *ss = suggested && !suggested_diffuse ? suggested : nullptr;
    for (size_t v = 0; v < set_.mesh.vertex_count; ++v) {
      const float *n = set_.mesh.normals + 3 * v, *e = &eyes_[3 * v];
      if (is_set(need_d_, v) && !is_set(set_.diffuse, c * set_.words, v) &&
          (light_covers_diffuse(n, e, l, s) || (sd && light_covers_diffuse(n, e, sd, s))))
        ++fail_d_[v];
      if (is_set(need_s_, v) && !is_set(set_.specular, c * set_.words, v) &&
          (light_covers_specular(n, e, l, s) || (ss && light_covers_specular(n, e, ss, s))))
        ++fail_s_[v];
    }
    for (size_t w = 0; w < set_.words; ++w) {
      need_d_[w] &= ~set_.diffuse[c * set_.words + w];
      need_s_[w] &= ~set_.specular[c * set_.words + w];
    }
    left_d_ = popcount(need_d_), left_s_ = popcount(need_s_);
  }

  size_t gain(size_t c, bool diffuse_phase) const {
    const uint64_t *bits = (diffuse_phase ? set_.diffuse.data() : set_.specular.data()) + c * set_.words;
    return popcount_and(bits, (diffuse_phase ? need_d_ : need_s_).data(), set_.words);
  }

  // Per-vertex weights for suggest_next_light: where the phase's target is still uncovered, 1
  // lowered by the failed predictions (prediction_failure_weight).
  void needs(bool diffuse_phase, std::vector<float> &out) const {
    const std::vector<uint64_t> &bits = diffuse_phase ? need_d_ : need_s_;
    const std::vector<uint16_t> &fails = diffuse_phase ? fail_d_ : fail_s_;
    out.assign(set_.mesh.vertex_count, 0.0f);
    for (size_t v = 0; v < out.size(); ++v)
      if (is_set(bits, v)) out[v] = prediction_failure_weight(fails[v]);
  }

  // Weighted number of needing vertices the geometry predicts light `l` to cover.
  double predicted_gain(const float *l, bool diffuse_phase, const std::vector<float> &needs,
                        const LightSuggestionSettings &s) const {
    double sum = 0;
    for (size_t v = 0; v < needs.size(); ++v) {
      if (!(needs[v] > 0) || !set_.visible[v]) continue;
      const float *n = set_.mesh.normals + 3 * v, *e = &eyes_[3 * v];
      if (diffuse_phase ? light_covers_diffuse(n, e, l, s) : light_covers_specular(n, e, l, s)) sum += needs[v];
    }
    return sum;
  }

  size_t target_d_ = 0, target_s_ = 0, left_d_ = 0, left_s_ = 0;

private:
  static bool is_set(const std::vector<uint64_t> &bits, size_t v) { return (bits[v / 64] >> (v % 64)) & 1u; }
  static bool is_set(const std::vector<uint64_t> &bits, size_t word0, size_t v) {
    return (bits[word0 + v / 64] >> (v % 64)) & 1u;
  }
  const CandidateSet &set_;
  std::vector<uint64_t> need_d_, need_s_;
  std::vector<float> eyes_;
  std::vector<uint16_t> fail_d_, fail_s_;
};

void record(SimRun &run, const CoverageState &state) {
  run.uncovered.push_back(state.left_d_ + state.left_s_);
  if (run.photos_diffuse == 0 && state.left_d_ == 0) run.photos_diffuse = run.order.size();
  if (run.photos_full == 0 && state.left_d_ == 0 && state.left_s_ == 0) run.photos_full = run.order.size();
}

// The suggestion of one kind for the uncovered targets, learning from the photos taken.
LightSuggestion suggest_kind(const CandidateSet &set, const CoverageState &state, const std::vector<uint8_t> &taken,
                             bool diffuse, bool brute, const SimSettings &s, const SimRun &run, std::vector<float> &needs) {
  state.needs(diffuse, needs);
  const CoverageKind kind = diffuse ? CoverageKind::Diffuse : CoverageKind::Specular;
  // What the tool learns from: the lights of the photos taken, and here also the suggestions they
  // answered (the photographer aimed there; the nearest candidate may be far off).
  std::vector<std::array<float, 3>> taken_lights = run.answered;
  for (size_t c = 0; c < set.size(); ++c)
    if (taken[c]) taken_lights.push_back(set.lights_world[c]);
  if (s.failure_cone_deg <= 0) taken_lights.clear();
  return suggest_light_learning(set.mesh, set.shot, set.visible.data(), needs.data(), kind, s.suggest, s.tolerance_deg,
                                taken_lights, s.failure_cone_deg, nullptr, nullptr, brute);
}

// Next candidate of a suggestion strategy: the suggestion of the allowed kind that promises more
// (weighted), then the nearest candidate; set.size() when none. `suggested` receives the light.
size_t choose_by_suggestion(const CandidateSet &set, const CoverageState &state, const std::vector<uint8_t> &taken,
                            bool allow_diffuse, bool allow_specular, bool brute, const SimSettings &s,
                            std::vector<float> &needs, float suggested[3], bool &suggested_diffuse, SimRun &run) {
  LightSuggestion best;
  bool best_diffuse = false;
  for (bool diffuse : {true, false}) {
    if (!(diffuse ? allow_diffuse : allow_specular)) continue;
    const LightSuggestion sg = suggest_kind(set, state, taken, diffuse, brute, s, run, needs);
    if (sg.valid && (!best.valid || sg.covered_weight > best.covered_weight)) best = sg, best_diffuse = diffuse;
  }
  const size_t c = best.valid ? nearest_candidate(set, taken, best.dir_world) : set.size();
  if (c < set.size()) {
    const auto &l = set.lights_world[c];
    const float cs = l[0] * best.dir_world[0] + l[1] * best.dir_world[1] + l[2] * best.dir_world[2];
    run.predicted.push_back(best.covered_vertices);
    run.gained.push_back(state.gain(c, best_diffuse));
    run.offset_deg.push_back(std::acos(std::max(-1.0f, std::min(1.0f, cs))) * 57.2957795f);
    std::copy(best.dir_world, best.dir_world + 3, suggested);
    suggested_diffuse = best_diffuse;
    run.answered.push_back({{best.dir_world[0], best.dir_world[1], best.dir_world[2]}});
  }
  return c;
}

// The candidate whose light the geometry predicts to cover the most (weighted) needing vertices.
size_t choose_by_prediction(const CandidateSet &set, const CoverageState &state, const std::vector<uint8_t> &taken,
                            bool allow_diffuse, bool allow_specular, const SimSettings &s) {
  std::vector<float> needs_d, needs_s;
  if (allow_diffuse) state.needs(true, needs_d);
  if (allow_specular) state.needs(false, needs_s);
  size_t best = set.size();
  double best_gain = 0;
  for (size_t c = 0; c < set.size(); ++c) {
    if (taken[c]) continue;
    const float *l = set.lights_world[c].data();
    const double g = (allow_diffuse ? state.predicted_gain(l, true, needs_d, s.suggest) : 0) +
                     (allow_specular ? state.predicted_gain(l, false, needs_s, s.suggest) : 0);
    if (g > best_gain) best_gain = g, best = c;
  }
  return best;
}

size_t choose_by_oracle(const CandidateSet &set, const CoverageState &state, const std::vector<uint8_t> &taken,
                        bool allow_diffuse, bool allow_specular) {
  size_t best = set.size(), best_gain = 0, best_other = 0;
  for (size_t c = 0; c < set.size(); ++c) {
    if (taken[c]) continue;
    const size_t d = state.gain(c, true), sp = state.gain(c, false);
    const size_t g = (allow_diffuse ? d : 0) + (allow_specular ? sp : 0);
    const size_t other = allow_specular ? 0 : sp;  // tie-break in the diffuse phase: specular bonus
    if (g > best_gain || (g == best_gain && g > 0 && other > best_other)) best = c, best_gain = g, best_other = other;
  }
  return best;
}
} // namespace

CandidateSet gather_candidates(const MeshView &mesh, const std::vector<Raster> &rasters,
                               const std::vector<std::array<float, 3>> &lights_world, VisibilityBackend &visibility,
                               const GatherSettings &gather, const ProgressFn &progress) {
  if (rasters.empty()) throw InputError("No candidate photos: the project has no rasters.");
  if (lights_world.size() != rasters.size())
    throw InputError("Internal: " + std::to_string(lights_world.size()) + " lights for " + std::to_string(rasters.size()) +
                     " candidate photos.");
  const std::vector<Viewpoint> viewpoints = group_viewpoints(rasters);
  if (viewpoints.size() != 1)
    throw InputError("The candidate photos must share one viewpoint (one registration), but raster '" +
                     rasters[viewpoints[1].rasters.front()].label + "' has another shot than '" + rasters.front().label +
                     "': simulate each viewpoint on its own.");
  CandidateSet set;
  set.mesh = mesh;
  set.shot = rasters.front().shot;
  set.lights_world = lights_world;
  for (const Raster &r : rasters) set.names.push_back(r.label);
  const std::vector<LightSource> sources = directional_lights(lights_world);
  const VisibilityMasks masks = compute_visibility(
      mesh, rasters, sources, visibility, [&](float f, const char *s) { return !progress || progress(0.5f * f, s); });
  set.words = masks.words();
  set.visible.assign(mesh.vertex_count, 0);
  for (size_t v = 0; v < mesh.vertex_count; ++v) set.visible[v] = masks.is_seen(0, v) && masks.own_texels(0, v) != 0;
  set.diffuse.assign(set.words * rasters.size(), 0);
  set.specular.assign(set.words * rasters.size(), 0);
  PhotoCache photos(gather.encoding, gather.saturation_level, gather.photo_cache_bytes, gather.host_photos);
  gather_samples(
      mesh, rasters, sources, masks, gather, photos,
      [&](const SampleChunk &chunk) {
        for (uint32_t i = 0; i < chunk.vertex_count; ++i)
          for (uint32_t k = chunk.offsets[i]; k < chunk.offsets[i + 1]; ++k) {
            const Sample &s = chunk.samples[k];
            const size_t v = chunk.first_vertex + i, word0 = size_t(s.raster) * set.words;
            if (is_diffuse_sample(s)) set_bit(set.diffuse, word0, v);
            if (is_specular_sample(s)) set_bit(set.specular, word0, v);
          }
      },
      [&](float f, const char *s) { return !progress || progress(0.5f + 0.5f * f, s); });
  return set;
}

const char *sim_strategy_name(SimStrategy s) {
  switch (s) {
  case SimStrategy::Binned: return "binned";
  case SimStrategy::BruteForce: return "brute-force suggestion";
  case SimStrategy::Predicted: return "all candidates, predicted";
  case SimStrategy::Oracle: return "oracle (best candidate)";
  default: return "random";
  }
}

size_t nearest_candidate(const CandidateSet &set, const std::vector<uint8_t> &taken, const float dir[3]) {
  size_t best = set.size();
  float best_cos = -2;
  for (size_t c = 0; c < set.size(); ++c) {
    if (taken[c]) continue;
    const auto &l = set.lights_world[c];
    const float cs = l[0] * dir[0] + l[1] * dir[1] + l[2] * dir[2];
    if (cs > best_cos) best_cos = cs, best = c;
  }
  return best;
}

SimRun simulate_acquisition(const CandidateSet &set, SimStrategy strategy, const SimSettings &s) {
  if (s.start >= set.size())
    throw InputError("Start photo " + std::to_string(s.start) + " does not exist: there are " +
                     std::to_string(set.size()) + " candidate photos.");
  SimRun run;
  run.strategy = strategy;
  run.start = s.start;
  CoverageState state(set);
  run.target_diffuse = state.target_d_, run.target_specular = state.target_s_;
  std::vector<uint8_t> taken(set.size(), 0);
  std::vector<size_t> random_order;
  if (strategy == SimStrategy::Random) {
    for (size_t c = 0; c < set.size(); ++c)
      if (c != s.start) random_order.push_back(c);
    std::mt19937 rng(s.seed);
    std::shuffle(random_order.begin(), random_order.end(), rng);
  }
  std::vector<float> needs;
  float suggested[3] = {0, 0, 0};
  bool answered = false, suggested_diffuse = false;  // the photo answers a suggestion (of that kind)
  size_t next = s.start;
  while (next < set.size()) {
    taken[next] = 1;
    run.order.push_back(next);
    state.take(next, answered ? suggested : nullptr, suggested_diffuse, s.suggest);
    record(run, state);
    if (run.photos_full) break;
    // Diffuse first, then specular; or both kinds at every step (Goal::Both).
    const bool both = s.goal == SimGoal::Both;
    const bool allow_d = state.left_d_ > 0, allow_s = state.left_s_ > 0 && (both || !allow_d);
    const bool brute = strategy == SimStrategy::BruteForce;
    const auto t = Clock::now();
    switch (strategy) {
    case SimStrategy::Binned:
    case SimStrategy::BruteForce:
      next = choose_by_suggestion(set, state, taken, allow_d, allow_s, brute, s, needs, suggested, suggested_diffuse, run);
      // The diffuse suggestion can run dry (the remaining targets need lights it cannot place):
      // go on with specular coverage, as the photographer would.
      if (next == set.size() && !allow_s && state.left_s_ > 0)
        next = choose_by_suggestion(set, state, taken, false, true, brute, s, needs, suggested, suggested_diffuse, run);
      answered = next < set.size();
      break;
    case SimStrategy::Predicted:
      next = choose_by_prediction(set, state, taken, allow_d, allow_s, s);
      if (next == set.size() && !allow_s && state.left_s_ > 0) next = choose_by_prediction(set, state, taken, false, true, s);
      break;
    case SimStrategy::Oracle: next = choose_by_oracle(set, state, taken, allow_d, allow_s); break;
    case SimStrategy::Random:
      next = run.order.size() - 1 < random_order.size() ? random_order[run.order.size() - 1] : set.size();
      break;
    }
    const double dt = seconds_since(t);
    run.seconds += dt, run.seconds_max_choice = std::max(run.seconds_max_choice, dt), ++run.choices;
  }
  run.left_diffuse = state.left_d_, run.left_specular = state.left_s_;
  run.stalled = run.photos_full == 0;
  return run;
}

} // namespace vbrdf
