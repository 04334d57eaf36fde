// Table 4.1 simulation (acquisition_sim.h): constructed candidate sets with known answers, the
// greedy choices, random order, stalling, and candidates gathered from a sample project.
#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>

#include "tools/acquisition_sim.h"
#include "run/coverage_run.h"
#include "base/errors.h"
#include "tools/mesh_io.h"
#include "inputs/project.h"
#include "test_paths.h"
#include "test_scenes.h"
#include "thesis_settings.h"

using namespace vbrdf;

namespace {
const float kEye[3] = {0, 0, 10}, kTarget[3] = {0, 0, 0}, kUp[3] = {0, 1, 0};

// Patches of vertices near the origin, one normal each, seen by a camera on +z.
MeshData patches(const std::vector<std::array<float, 3>> &normals, const std::vector<int> &counts) {
  MeshData m;
  for (size_t p = 0; p < normals.size(); ++p)
    for (int i = 0; i < counts[p]; ++i) {
      m.positions.insert(m.positions.end(), {0.5f * float(p) - 0.5f + 0.002f * float(i % 10), 0.002f * float(i / 10), 0});
      const float *n = normals[p].data();
      const float l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      m.normals.insert(m.normals.end(), {n[0] / l, n[1] / l, n[2] / l});
    }
  return m;
}

// Candidate lights on a spiral over the camera-facing hemisphere (camera frame = world frame).
std::vector<std::array<float, 3>> spiral_lights(int count, float min_elev_deg, float max_elev_deg) {
  std::vector<std::array<float, 3>> out;
  for (int i = 0; i < count; ++i) {
    const float t = (float(i) + 0.5f) / float(count);
    const float elev = (min_elev_deg + t * (max_elev_deg - min_elev_deg)) * 3.14159265f / 180;
    const float az = float(i) * 2.39996323f;  // golden angle
    out.push_back({{std::cos(elev) * std::cos(az), std::cos(elev) * std::sin(az), std::sin(elev)}});
  }
  return out;
}

// Candidates whose measured coverage is exactly what the geometry predicts (no shadows).
CandidateSet geometric_set(const MeshData &mesh, const Shot &shot, const std::vector<std::array<float, 3>> &lights) {
  CandidateSet set;
  set.mesh = mesh.view();
  set.shot = shot;
  const size_t n = set.mesh.vertex_count;
  set.visible.assign(n, 1);
  set.lights_world = lights;
  set.names.assign(lights.size(), "c");
  set.words = (n + 63) / 64;
  set.diffuse.assign(set.words * lights.size(), 0);
  set.specular.assign(set.words * lights.size(), 0);
  float centre[3];
  camera_centre(shot, centre);
  const LightSuggestionSettings s;
  for (size_t c = 0; c < lights.size(); ++c)
    for (size_t v = 0; v < n; ++v) {
      const float *p = &mesh.positions[3 * v], *nrm = &mesh.normals[3 * v];
      float e[3] = {centre[0] - p[0], centre[1] - p[1], centre[2] - p[2]};
      const float l = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
      for (float &x : e) x /= l;
      const uint64_t bit = uint64_t(1) << (v % 64);
      if (light_covers_diffuse(nrm, e, lights[c].data(), s)) set.diffuse[c * set.words + v / 64] |= bit;
      if (light_covers_specular(nrm, e, lights[c].data(), s)) set.specular[c * set.words + v / 64] |= bit;
    }
  return set;
}

size_t most_frontal(const CandidateSet &set) {
  size_t best = 0;
  for (size_t c = 0; c < set.size(); ++c)
    if (set.lights_world[c][2] > set.lights_world[best][2]) best = c;
  return best;
}
} // namespace

TEST(AcquisitionSim, OracleTakesTheLargestMeasuredGainFirst) {
  // 15 vertices; A covers 0..11, B 0..4, C 10..14 (diffuse); nothing specular.
  const MeshData mesh = patches({{{0, 0, 1}}}, {15});
  CandidateSet set;
  set.mesh = mesh.view();
  set.shot = test::make_look_at_shot(kEye, kTarget, kUp, 800, 640, 480);
  set.visible.assign(15, 1);
  set.lights_world = {{{0, 0, 1}}, {{0, 0.6f, 0.8f}}, {{0.6f, 0, 0.8f}}};
  set.names = {"A", "B", "C"};
  set.words = 1;
  set.diffuse = {0xFFFu, 0x1Fu, 0x7C00u};
  set.specular = {0, 0, 0};
  SimSettings s;
  s.start = 1;  // B
  const SimRun run = simulate_acquisition(set, SimStrategy::Oracle, s);
  EXPECT_EQ(run.order, (std::vector<size_t>{1, 0, 2}));  // A adds 7, C only 5
  EXPECT_EQ(run.target_diffuse, 15u);
  EXPECT_EQ(run.target_specular, 0u);
  EXPECT_EQ(run.photos_diffuse, 3u);
  EXPECT_EQ(run.photos_full, 3u);
  EXPECT_EQ(run.uncovered, (std::vector<size_t>{10, 3, 0}));
  EXPECT_FALSE(run.stalled);
  s.start = 0;  // A then C: two photos
  EXPECT_EQ(simulate_acquisition(set, SimStrategy::Oracle, s).photos_full, 2u);
  s.start = 3;
  EXPECT_THROW(simulate_acquisition(set, SimStrategy::Oracle, s), InputError);
}

TEST(AcquisitionSim, NearestCandidateSkipsTakenOnes) {
  CandidateSet set;
  set.lights_world = {{{0, 0, 1}}, {{0, 0.6f, 0.8f}}, {{0.6f, 0, 0.8f}}};
  const float dir[3] = {0.1f, 0.5f, 0.86f};
  EXPECT_EQ(nearest_candidate(set, {0, 0, 0}, dir), 1u);
  EXPECT_EQ(nearest_candidate(set, {0, 1, 0}, dir), 0u);
  EXPECT_EQ(nearest_candidate(set, {1, 1, 1}, dir), 3u);
}

TEST(AcquisitionSim, FollowingSuggestionsNeedsOnePhotoPerHighlightDirection) {
  // Three patches tilted left, up and right by 37 degrees: a frontal light covers all of them
  // diffusely; each needs its own specular light (mirrors 85+ degrees apart). Known answer:
  // start frontal, then 3 photos = 4, for the binned and exact suggestions and the oracle.
  const Shot shot = test::make_look_at_shot(kEye, kTarget, kUp, 800, 640, 480);
  const MeshData mesh = patches({{{-0.6f, 0, 0.8f}}, {{0, 0.6f, 0.8f}}, {{0.6f, 0, 0.8f}}}, {200, 100, 50});
  const CandidateSet set = geometric_set(mesh, shot, spiral_lights(150, 10, 88));
  SimSettings s;
  s.start = most_frontal(set);
  for (SimStrategy strategy : {SimStrategy::Binned, SimStrategy::BruteForce, SimStrategy::Oracle}) {
    const SimRun run = simulate_acquisition(set, strategy, s);
    EXPECT_EQ(run.target_diffuse, 350u);
    EXPECT_EQ(run.target_specular, 350u);
    EXPECT_EQ(run.photos_diffuse, 1u) << sim_strategy_name(strategy);
    EXPECT_EQ(run.photos_full, 4u) << sim_strategy_name(strategy);
    EXPECT_FALSE(run.stalled);
    EXPECT_EQ(run.uncovered.back(), 0u);
  }
  // The greedy order: the largest patch's highlight first (200 vertices, tilted left).
  const SimRun binned = simulate_acquisition(set, SimStrategy::Binned, s);
  EXPECT_LT(set.lights_world[binned.order[1]][0], -0.5f);
  // Random order needs at least as many photos, and reaches full coverage (all candidates).
  size_t random_total = 0;
  for (uint32_t seed = 1; seed <= 10; ++seed) {
    s.seed = seed;
    const SimRun r = simulate_acquisition(set, SimStrategy::Random, s);
    ASSERT_GT(r.photos_full, 0u);
    EXPECT_GE(r.photos_full, 4u);
    random_total += r.photos_full;
  }
  std::printf("random order: %.1f photos on average (suggestions: 4)\n", double(random_total) / 10);
  EXPECT_GT(random_total, 10u * 4u);
}

TEST(AcquisitionSim, StallsWhenNoSuggestionCanReachTheRest) {
  // Vertex 0 is measured as covered by candidate 2 only, but the viewpoint does not see it
  // cleanly (e.g. a mixed pixel): no suggestion targets it, so the suggestion strategies stop
  // after covering the rest (start: frontal light = highlights; candidate 1: the diffuse rest).
  const Shot shot = test::make_look_at_shot(kEye, kTarget, kUp, 800, 640, 480);
  const MeshData mesh = patches({{{0, 0, 1}}}, {10});
  CandidateSet set = geometric_set(mesh, shot, {{{0, 0, 1}}, {{0.6f, 0, 0.8f}}, {{0, -0.6f, 0.8f}}});
  for (size_t c = 0; c < 3; ++c) set.diffuse[c * set.words] &= ~uint64_t(1), set.specular[c * set.words] &= ~uint64_t(1);
  set.diffuse[2 * set.words] |= 1;
  set.visible[0] = 0;
  SimSettings s;
  s.start = 0;
  const SimRun run = simulate_acquisition(set, SimStrategy::Binned, s);
  EXPECT_EQ(run.order, (std::vector<size_t>{0, 1}));
  EXPECT_TRUE(run.stalled);
  EXPECT_EQ(run.left_diffuse, 1u);
  EXPECT_EQ(run.photos_full, 0u);
  // Measured coverage finds it: candidate 2 covers the diffuse rest too, so 2 photos.
  EXPECT_EQ(simulate_acquisition(set, SimStrategy::Oracle, s).order, (std::vector<size_t>{0, 2}));
}

namespace {

// Replays `run.order` on the candidate set from scratch and checks what the simulation reported:
// the targets (vertices some candidate covers diffusely; of those, the ones some candidate covers
// specularly), the uncovered targets after each photo, when diffuse and full coverage were
// reached, and what was left. Also: the start photo first, no candidate taken twice.
void expect_run_replays(const CandidateSet &set, const SimRun &run, size_t start) {
  const size_t n = set.mesh.vertex_count;
  ASSERT_FALSE(run.order.empty());
  EXPECT_EQ(run.order.front(), start);
  std::vector<bool> target_d(n, false), target_s(n, false);
  for (size_t v = 0; v < n; ++v) {
    bool any_s = false;
    for (size_t c = 0; c < set.size(); ++c) {
      target_d[v] = target_d[v] || set.covers_diffuse(c, v);
      any_s = any_s || set.covers_specular(c, v);
    }
    target_s[v] = target_d[v] && any_s;
  }
  EXPECT_EQ(run.target_diffuse, size_t(std::count(target_d.begin(), target_d.end(), true)));
  EXPECT_EQ(run.target_specular, size_t(std::count(target_s.begin(), target_s.end(), true)));
  ASSERT_EQ(run.uncovered.size(), run.order.size());
  std::vector<bool> has_d(n, false), has_s(n, false), taken(set.size(), false);
  size_t reached_d = 0, reached_full = 0, left_d = 0, left_s = 0;
  for (size_t k = 0; k < run.order.size(); ++k) {
    const size_t c = run.order[k];
    ASSERT_LT(c, set.size());
    EXPECT_FALSE(taken[c]) << "candidate " << c << " taken twice";
    taken[c] = true;
    left_d = left_s = 0;
    for (size_t v = 0; v < n; ++v) {
      has_d[v] = has_d[v] || set.covers_diffuse(c, v);
      has_s[v] = has_s[v] || set.covers_specular(c, v);
      left_d += target_d[v] && !has_d[v];
      left_s += target_s[v] && !has_s[v];
    }
    EXPECT_EQ(run.uncovered[k], left_d + left_s) << "after photo " << k + 1;
    if (reached_d == 0 && left_d == 0) reached_d = k + 1;
    if (reached_full == 0 && left_d == 0 && left_s == 0) reached_full = k + 1;
  }
  EXPECT_EQ(run.photos_diffuse, reached_d);
  EXPECT_EQ(run.photos_full, reached_full);
  EXPECT_EQ(run.left_diffuse, left_d);
  EXPECT_EQ(run.left_specular, left_s);
}

} // namespace

TEST(AcquisitionSim, GatheredCandidatesMatchTheCoverageCounts) {
  const Project p = read_project(test::source_dir() + "/sample_projects/synth_basic/project.mlp");
  const MeshData mesh = load_mesh_ply(p.mesh_path);
  const auto lights = lights_for_rasters(p.rasters, find_default_light_file(p.rasters, p.project_path));
  auto vis = make_cpu_visibility(mesh.view(), VisibilitySettings());
  const CandidateSet set = gather_candidates(mesh.view(), p.rasters, lights, *vis, vbrdf::test::thesis_gather_settings());
  ASSERT_EQ(set.size(), 16u);
  CoverageInput input;
  input.mesh = mesh.view();
  input.rasters = p.rasters;
  input.project_path = p.project_path;
  CoverageSettings cs;
  cs.write_files = false;
  const CoverageResult r = run_coverage(input, cs, *vis, {}, [](const std::string &) {});
  size_t mismatches = 0;
  for (size_t v = 0; v < input.mesh.vertex_count; ++v) {
    size_t d = 0, sp = 0;
    for (size_t c = 0; c < set.size(); ++c) d += set.covers_diffuse(c, v), sp += set.covers_specular(c, v);
    mismatches += d != r.counts[v].diffuse || sp != r.counts[v].specular;
  }
  EXPECT_EQ(mismatches, 0u);
  // From the first photo, following the suggestions reaches everything the 16 photos cover.
  SimSettings s;
  const SimRun oracle = simulate_acquisition(set, SimStrategy::Oracle, s);
  const SimRun binned = simulate_acquisition(set, SimStrategy::Binned, s);
  std::printf("synth_basic, 16 candidates: targets %zu diffuse / %zu specular; photos binned %zu (left %zu), oracle %zu\n",
              binned.target_diffuse, binned.target_specular, binned.photos_full, binned.left_diffuse + binned.left_specular,
              oracle.photos_full);
  EXPECT_GT(oracle.photos_full, 0u);
  EXPECT_LE(oracle.photos_full, 16u);
  expect_run_replays(set, binned, s.start);
  expect_run_replays(set, oracle, s.start);
  // The binned suggestions reach full coverage within the 16 candidates, never more photos than
  // candidates, and diffuse coverage no later than full coverage.
  EXPECT_FALSE(binned.stalled);
  EXPECT_GT(binned.photos_full, 0u);
  EXPECT_LE(binned.photos_full, set.size());
  EXPECT_EQ(binned.left_diffuse + binned.left_specular, 0u);
  EXPECT_GT(binned.photos_diffuse, 0u);
  EXPECT_LE(binned.photos_diffuse, binned.photos_full);
  // Every decision after the start photo is a suggestion with its prediction and offset.
  EXPECT_EQ(binned.predicted.size(), binned.order.size() - 1);
  EXPECT_EQ(binned.gained.size(), binned.order.size() - 1);
  EXPECT_EQ(binned.offset_deg.size(), binned.order.size() - 1);
  for (float off : binned.offset_deg) EXPECT_TRUE(off >= 0.0f && off <= 180.0f) << off;
  // Candidates of two viewpoints are refused with the culprit named.
  const Project two = read_project(test::source_dir() + "/sample_projects/synth_two_views/project.mlp");
  const MeshData mesh2 = load_mesh_ply(two.mesh_path);
  auto vis2 = make_cpu_visibility(mesh2.view(), VisibilitySettings());
  const auto lights2 = lights_for_rasters(two.rasters, find_default_light_file(two.rasters, two.project_path));
  try {
    gather_candidates(mesh2.view(), two.rasters, lights2, *vis2, vbrdf::test::thesis_gather_settings());
    ADD_FAILURE() << "two viewpoints accepted";
  } catch (const InputError &e) {
    EXPECT_NE(std::string(e.what()).find("one viewpoint"), std::string::npos);
  }
}
