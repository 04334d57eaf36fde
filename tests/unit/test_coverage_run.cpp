// Acquisition feedback run (coverage_run.h): viewpoints, light lookup, needs, the whole run on a
// sample project, following a suggestion, photo import helpers; plus the geometry of the
// suggested lights (Algorithms 1 and 3) through the public API.
#include <cmath>
#include <fstream>
#include <gtest/gtest.h>
#include <sstream>
#include <random>
#include <unistd.h>

#include "tool_errors.h"
#include "run/coverage_run.h"
#include "run/coverage_outputs.h"
#include "base/errors.h"
#include "inputs/light_file.h"
#include "tools/mesh_io.h"
#include "run/fit_run.h"
#include "inputs/project.h"
#include "test_paths.h"
#include "test_scenes.h"
#include "thesis_settings.h"

using namespace vbrdf;

namespace {
const float kEye[3] = {0, 0, 10}, kTarget[3] = {0, 0, 0}, kUp[3] = {0, 1, 0};
Shot front_camera() { return test::make_look_at_shot(kEye, kTarget, kUp, 800, 640, 480); }

float dot3(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

std::string read_text(const std::string &path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

void write_text(const std::string &path, const std::string &text) { std::ofstream(path) << text; }

using test::error_of;

Raster raster_at(const std::string &label, const std::string &image, const Shot &shot) {
  Raster r;
  r.label = label;
  r.image_path = image;
  r.shot = shot;
  return r;
}

// synth_basic (read only): 4919 vertices, 16 photos of one viewpoint.
struct SampleProject {
  Project project = read_project(test::source_dir() + "/sample_projects/synth_basic/project.mlp");
  MeshData mesh = load_mesh_ply(project.mesh_path);
  CoverageInput input(std::vector<Raster> rasters) const {
    CoverageInput in;
    in.mesh = mesh.view();
    in.mesh_name = "synth_basic";
    in.rasters = rasters;
    in.project_path = project.project_path;
    return in;
  }
};

CoverageResult run_on(const CoverageInput &input, CoverageSettings s, const std::string &dir) {
  s.suggestion_file = dir + "/next_light.txt";
  auto vis = make_cpu_visibility(input.mesh, s.visibility);
  return run_coverage(input, s, *vis, {}, [](const std::string &) {});
}

size_t nearest_raster(const std::vector<Raster> &rasters, const std::vector<std::array<float, 3>> &lights,
                      const std::vector<size_t> &skip, const float dir[3]) {
  size_t best = 0;
  float best_cos = -2;
  for (size_t r = 0; r < rasters.size(); ++r) {
    if (std::find(skip.begin(), skip.end(), r) != skip.end()) continue;
    const float c = dot3(lights[r].data(), dir);
    if (c > best_cos) best_cos = c, best = r;
  }
  return best;
}
} // namespace

TEST(CoverageRun, ViewpointsGroupIdenticalShots) {
  const Shot a = front_camera();
  const float eye2[3] = {10, 0, 0};
  const Shot b = test::make_look_at_shot(eye2, kTarget, kUp, 800, 640, 480);
  const std::vector<Raster> rasters = {raster_at("a0", "a0.png", a), raster_at("b0", "b0.png", b),
                                       raster_at("a1", "a1.png", a), raster_at("b1", "b1.png", b)};
  const auto vps = group_viewpoints(rasters);
  ASSERT_EQ(vps.size(), 2u);
  EXPECT_EQ(vps[0].rasters, (std::vector<size_t>{0, 2}));
  EXPECT_EQ(vps[1].rasters, (std::vector<size_t>{1, 3}));
  EXPECT_EQ(viewpoint_of_raster(vps, 3), 1u);
  EXPECT_NE(error_of([&] { viewpoint_of_raster(vps, 4); }).find("Raster 4"), std::string::npos);
}

TEST(CoverageRun, NeedsFromCountsAndFitQuality) {
  const std::vector<CoverageCounts> counts = {{0, 0, 0}, {3, 0, 0}, {3, 2, 0}, {3, 2, 1}, {3, 2, 1}};
  CoverageSettings s = vbrdf::test::thesis_coverage_settings();
  CoverageNeeds n = coverage_needs(counts, nullptr, nullptr, s);
  EXPECT_EQ(n.diffuse, (std::vector<float>{0, 1, 0, 0, 0}));   // unseen: no light of this view helps
  EXPECT_EQ(n.specular, (std::vector<float>{0, 0, 1, 0, 0}));  // specular only once diffusely covered
  const std::vector<float> dq = {0, 0, 1.9f, 0.75f, 1.9f}, sq = {0, 0, 0, 1.9f, 0.3f};
  n = coverage_needs(counts, dq.data(), sq.data(), s);
  EXPECT_EQ(n.poor_diffuse, 1u);  // vertex 3: DQ 0.75 < 1.5
  EXPECT_NEAR(n.diffuse[3], 0.5f, 1e-6f);  // (1.5 - 0.75) / 1.5: poorer fits weigh more
  EXPECT_EQ(n.poor_specular, 1u);  // vertex 4: SQ 0.3
  EXPECT_NEAR(n.specular[4], 0.8f, 1e-6f);
  EXPECT_EQ(n.specular[2], 1.0f);  // uncovered weighs 1 whatever its quality
}

TEST(CoverageRun, LightLookupAllowsPhotosNotImportedYet) {
  const std::string dir = test::scratch_dir("cov_lp");
  const Shot shot = front_camera();
  write_text(dir + "/a.lp", "3\nimages/p0.png 0 0 1\nimages/p1.png 1 0 1\nimages/p2.png 0 1 1\n");
  const std::vector<Raster> rasters = {raster_at("p1", dir + "/images/p1.png", shot)};
  std::vector<std::string> unused;
  const auto dirs = lights_for_rasters(rasters, dir + "/a.lp", &unused);
  ASSERT_EQ(dirs.size(), 1u);
  EXPECT_NEAR(dirs[0][0], std::sqrt(0.5f), 1e-5f);  // the camera frame is the world frame here
  EXPECT_EQ(unused, (std::vector<std::string>{"images/p0.png", "images/p2.png"}));
  const std::vector<Raster> more = {raster_at("p9", dir + "/images/p9.png", shot)};
  const std::string msg = error_of([&] { lights_for_rasters(more, dir + "/a.lp"); });
  EXPECT_NE(msg.find("a.lp"), std::string::npos);
  EXPECT_NE(msg.find("'p9'"), std::string::npos);
}

TEST(LightFile, DefaultIsTheNewestCompleteOne) {
  const std::string dir = test::scratch_dir("cov_find");
  const Shot shot = front_camera();
  const std::vector<Raster> rasters = {raster_at("p0", dir + "/p0.png", shot), raster_at("p1", dir + "/p1.png", shot)};
  write_text(dir + "/old.lp", "2\np0.png 0 0 1\np1.png 0 1 1\n");
  write_text(dir + "/partial.lp", "1\np0.png 0 0 1\n");
  ::usleep(20000);
  write_text(dir + "/new.lp", "3\np0.png 0 0 1\np1.png 1 0 1\np2.png 0 1 1\n");
  std::vector<std::string> checked;
  EXPECT_EQ(find_default_light_file(rasters, dir + "/project.mlp", &checked), dir + "/new.lp");
  ::usleep(20000);  // file times are as coarse as the kernel's tick
  write_text(dir + "/partial.lp", "1\np0.png 0 0 1\n");  // now the newest, but incomplete
  checked.clear();
  EXPECT_EQ(find_default_light_file(rasters, dir + "/project.mlp", &checked), dir + "/new.lp");
  ASSERT_EQ(checked.size(), 1u);
  EXPECT_NE(checked[0].find("partial.lp"), std::string::npos);
  EXPECT_EQ(find_default_light_file({raster_at("x", dir + "/x.png", shot)}, dir + "/project.mlp"), "");
}

TEST(LightFile, EveryFilterPicksTheSameFileBesideAStaleLightsLp) {
  // An acquisition after an import: the first lights.lp (complete but superseded), the import's
  // newer <project>_lights.lp, and a still newer .lp that lacks a raster. The fit, coverage and the
  // shared rule agree on the newer complete file (not the alphabetically first, lights.lp). Relight, import and the tools call the same find_default_light_file.
  const SampleProject sample;
  const std::string dir = test::scratch_dir("lp_policy"), project = dir + "/project.mlp";
  const std::string lights = read_text(sample.project.project_path.substr(0, sample.project.project_path.rfind('/')) +
                                       "/lights.lp");
  write_text(dir + "/lights.lp", lights);
  ::usleep(20000);  // file times are as coarse as the kernel's tick
  write_text(dir + "/project_lights.lp", lights);
  ::usleep(20000);
  write_text(dir + "/partial.lp", "1\nimages/light_000.png 0 0 1\n");
  const std::string expected = dir + "/project_lights.lp";
  const std::vector<Raster> &rasters = sample.project.rasters;
  std::vector<std::string> checked;
  EXPECT_EQ(find_default_light_file(rasters, project, &checked), expected);
  ASSERT_EQ(checked.size(), 1u);
  EXPECT_NE(checked[0].find("partial.lp"), std::string::npos);

  CoverageInput cin = sample.input(rasters);
  cin.project_path = project;
  EXPECT_EQ(run_on(cin, vbrdf::test::thesis_coverage_settings(), dir).light_file, expected);

  FitInput fin;
  fin.mesh = sample.mesh.view();
  fin.mesh_name = "synth_basic";
  fin.rasters = rasters;
  fin.project_path = project;
  FitSettings fs;
  fs.fit_reflectance = false;
  fs.output_ply = dir + "/fit.ply";
  auto vis = make_cpu_visibility(fin.mesh, fs.visibility);
  const FitResult fit = run_fit(fin, fs, *vis, nullptr, {}, [](const std::string &) {});
  EXPECT_EQ(fit.light_file, expected);
}

TEST(CoverageRun, NewPhotosAndMergedLights) {
  const std::string dir = test::scratch_dir("cov_new");
  for (const char *name : {"b.png", "a.JPG", "c.tif", "notes.txt", "d.png"}) write_text(dir + "/" + name, "x");
  const std::vector<Raster> rasters = {raster_at("d", dir + "/d.png", front_camera())};
  EXPECT_EQ(new_photos_in_folder(dir, rasters),
            (std::vector<std::string>{dir + "/a.JPG", dir + "/b.png", dir + "/c.tif"}));
  EXPECT_NE(error_of([&] { new_photos_in_folder(dir + "/missing", rasters); }).find("missing"), std::string::npos);

  const std::vector<LightEntry> existing = {{"images/a.png", {0, 0, 1}}, {"images/b.png", {0, 1, 0}}};
  const std::vector<LightEntry> added = {{"images/b.png", {1, 0, 0}}, {"images/c.png", {0, 0, 1}}};
  const auto merged = merge_light_entries(existing, added);
  ASSERT_EQ(merged.size(), 3u);
  EXPECT_EQ(merged[0].image, "images/a.png");
  EXPECT_EQ(merged[1].image, "images/b.png");
  EXPECT_EQ(merged[1].dir_cam[0], 1.0f);  // the new estimate replaces the old entry
}

TEST(CoverageRun, WholeRunOnTheSampleProject) {
  const SampleProject p;
  const std::string dir = test::scratch_dir("cov_run");
  const CoverageResult r = run_on(p.input(p.project.rasters), vbrdf::test::thesis_coverage_settings(), dir);
  const size_t n = p.mesh.positions.size() / 3;
  size_t total = 0, unseen = 0;
  for (size_t c : r.class_counts) total += c;
  for (const CoverageCounts &c : r.counts) unseen += c.seen == 0;
  EXPECT_EQ(total, n);
  EXPECT_EQ(r.class_counts[kUnseen], unseen);
  EXPECT_GT(r.class_counts[kDiffuseNoSpecular] + r.class_counts[kFullyCovered], n / 3);  // 16 lights: much is covered
  EXPECT_GT(r.class_counts[kFullyCovered], 0u);
  EXPECT_EQ(r.viewpoints.size(), 1u);
  EXPECT_EQ(r.viewpoint, 0u);
  for (const LightSuggestion *s : {&r.diffuse, &r.specular})
    if (s->valid) {
      EXPECT_TRUE(light_is_placeable(r.viewpoints[0].shot, s->dir_world, 5.0f));
      EXPECT_LE(s->covered_vertices, s->needing_vertices);
      EXPECT_GT(s->covered_vertices, 0u);
    }
  // Files: key: value lines agree with the result; the vertex list has one line per vertex.
  const std::string text = read_text(r.suggestion_file);
  EXPECT_EQ(suggestion_value(text, "vertices"), std::to_string(n));
  EXPECT_EQ(suggestion_value(text, "unseen"), std::to_string(r.class_counts[kUnseen]));
  EXPECT_EQ(suggestion_value(text, "fully_covered"), std::to_string(r.class_counts[kFullyCovered]));
  EXPECT_EQ(suggestion_value(text, "diffuse_valid"), r.diffuse.valid ? "1" : "0");
  EXPECT_EQ(suggestion_value(text, "new_view_vertices"), std::to_string(r.new_view_vertices.size()));
  std::ifstream list(r.vertex_list_file);
  size_t lines = 0;
  for (std::string line; std::getline(list, line);) lines += !line.empty() && line[0] != '#';
  EXPECT_EQ(lines, r.new_view_vertices.size());
  EXPECT_GE(r.new_view_vertices.size(), r.class_counts[kUnseen]);  // every unseen vertex is listed
  std::printf("classes: unseen %zu, no diffuse %zu, no specular %zu, full %zu; new view %zu; times %.2f/%.2f/%.3f s\n",
              r.class_counts[0], r.class_counts[1], r.class_counts[2], r.class_counts[3], r.new_view_vertices.size(),
              r.seconds_visibility, r.seconds_gather, r.seconds_suggest);
}

TEST(CoverageRun, FollowingTheDiffuseSuggestionCoversWhatItPredicts) {
  const SampleProject p;
  const auto lights = lights_for_rasters(p.project.rasters, p.project.project_path.substr(0, p.project.project_path.rfind('/')) + "/lights.lp");
  const std::string dir = test::scratch_dir("cov_follow");
  std::vector<size_t> taken = {0};
  std::vector<Raster> rasters = {p.project.rasters[0]};
  const CoverageResult one = run_on(p.input(rasters), vbrdf::test::thesis_coverage_settings(), dir);  // a single photo works
  ASSERT_TRUE(one.diffuse.valid);
  const size_t next = nearest_raster(p.project.rasters, lights, taken, one.diffuse.dir_world);
  rasters.push_back(p.project.rasters[next]);
  const CoverageResult two = run_on(p.input(rasters), vbrdf::test::thesis_coverage_settings(), dir);
  const size_t before = one.class_counts[kSeenNotDiffuse], after = two.class_counts[kSeenNotDiffuse];
  std::printf("seen but not diffusely covered: %zu -> %zu after raster %zu (suggestion covers %zu, light %.1f deg away)\n",
              before, after, next, one.diffuse.covered_vertices,
              std::acos(std::min(1.0f, dot3(lights[next].data(), one.diffuse.dir_world))) * 57.2958f);
  EXPECT_LT(after, before);
  EXPECT_GE(double(before - after), 0.3 * double(one.diffuse.covered_vertices));  // only the nearest photo, not the exact light
}

TEST(CoverageRun, PoorFitsAskForSamples) {
  const SampleProject p;
  const std::string dir = test::scratch_dir("cov_quality");
  CoverageInput input = p.input(p.project.rasters);
  const size_t n = input.mesh.vertex_count;
  input.dq.assign(n, 0.2f);
  input.sq.assign(n, 2.0f);
  const CoverageResult r = run_on(input, vbrdf::test::thesis_coverage_settings(), dir);
  EXPECT_EQ(r.poor_diffuse, r.class_counts[kDiffuseNoSpecular] + r.class_counts[kFullyCovered]);
  EXPECT_EQ(r.poor_specular, 0u);
  EXPECT_TRUE(r.diffuse.valid);  // covered but poorly fitted vertices still get a diffuse light
  input.dq.resize(n - 1);
  EXPECT_NE(error_of([&] { run_on(input, vbrdf::test::thesis_coverage_settings(), dir); }).find("vertices"), std::string::npos);
}

TEST(CoverageRun, BadInputIsNamed) {
  const SampleProject p;
  const std::string dir = test::scratch_dir("cov_bad");
  CoverageSettings s = vbrdf::test::thesis_coverage_settings();
  s.viewpoint_raster = 16;
  EXPECT_NE(error_of([&] { run_on(p.input(p.project.rasters), s, dir); }).find("Viewpoint raster 16"), std::string::npos);
  s = vbrdf::test::thesis_coverage_settings();
  write_text(dir + "/short.lp", "1\nimages/light_000.png 0 0 1\n");
  s.light_file = dir + "/short.lp";
  const std::string msg = error_of([&] { run_on(p.input(p.project.rasters), s, dir); });
  EXPECT_NE(msg.find("short.lp"), std::string::npos);
  EXPECT_NE(msg.find("light_001.png"), std::string::npos);
  EXPECT_NE(error_of([&] { run_on(p.input({}), vbrdf::test::thesis_coverage_settings(), dir); }).find("no rasters"), std::string::npos);
}

// Algorithm 3 geometry: the specular light is the eye mirrored about the normal when that is
// placeable; otherwise it is moved towards the camera until placeable, still giving R.E > T_s.
TEST(CoverageGeometry, SpecularLightIsTheMirrorOrItsPlaceableRotation) {
  const Shot shot = front_camera();
  LightSuggestionSettings s;
  const float e[3] = {0, 0, 1};
  const float n_small[3] = {0.2f, 0, 0.9797959f};  // mirror at ~23 deg from the camera axis: placeable
  float l[3];
  ASSERT_TRUE(ideal_specular_light(n_small, e, shot, s, l));
  const float d = dot3(n_small, e);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(l[k], 2 * d * n_small[k] - e[k], 1e-5f);
  const float n_big[3] = {0.7f, 0, 0.71414284f};  // mirror at ~91 deg: behind the image plane
  ASSERT_TRUE(ideal_specular_light(n_big, e, shot, s, l));
  EXPECT_GE(l[2], std::sin(s.min_elevation_deg * 3.14159265f / 180) - 1e-5f);  // never below the horizon
  EXPECT_NEAR(l[1], 0.0f, 1e-5f);  // rotated within the plane of the mirror and the camera axis
  EXPECT_TRUE(light_covers_specular(n_big, e, l, s));
  const float n_grazing[3] = {0.95f, 0, 0.31224990f};  // needs a light far behind the object: refused
  EXPECT_FALSE(ideal_specular_light(n_grazing, e, shot, s, l));
}

// Sphere lights of the import filter on a scene with a mirror sphere (shared, read only).
TEST(CoverageRun, SphereLightsOfNewPhotosMatchTheLightFile) {
  VBRDF_REQUIRE_SHARED("scenes/spot_dir24/project.mlp");
  const std::string scene = test::shared_dir() + "/scenes/spot_dir24";
  const Project p = read_project(scene + "/project.mlp");
  const std::vector<LightEntry> truth = read_light_file(scene + "/lights.lp");
  std::vector<std::string> photos;
  for (const Raster &r : p.rasters) photos.push_back(r.image_path);
  const std::vector<size_t> wanted = {3, 11, 20};
  const auto entries = sphere_light_entries(photos, wanted, p.rasters[0].shot, SphereCircle(), scene,
                                            [](const std::string &) {});
  ASSERT_EQ(entries.size(), wanted.size());
  for (size_t i = 0; i < wanted.size(); ++i) {
    EXPECT_EQ(entries[i].image, "images/" + p.rasters[wanted[i]].image_path.substr(p.rasters[wanted[i]].image_path.rfind('/') + 1));
    const int t = find_light_for_image(truth, photos[wanted[i]]);
    ASSERT_GE(t, 0);
    const float angle = std::acos(std::min(1.0f, dot3(entries[i].dir_cam, truth[size_t(t)].dir_cam))) * 57.2958f;
    std::printf("%s: sphere light %.2f deg from lights.lp\n", entries[i].image.c_str(), angle);
    EXPECT_LT(angle, 2.0f);
  }
}

// The new-viewpoint test takes shortcuts (the normal, the mirror, a reach bound) before Algorithm
// 1/3's search: it must agree with the search.
TEST(CoverageGeometry, NewViewReasonsAgreeWithTheIdealLightSearch) {
  const Shot shot = front_camera();
  const LightSuggestionSettings s;
  std::mt19937 rng(11);
  std::normal_distribution<float> g(0, 1);
  MeshData mesh;
  std::vector<uint8_t> classes;
  for (int i = 0; i < 4000; ++i) {
    float n[3] = {g(rng), g(rng), std::fabs(g(rng)) + 0.2f};
    const float l = std::sqrt(dot3(n, n));
    for (float &c : n) c /= l;
    mesh.positions.insert(mesh.positions.end(), {0.3f * g(rng), 0.3f * g(rng), 0.3f * g(rng)});
    mesh.normals.insert(mesh.normals.end(), {n[0], n[1], n[2]});
    classes.push_back(i % 2 ? kSeenNotDiffuse : kDiffuseNoSpecular);
  }
  Viewpoint vp;
  vp.shot = shot;
  vp.rasters = {0};
  const std::vector<uint8_t> visible(classes.size(), 1);
  const auto reasons = new_view_reasons(mesh.view(), classes, {visible}, {vp}, s);
  float centre[3];
  camera_centre(shot, centre);
  size_t disagree = 0, uncoverable = 0;
  for (size_t v = 0; v < classes.size(); ++v) {
    const float *p = &mesh.positions[3 * v], *n = &mesh.normals[3 * v];
    float e[3] = {centre[0] - p[0], centre[1] - p[1], centre[2] - p[2]}, l[3];
    const float len = std::sqrt(dot3(e, e));
    for (float &c : e) c /= len;
    const bool ok = classes[v] == kSeenNotDiffuse ? ideal_diffuse_light(n, e, shot, s, l) : ideal_specular_light(n, e, shot, s, l);
    disagree += ok != (reasons[v] == 0);
    uncoverable += !ok;
  }
  std::printf("uncoverable by the search: %zu of %zu; disagreements: %zu\n", uncoverable, classes.size(), disagree);
  EXPECT_GT(uncoverable, 100u);
  EXPECT_LE(disagree, classes.size() / 200);  // boundary cases of the search's 2-degree steps only
}
