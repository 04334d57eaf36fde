// The material stage (materials.h): a synthetic object of two materials, a glossy half (one
// Phong lobe) and a diffuse half, both under the same textured albedo; every vertex sees each
// lobe at most once or twice, so per-vertex fits cannot pin it, the pooled samples can.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <algorithm>
#include <random>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "fit/materials.h"
#include "test_scenes.h"
#include "thesis_settings.h"

using namespace vbrdf;

namespace {

struct Scene {
  MeshData mesh;
  SampleChunk chunk;
  std::vector<int> truth;  // 1 glossy, 2 diffuse
};

// A (grid + 1) x (grid + 1) grid whose normals fan out over +-40 degrees (a cap), 16 lights, camera along +z.
// Vertices with x < 0 are glossy when `two_materials`, else every vertex is glossy.
// The true lobe is ks * g(cos, alpha) of `form` (cos^alpha on R.E or N.H, or GGX on N.H;
// lobe_value), the cosine as Sample::lobe_cos.
Scene make_scene(bool two_materials, float ks, float alpha, unsigned seed, LobeForm form = LobeForm::PhongRE, int grid = 30) {
  Scene sc;
  sc.mesh = test::make_grid(grid, 1.0f, 0.0f);
  const size_t n = sc.mesh.positions.size() / 3;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  std::normal_distribution<float> gauss(0, 1);
  std::vector<std::array<float, 3>> lights;
  for (int i = 0; i < 16; ++i) {
    const float z = 0.35f + 0.6f * float(i % 4) / 3.0f, phi = 2.39996f * float(i);
    const float r = std::sqrt(1 - z * z);
    lights.push_back({{r * std::cos(phi), r * std::sin(phi), z}});
  }
  sc.chunk.first_vertex = 0;
  sc.chunk.vertex_count = uint32_t(n);
  sc.chunk.offsets.push_back(0);
  for (size_t v = 0; v < n; ++v) {
    const float x = sc.mesh.positions[3 * v], y = sc.mesh.positions[3 * v + 2];
    float N[3] = {0.8f * x, 0.8f * y, 1.0f};
    const float len = std::sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
    for (float &c : N) c /= len;
    const bool glossy = !two_materials || x < 0;
    sc.truth.push_back(glossy ? 1 : 2);
    const float rho[3] = {0.2f + 0.5f * u(rng), 0.2f + 0.5f * u(rng), 0.2f + 0.5f * u(rng)};  // texture
    for (size_t l = 0; l < lights.size(); ++l) {
      const float *L = lights[l].data();
      const float d = N[0] * L[0] + N[1] * L[1] + N[2] * L[2];
      const float E[3] = {0, 0, 1};
      const float re = lobe_cosine(LobeForm::PhongRE, N, L, E), s = lobe_cosine(form, N, L, E);
      Sample smp{};
      smp.d = d, smp.lobe_cos = s, smp.raster = uint16_t(l);
      const float g = glossy && s > 0 && d > 0 ? ks * float(lobe_value(form, s, alpha)) : 0.0f;
      for (int c = 0; c < 3; ++c) smp.rgb[c] = std::max(0.0f, (rho[c] * std::max(d, 0.0f) + g) * (1 + 0.01f * gauss(rng)));
      smp.flags = uint16_t((d <= 0 ? kAttachedShadow : 0) | (d > 0 && d < 0.2f ? kGrazing : 0) | (re > 0.9f ? kHighlight : 0));
      sc.chunk.samples.push_back(smp);
    }
    sc.chunk.offsets.push_back(uint32_t(sc.chunk.samples.size()));
  }
  return sc;
}

struct StageRun {
  MaterialResult result;
  std::vector<VertexFit> before, after;
};

StageRun run_stage(const Scene &sc, const MaterialOptions &mo = MaterialOptions(), LobeForm form = LobeForm::PhongRE) {
  ReflectanceFitOptions o = vbrdf::test::thesis_fit_options();
  o.lobe = form;
  StageRun r;
  r.before.resize(sc.chunk.vertex_count);
  fit_chunk_cpu(sc.chunk, o, r.before.data());
  r.after = r.before;
  MaterialSampleStore store(sc.chunk.vertex_count);
  store.add_chunk(sc.chunk, r.before.data(), o);
  r.result = fit_materials(sc.mesh.view(), store, o, mo, nullptr, nullptr, r.after);
  return r;
}

// For a stage run that found two materials: which is the glossy one (the one holding most truly
// glossy vertices; returned, 1 or 2). Expects >= 95 % of the vertices labelled as the truth says,
// the other material diffuse, and the glossy lobe's k_s and alpha within 10 %.
int expect_two_materials_found(const Scene &sc, const StageRun &r, float ks, float alpha) {
  size_t agree[3][3] = {};
  for (size_t v = 0; v < sc.truth.size(); ++v) {
    const int32_t label = r.result.label[v];
    ++agree[sc.truth[v]][label >= 1 && label <= 2 ? size_t(label) : 0];
  }
  const int glossy = agree[1][1] >= agree[1][2] ? 1 : 2, diffuse = 3 - glossy;
  const double correct = double(agree[1][size_t(glossy)] + agree[2][size_t(diffuse)]) / double(sc.truth.size());
  EXPECT_GE(correct, 0.95) << r.result.report;
  const Material &g = r.result.materials[size_t(glossy) - 1], &d = r.result.materials[size_t(diffuse) - 1];
  EXPECT_FALSE(g.diffuse);
  EXPECT_TRUE(d.diffuse) << r.result.report;
  EXPECT_NEAR(g.shininess, alpha, 0.1 * alpha) << r.result.report;
  EXPECT_NEAR(g.ks, ks, 0.1 * ks) << r.result.report;
  return glossy;
}

} // namespace


class MaterialsBothLobes : public ::testing::TestWithParam<LobeForm> {};

// Materials, their lobes (k_s, alpha in the form fitted) and every vertex's lobe weight (k_s, its
// blend between the material's lobe and its own data) recovered, in either lobe form.
TEST_P(MaterialsBothLobes, TwoMaterialsAndTheirLobesAreRecovered) {
  const LobeForm form = GetParam();
  const float ks = 0.5f, alpha = form != LobeForm::PhongRE ? 120.0f : 30.0f;
  const Scene sc = make_scene(true, ks, alpha, 7, form);
  MaterialOptions everywhere;
  everywhere.keep_full_fits = false;  // every glossy vertex takes the material-regularised lobe
  const StageRun r = run_stage(sc, everywhere, form);
  ASSERT_EQ(r.result.chosen_k, 2) << r.result.report;
  ASSERT_EQ(r.result.materials.size(), 2u);
  const int glossy = expect_two_materials_found(sc, r, ks, alpha);
  const Material &g = r.result.materials[size_t(glossy) - 1];
  // Every vertex of the glossy material has a lobe, every one of the diffuse material none; the
  // per-vertex fit alone left many glossy vertices without one.
  size_t glossy_n = 0, glossy_ks = 0, glossy_ks_before = 0, diffuse_n = 0, diffuse_ks0 = 0;
  for (size_t v = 0; v < sc.truth.size(); ++v) {
    if (r.result.label[v] == glossy) {
      ++glossy_n, glossy_ks += r.after[v].ks > 0, glossy_ks_before += r.before[v].ks > 0;
      // The vertex's alpha is its material's, or regularised towards it within a factor of 4.
      EXPECT_GE(r.after[v].shininess, 0.25f * float(g.shininess) * 0.999f);
      EXPECT_LE(r.after[v].shininess, 4.0f * float(g.shininess) * 1.001f);
    } else {
      ++diffuse_n, diffuse_ks0 += r.after[v].ks == 0;
    }
    for (float c : r.after[v].color) EXPECT_TRUE(std::isfinite(c));
    EXPECT_TRUE(std::isfinite(r.after[v].kd) && std::isfinite(r.after[v].ks) && std::isfinite(r.after[v].rmse));
  }
  EXPECT_EQ(glossy_ks, glossy_n);
  EXPECT_EQ(diffuse_ks0, diffuse_n);
  // The case the stage exists for: the per-vertex fits' exponents scatter far more than the pooled one's error.
  std::vector<double> alpha_err;
  for (size_t v = 0; v < sc.truth.size(); ++v)
    if (sc.truth[v] == 1 && r.before[v].ks > 0) alpha_err.push_back(std::fabs(r.before[v].shininess - alpha) / alpha);
  ASSERT_FALSE(alpha_err.empty());
  std::nth_element(alpha_err.begin(), alpha_err.begin() + long(alpha_err.size() / 2), alpha_err.end());
  const double per_vertex_median = alpha_err[alpha_err.size() / 2];
  EXPECT_LT(std::fabs(g.shininess - alpha) / alpha, 0.5 * per_vertex_median)
      << "per-vertex alpha median error " << per_vertex_median << ", glossy vertices with k_s > 0 before: "
      << glossy_ks_before << " of " << glossy_n;
}

// Above about 3000 vertices K and the priors are chosen on an even subsample of the vertices
// (materials.cpp selection_subsample), then the chosen K's materials are found again on every
// vertex: 14 641 vertices must give the same answer as the whole mesh would: two materials,
// the right one diffuse, the glossy lobe within 10 %, every vertex labelled and as the truth says.
// (Held out over two folds, K = 3 scores 0.7 % better than K = 2 here by splitting the glossy half
// into two materials of one lobe, with one 0.50 %: at the tolerance's edge. The twin rule below
// merges such materials.)
TEST(Materials, ChosenOnASubsampleOfALargeMesh) {
  const float ks = 0.5f, alpha = 120.0f;
  const Scene sc = make_scene(true, ks, alpha, 11, LobeForm::BlinnNH, 120);
  ASSERT_GT(sc.truth.size(), 12000u);
  const StageRun r = run_stage(sc, MaterialOptions(), LobeForm::BlinnNH);
  ASSERT_EQ(r.result.chosen_k, 2) << r.result.report;
  ASSERT_EQ(r.result.materials.size(), 2u);
  size_t unlabelled = 0;
  for (int32_t label : r.result.label) unlabelled += label <= 0 || label > 2;
  EXPECT_EQ(unlabelled, 0u);
  expect_two_materials_found(sc, r, ks, alpha);
}

// A material split in two with one lobe is one material (MaterialOptions::twin_lobe_tolerance): on
// the scene above, held out over two folds, the held-out error prefers K = 3 by 0.7 %, two glossy
// materials with k_s 0.48 / 0.50 and alpha 117 / 120; without the rule they are kept apart, with it
// merged (and the materials are the truth's, expect_two_materials_found).
TEST(Materials, AMaterialSplitInTwoWithOneLobeIsOneMaterial) {
  const Scene sc = make_scene(true, 0.5f, 120.0f, 11, LobeForm::BlinnNH, 120);
  MaterialOptions two_folds;
  two_folds.pool_folds_below = 17;  // (16 photos)
  MaterialOptions no_rule = two_folds;
  no_rule.twin_lobe_tolerance = 0.0f;
  const StageRun split = run_stage(sc, no_rule, LobeForm::BlinnNH);
  ASSERT_EQ(split.result.chosen_k, 3) << split.result.report;
  const StageRun r = run_stage(sc, two_folds, LobeForm::BlinnNH);
  ASSERT_EQ(r.result.chosen_k, 2) << r.result.report;
  EXPECT_NE(r.result.report.find("merged, K = 2"), std::string::npos) << r.result.report;
  expect_two_materials_found(sc, r, 0.5f, 120.0f);
}

// The stage's loops (and the K of its choice, clustered concurrently) sum per vertex or in a fixed
// order: one thread and several give the same labels, lobes and fits, bit for bit.
TEST(Materials, TheSameResultsOnOneThreadAndOnSeveral) {
#ifdef _OPENMP
  const Scene sc = make_scene(true, 0.5f, 120.0f, 11, LobeForm::GgxNH, 120);  // subsampled choice, parallel loops
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const StageRun one = run_stage(sc, MaterialOptions(), LobeForm::GgxNH);
  omp_set_num_threads(std::max(2, threads));
  const StageRun several = run_stage(sc, MaterialOptions(), LobeForm::GgxNH);
  omp_set_num_threads(threads);
  ASSERT_EQ(one.result.chosen_k, several.result.chosen_k);
  EXPECT_EQ(one.result.label, several.result.label);
  EXPECT_EQ(one.result.heldout_error, several.result.heldout_error);
  for (size_t v = 0; v < sc.truth.size(); ++v) {
    ASSERT_EQ(one.after[v].kd, several.after[v].kd) << "vertex " << v;
    ASSERT_EQ(one.after[v].ks, several.after[v].ks) << "vertex " << v;
    ASSERT_EQ(one.after[v].shininess, several.after[v].shininess) << "vertex " << v;
    for (int ch = 0; ch < 3; ++ch) ASSERT_EQ(one.after[v].color[ch], several.after[v].color[ch]) << "vertex " << v;
  }
#else
  GTEST_SKIP() << "built without OpenMP: one thread only";
#endif
}

INSTANTIATE_TEST_SUITE_P(LobeForms, MaterialsBothLobes,
                         ::testing::Values(LobeForm::PhongRE, LobeForm::BlinnNH, LobeForm::GgxNH),
                         [](const ::testing::TestParamInfo<LobeForm> &i) {
                           return std::string(i.param == LobeForm::GgxNH ? "GGX" : i.param == LobeForm::BlinnNH ? "NH" : "RE");
                         });

TEST(Materials, OneGlossyMaterialIsOneMaterial) {
  const Scene sc = make_scene(false, 0.4f, 60.0f, 11);
  const StageRun r = run_stage(sc);
  ASSERT_EQ(r.result.chosen_k, 1) << r.result.report;
  EXPECT_FALSE(r.result.materials[0].diffuse);
  EXPECT_NEAR(r.result.materials[0].shininess, 60.0, 6.0) << r.result.report;
  for (size_t v = 0; v < sc.truth.size(); ++v) EXPECT_GT(r.after[v].ks, 0.0f);
}

TEST(Materials, NoSamplesLeaveTheFitsAlone) {
  const MeshData mesh = test::make_grid(2, 1.0f, 0.0f);
  std::vector<VertexFit> fits(mesh.positions.size() / 3, VertexFit{{0, 0, 0}, 0, 0, 0, 0, 0, 0, 0, kFitNone, 0});
  MaterialSampleStore store(fits.size());
  const MaterialResult r = fit_materials(mesh.view(), store, vbrdf::test::thesis_fit_options(), MaterialOptions(), nullptr, nullptr, fits);
  EXPECT_EQ(r.chosen_k, 0);
  for (int32_t l : r.label) EXPECT_EQ(l, 0);
}

// With no glossy material at all (every material diffuse: the real photometric-stereo objects pool
// into one material whose lobe explains 1-2 % of the energy), a vertex's own highlights are the only
// specular evidence: the stage keeps every vertex's own fit instead of stripping its lobe.
TEST(Materials, WithoutAGlossyMaterialOwnLobesAreKept) {
  const Scene sc = make_scene(false, 0.0f, 30.0f, 5);  // a matte object
  ReflectanceFitOptions o = vbrdf::test::thesis_fit_options();
  o.lobe = LobeForm::GgxNH;
  std::vector<VertexFit> before(sc.chunk.vertex_count);
  fit_chunk_cpu(sc.chunk, o, before.data());
  size_t own = 0;
  for (size_t v = 0; v < before.size(); v += 10)  // as if these vertices' own photos showed a highlight
    if (before[v].status == kFitDiffuseOnly) before[v].status = kFitFull, before[v].ks = 0.2f, before[v].shininess = 40.0f, ++own;
  ASSERT_GT(own, 20u);
  std::vector<VertexFit> after = before;
  MaterialSampleStore store(sc.chunk.vertex_count);
  store.add_chunk(sc.chunk, before.data(), o);
  const MaterialResult r = fit_materials(sc.mesh.view(), store, o, MaterialOptions(), nullptr, nullptr, after);
  ASSERT_GE(r.chosen_k, 1);
  for (const Material &m : r.materials) ASSERT_TRUE(m.diffuse) << r.report;
  EXPECT_EQ(r.vertices_set_diffuse, 0u) << r.report;
  for (size_t v = 0; v < before.size(); ++v) {
    EXPECT_EQ(after[v].ks, before[v].ks) << "vertex " << v;
    EXPECT_EQ(after[v].kd, before[v].kd) << "vertex " << v;
    EXPECT_EQ(after[v].status, before[v].status) << "vertex " << v;
  }
  EXPECT_NE(r.report.find("no glossy material"), std::string::npos) << r.report;
}

// A glossy material gives its lobe to its lobeless vertices only where that clearly lowers their
// held-out error (min_giving_gain): demanding an impossible gain leaves every vertex its own fit.
TEST(Materials, LobesAreGivenOnlyWhereTheHeldOutPhotosSayTheyHelp) {
  const Scene sc = make_scene(true, 0.5f, 30.0f, 7);
  const StageRun given = run_stage(sc);
  ASSERT_GT(given.result.vertices_changed_to_specular, 0u) << given.result.report;
  EXPECT_NE(given.result.report.find(": given"), std::string::npos) << given.result.report;
  MaterialOptions strict;
  strict.min_giving_gain = 1.0f;  // the lobe would have to explain every held-out residual
  const StageRun kept = run_stage(sc, strict);
  EXPECT_EQ(kept.result.vertices_changed_to_specular, 0u) << kept.result.report;
  EXPECT_NE(kept.result.report.find("NOT given"), std::string::npos) << kept.result.report;
  for (size_t v = 0; v < sc.truth.size(); ++v) {
    const Material &m = kept.result.materials[size_t(kept.result.label[v]) - 1];
    if (!m.diffuse && !(kept.before[v].ks > 0)) EXPECT_EQ(kept.after[v].ks, 0.0f) << "vertex " << v;
  }
}

// The scene with one more sample per vertex in each held-out photo of the giving test (raster % 4 ==
// 3): grazing light (N.L = 0.05, flagged kGrazing: the fits leave it out) at a lobe cosine where the
// lobe is bright, and the photo dark there (the diffuse term only, as a microfacet lobe's shadowing
// makes it): the pixels a relit lobe would light wrongly.
Scene with_dark_grazing_samples(const Scene &sc) {
  Scene out = sc;
  out.chunk.samples.clear();
  out.chunk.offsets.assign(1, 0);
  for (uint32_t v = 0; v < sc.chunk.vertex_count; ++v) {
    for (uint32_t k = sc.chunk.offsets[v]; k < sc.chunk.offsets[v + 1]; ++k) {
      const Sample &smp = sc.chunk.samples[k];
      out.chunk.samples.push_back(smp);
      if (smp.raster % 4 != 3) continue;
      Sample dark = smp;  // the held-out photo's colour at N.L = 0.05, without the lobe
      const float scale = smp.d > 0.05f ? 0.05f / smp.d : 1.0f;
      for (float &c : dark.rgb) c *= scale;
      dark.d = 0.05f, dark.lobe_cos = 0.99f, dark.flags = kGrazing;
      out.chunk.samples.push_back(dark);
    }
    out.chunk.offsets.push_back(uint32_t(out.chunk.samples.size()));
  }
  return out;
}

// The giving test scores the grazing-light samples too (which the fits leave out): a lobe that would
// light them where the photos stay dark is not given; without them the same lobe is.
TEST(Materials, ALobeThatLightsDarkGrazingSamplesIsNotGiven) {
  const Scene sc = make_scene(true, 0.5f, 30.0f, 7);
  const StageRun plain = run_stage(sc);
  ASSERT_GT(plain.result.vertices_changed_to_specular, 0u) << plain.result.report;
  const StageRun dark = run_stage(with_dark_grazing_samples(sc));
  ASSERT_EQ(dark.result.chosen_k, 2) << dark.result.report;
  EXPECT_EQ(dark.result.vertices_changed_to_specular, 0u) << dark.result.report;
  EXPECT_NE(dark.result.report.find("NOT given"), std::string::npos) << dark.result.report;
  for (size_t v = 0; v < sc.truth.size(); ++v)  // the fits never saw the added samples
    ASSERT_EQ(dark.before[v].ks, plain.before[v].ks) << "vertex " << v;
}

// The scene with every training sample (raster % 4 != 3) of the vertices at x < -0.8 (two columns
// of the glossy half) dropped: the training photos of the stage's split never see them, only its
// held-out ones do (as one camera's vertices in a two-camera project of 4 photos).
Scene seen_only_by_heldout_photos(const Scene &sc) {
  Scene out = sc;
  out.chunk.samples.clear();
  out.chunk.offsets.assign(1, 0);
  for (uint32_t v = 0; v < sc.chunk.vertex_count; ++v) {
    const bool strip = sc.mesh.positions[3 * v] < -0.8f;
    for (uint32_t k = sc.chunk.offsets[v]; k < sc.chunk.offsets[v + 1]; ++k)
      if (!strip || sc.chunk.samples[k].raster % 4 == 3) out.chunk.samples.push_back(sc.chunk.samples[k]);
    out.chunk.offsets.push_back(uint32_t(out.chunk.samples.size()));
  }
  return out;
}

// Vertices that no training photo of the giving test sees are no evidence about a lobe: both of its
// answers there are guesses (the one without a lobe is black, ~38 CIEDE2000), and counted they swamp
// what the seen vertices show (checked: with them the lobe is NOT given, 38.17 against 38.25). Left
// out and said so, the lobeless vertices the training photos see decide, and the lobe helps them.
TEST(Materials, VerticesNoTrainingPhotoSeesAreNoEvidenceAboutALobe) {
  const Scene sc = seen_only_by_heldout_photos(make_scene(true, 0.5f, 30.0f, 7));
  const StageRun r = run_stage(sc);
  ASSERT_EQ(r.result.chosen_k, 2) << r.result.report;
  EXPECT_NE(r.result.report.find("photos do not see them"), std::string::npos) << r.result.report;
  EXPECT_NE(r.result.report.find(": given"), std::string::npos) << r.result.report;
  EXPECT_GT(r.result.vertices_changed_to_specular, 0u) << r.result.report;
}

// The scene without the held-out photos' samples (raster % 4 == 3) of the vertices `strip` marks.
Scene unseen_by_heldout_photos(const Scene &sc, const std::vector<uint8_t> &strip) {
  Scene out = sc;
  out.chunk.samples.clear();
  out.chunk.offsets.assign(1, 0);
  for (uint32_t v = 0; v < sc.chunk.vertex_count; ++v) {
    for (uint32_t k = sc.chunk.offsets[v]; k < sc.chunk.offsets[v + 1]; ++k)
      if (!strip[v] || sc.chunk.samples[k].raster % 4 != 3) out.chunk.samples.push_back(sc.chunk.samples[k]);
    out.chunk.offsets.push_back(uint32_t(out.chunk.samples.size()));
  }
  return out;
}

// Nor are vertices that no held-out photo sees: they add a paired difference of exactly 0 and pull
// the mean towards "no gain" (synth_linear16 at 4 photos: 69 of 73 vertices, -0.44 +- 0.26 where the
// 4 seen ones give -8.0 +- 2.9). Two in three of the scene's lobeless glossy vertices lose their
// held-out samples; the test counts only the others, each with its held-out samples (checked to fail
// when they are counted: 57 vertices for 80 samples).
TEST(Materials, VerticesNoHeldOutPhotoSeesAreNoEvidenceEither) {
  const Scene sc = make_scene(true, 0.5f, 30.0f, 7);
  const StageRun plain = run_stage(sc);
  std::vector<uint8_t> strip(sc.truth.size(), 0);
  size_t lobeless = 0;
  for (size_t v = 0; v < sc.truth.size(); ++v)
    if (sc.truth[v] == 1 && !(plain.before[v].ks > 0)) strip[v] = (lobeless++ % 3) != 0;
  const StageRun r = run_stage(unseen_by_heldout_photos(sc, strip));
  const std::string &rep = r.result.report;
  const size_t at = rep.find("its lobe given to the vertices without one of their own? on ");
  ASSERT_NE(at, std::string::npos) << rep;
  unsigned vertices = 0, samples = 0;
  const size_t comma = rep.find(", ", at);
  ASSERT_EQ(std::sscanf(rep.c_str() + at, "its lobe given to the vertices without one of their own? on %u", &vertices), 1) << rep;
  ASSERT_EQ(std::sscanf(rep.c_str() + comma, ", %u held-out samples", &samples), 1) << rep;
  EXPECT_GT(vertices, 0u) << rep;
  // Every judged vertex brings its held-out samples: 4 here (a few may face away from a light).
  EXPECT_GE(samples, 3u * vertices) << rep;
  EXPECT_LE(samples, 4u * vertices) << rep;
  EXPECT_NE(rep.find(": given"), std::string::npos) << rep;
}

// The scene with the samples of its first `photos` photos only (raster < photos).
Scene first_photos(const Scene &sc, int photos) {
  Scene out = sc;
  out.chunk.samples.clear();
  out.chunk.offsets.assign(1, 0);
  for (uint32_t v = 0; v < sc.chunk.vertex_count; ++v) {
    for (uint32_t k = sc.chunk.offsets[v]; k < sc.chunk.offsets[v + 1]; ++k)
      if (sc.chunk.samples[k].raster < photos) out.chunk.samples.push_back(sc.chunk.samples[k]);
    out.chunk.offsets.push_back(uint32_t(out.chunk.samples.size()));
  }
  return out;
}

// The giving tests' "on N such vertices ..., M held-out samples" summed over a stage report's glossy
// materials.
struct GivingCounts {
  unsigned vertices = 0, samples = 0;
};
GivingCounts giving_counts(const std::string &rep) {
  const char *const key = "its lobe given to the vertices without one of their own? on ";
  GivingCounts sum;
  for (size_t at = rep.find(key); at != std::string::npos; at = rep.find(key, at + 1)) {
    unsigned vertices = 0, samples = 0;
    std::sscanf(rep.c_str() + at + std::strlen(key), "%u", &vertices);
    std::sscanf(rep.c_str() + rep.find(", ", at), ", %u held-out samples", &samples);
    sum.vertices += vertices, sum.samples += samples;
  }
  return sum;
}

// The stage on the scene's first `photos` photos, with one held-out fold and with the default folds.
struct FoldRuns {
  StageRun single, pooled;
};
FoldRuns one_fold_and_default(const Scene &full, int photos) {
  const Scene sc = first_photos(full, photos);
  MaterialOptions one_fold;
  one_fold.min_heldout_photos = 1;
  return {run_stage(sc, one_fold), run_stage(sc)};
}

// With 8 photos one held-out split (every 4th photo) rests on 2 photos; the choice of K and the
// giving test sum over the folds of heldout_folds.h until 8 photos were held out (here all 4, each
// photo held out once): 4 times the judged (vertex, split) pairs and held-out samples (synth_basic at
// 8 photos: relit 0.919 -> 0.813, ctest material_folds_few_photos). Checked to fail with one fold.
TEST(Materials, WithFewPhotosEveryPhotoIsHeldOutOnce) {
  const Scene full = make_scene(true, 0.5f, 30.0f, 7);
  const FoldRuns runs = one_fold_and_default(full, 8);
  const StageRun &single = runs.single, &pooled = runs.pooled;
  EXPECT_EQ(single.result.folds, 1) << single.result.report;
  EXPECT_EQ(pooled.result.folds, 4) << pooled.result.report;
  EXPECT_NE(pooled.result.report.find("summed over 4 such splits"), std::string::npos) << pooled.result.report;
  const GivingCounts one = giving_counts(single.result.report), four = giving_counts(pooled.result.report);
  ASSERT_GT(one.vertices, 0u) << single.result.report;
  EXPECT_GE(four.vertices, 3 * one.vertices) << single.result.report << pooled.result.report;
  EXPECT_GE(four.samples, 3 * one.samples) << single.result.report << pooled.result.report;
  // From pool_folds_below (16) photos on, one fold.
  const StageRun sixteen = run_stage(full);
  EXPECT_EQ(sixteen.result.folds, 1) << sixteen.result.report;
}

// With fewer photos than 4 the first fold (index % 4 == 3) holds none out: it is skipped, and the
// choice is scored on the folds that do hold one out (once it scored nothing: every K's error 0).
TEST(Materials, FewerPhotosThanTheSplitStillHoldSomeOut) {
  const FoldRuns runs = one_fold_and_default(make_scene(true, 0.5f, 30.0f, 7), 3);
  const StageRun &single = runs.single, &pooled = runs.pooled;
  EXPECT_EQ(single.result.folds, 1) << single.result.report;
  EXPECT_EQ(pooled.result.folds, 3) << pooled.result.report;
  for (const StageRun *r : {&single, &pooled}) {
    ASSERT_FALSE(r->result.heldout_error.empty()) << r->result.report;
    EXPECT_GT(r->result.heldout_error.front(), 0.0) << r->result.report;
  }
}

// The folds of heldout_folds.h (the diffuse-form pilot's and the material stage's): in turn until
// 8 photos were held out, one fold from 32 photos on, all four for the thesis's 8-12; folds that hold out none of
// the photos, or all of them, are skipped.
TEST(HeldOutFolds, TakenInTurnUntilEightPhotosWereHeldOut) {
  EXPECT_EQ(heldout_fold_count(32), 1);
  EXPECT_EQ(heldout_fold_count(64), 1);
  EXPECT_EQ(heldout_fold_count(31), 2);  // fold 0 (index % 4 == 3) holds out 7
  EXPECT_EQ(heldout_fold_count(24), 2);
  EXPECT_EQ(heldout_fold_count(16), 2);
  EXPECT_EQ(heldout_fold_count(12), 3);
  EXPECT_EQ(heldout_fold_count(9), 4);
  EXPECT_EQ(heldout_fold_count(4), 4);
  EXPECT_EQ(heldout_fold_count(0), 4);
  EXPECT_EQ(heldout_fold_count(9, 1), 1);
  auto present = [](std::vector<size_t> rasters) {
    std::vector<uint8_t> p(64, 0);
    for (size_t r : rasters) p[r] = 1;
    return p;
  };
  EXPECT_EQ(heldout_folds(present({0, 1, 2})), (std::vector<int>{1, 2, 3}));  // nothing at index 3
  EXPECT_EQ(heldout_folds(present({3, 7})), (std::vector<int>{0}));             // (folds 1-3 would hold out nothing)
  EXPECT_EQ(heldout_folds(present({5})), (std::vector<int>{0}));                // one photo: nothing to split
  std::vector<size_t> all;
  for (size_t r = 0; r < 40; ++r) all.push_back(r);
  EXPECT_EQ(heldout_folds(present(all)), (std::vector<int>{0}));
  all.resize(20);
  EXPECT_EQ(heldout_folds(present(all)), (std::vector<int>{0, 1}));
}

TEST(Materials, ByDefaultOwnLobesAreKeptAndTheOthersGetTheMaterials) {
  const Scene sc = make_scene(true, 0.5f, 30.0f, 7);
  const StageRun r = run_stage(sc);
  ASSERT_EQ(r.result.chosen_k, 2) << r.result.report;
  size_t kept = 0, given = 0;
  for (size_t v = 0; v < sc.truth.size(); ++v) {
    const Material &m = r.result.materials[size_t(r.result.label[v]) - 1];
    if (m.diffuse) {
      EXPECT_EQ(r.after[v].ks, 0.0f);
    } else if (r.before[v].status == kFitFull && r.before[v].ks > 0) {
      EXPECT_EQ(r.after[v].ks, r.before[v].ks);
      EXPECT_EQ(r.after[v].shininess, r.before[v].shininess);
      ++kept;
    } else {
      EXPECT_GT(r.after[v].ks, 0.0f);
      EXPECT_NEAR(r.after[v].shininess, m.shininess, 3.0 * m.shininess);
      ++given;
    }
  }
  EXPECT_GT(kept, 0u);
  EXPECT_GT(kept + given, sc.truth.size() / 3);
}
