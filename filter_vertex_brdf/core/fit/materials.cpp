#include "fit/materials.h"

#include "base/mesh_adjacency.h"
#include "base/number_format.h"
#include "fit/heldout_folds.h"
#include "fit/label_spread.h"
#include "fit/material_labels.h"
#include "fit/material_report.h"
#include "fit/material_solve.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace vbrdf {

using namespace material_stage;

namespace {

// The vertices on which K and the priors are chosen: every k-th eligible one, k such that about
// kSelectionVertices remain (all of them on smaller meshes). The choice compares held-out errors
// summed over the same vertices for every K, so an even subsample ranks them as the whole mesh
// does; the materials of the chosen K are then found again on every vertex (fit_materials step 2).
// On the benchmark's 100 k vertices (45 k eligible) the choice took 1.68 s on all of them, 0.24 s
// on 3000 (same K and lobes: docs/decisions/material_stage.md).
constexpr size_t kSelectionVertices = 3000;
Context selection_subsample(const Context &c, size_t eligible) {
  Context sel = c;
  const size_t stride = (eligible + kSelectionVertices - 1) / kSelectionVertices;
  if (stride <= 1) return sel;
  sel.subsampled = true;
  sel.verts.clear();
  for (size_t v = 0, k = 0; v < c.n; ++v)
    if (c.eligible[v] && (sel.eligible[v] = (k++ % stride) == 0)) sel.verts.push_back(uint32_t(v));
  return sel;
}

// Merges a configuration's materials that have the same lobe: both diffuse (diffuse_flags), or both
// glossy with k_s and alpha within mo.twin_lobe_tolerance of each other (relative to the larger);
// the labels are renumbered 1..K' in order and the lobes refitted on `set`. Returns K - K'.
int merge_twin_materials(const Context &c, const std::vector<Static> &S, int set, const std::vector<VertexFit> &fits,
                         const MaterialOptions &mo, Config &cfg) {
  if (cfg.K < 2) return 0;
  const std::vector<uint8_t> diffuse = diffuse_flags(cfg.lobes, median_kd_of(c, fits, cfg.label, cfg.K), cfg.K, mo, c.o.lobe);
  auto close = [&](double a, double b) { return std::fabs(a - b) <= double(mo.twin_lobe_tolerance) * std::max(a, b); };
  std::vector<int> root(size_t(cfg.K) + 1);
  for (int m = 0; m <= cfg.K; ++m) root[size_t(m)] = m;
  for (int i = 1; i <= cfg.K; ++i)
    for (int j = i + 1; j <= cfg.K; ++j) {
      if (root[size_t(j)] != j) continue;  // already merged into an earlier one
      const LobeFit &a = cfg.lobes[size_t(i)], &b = cfg.lobes[size_t(j)];
      const bool twins = (diffuse[size_t(i)] && diffuse[size_t(j)]) ||
                         (!diffuse[size_t(i)] && !diffuse[size_t(j)] && close(a.ks, b.ks) && close(a.alpha, b.alpha));
      if (twins) root[size_t(j)] = root[size_t(i)];
    }
  std::vector<int32_t> renumbered(size_t(cfg.K) + 1, 0);
  int k = 0;
  for (int m = 1; m <= cfg.K; ++m) renumbered[size_t(m)] = root[size_t(m)] == m ? ++k : renumbered[size_t(root[size_t(m)])];
  const int merged = cfg.K - k;
  if (!merged) return 0;
  for (int32_t &l : cfg.label)
    if (l > 0) l = renumbered[size_t(l)];
  cfg.K = k;
  cfg.lobes = fit_lobes(c, set, S, cfg.label, k);
  return merged;
}

// Per raster index (16 bits): 1 when the raster has samples in the store (normal or grazing).
std::vector<uint8_t> rasters_present(const MaterialSampleStore &store) {
  std::vector<uint8_t> present(size_t(1) << 16, 0);
  for (const MaterialSampleStore::Entry &e : store.entries()) present[e.raster] = 1;
  for (const MaterialSampleStore::Entry &e : store.grazing_entries()) present[e.raster] = 1;
  return present;
}

// Per fold of heldout_folds.h taken for the store's photos, per raster index: 1 when held out.
std::vector<std::vector<uint8_t>> held_out_tables(const std::vector<uint8_t> &present, size_t min_held) {
  std::vector<std::vector<uint8_t>> tables;
  for (int k : heldout_folds(present, min_held)) {
    std::vector<uint8_t> held(present.size(), 0);
    for (size_t r = 0; r < held.size(); ++r) held[r] = held_out_in_fold(r, k);
    tables.push_back(std::move(held));
  }
  return tables;
}

} // namespace

namespace {

// The selection's sums per held-out fold (heldout_folds.h), and its one-material lobes (K = 1).
struct FoldSums {
  std::vector<std::vector<Static>> train, held;
  std::vector<std::vector<LobeFit>> one;
};

FoldSums fold_sums(Context &sel, const std::vector<std::vector<uint8_t>> &held_rasters,
                   const std::vector<int32_t> &ones) {
  const size_t n_folds = held_rasters.size();
  FoldSums F{std::vector<std::vector<Static>>(n_folds), std::vector<std::vector<Static>>(n_folds),
             std::vector<std::vector<LobeFit>>(n_folds)};
  for (size_t f = 0; f < n_folds; ++f) {
    sel.held_raster = &held_rasters[f];
    F.train[f] = static_sums(sel, kTrain), F.held[f] = static_sums(sel, kHeld);
    F.one[f] = fit_lobes(sel, kTrain, F.train[f], ones, 1);
  }
  sel.held_raster = &held_rasters.front();
  return F;
}

// The prior strengths tried for every K: each k_s prior with each alpha prior.
std::vector<Choice> prior_choices(const MaterialOptions &mo) {
  std::vector<Choice> choices;
  for (float prior : mo.prior_strengths)
    for (float alpha_prior : mo.alpha_prior_strengths) choices.push_back({prior, alpha_prior});
  if (choices.empty()) choices.push_back({1.0f, -1.0f});
  return choices;
}

// Clusters every (K, fold) pair on the training photos and scores it at the held-out ones, for
// every prior choice: error_of[K][f] (empty where fold 0 collapsed to fewer than K materials:
// nothing new to score). config_of[K] is fold 0's configuration, the one kept for step 2. The
// pairs are independent: clustered and scored concurrently, each with its own caches (the loops
// inside then run on one thread: on the 3 000-vertex subsample they parallelise poorly). The same
// results as in turn: every loop's sums are per vertex or in a fixed order.
void cluster_and_score(const Context &sel, const Adjacency &adj, const FoldSums &F,
                       const std::vector<std::vector<uint8_t>> &held_rasters, const std::vector<int32_t> &ones,
                       const std::vector<VertexFit> &fits, const std::vector<Choice> &choices,
                       std::vector<Config> &config_of, std::vector<std::vector<std::vector<double>>> &error_of) {
  const int kmax = int(config_of.size()) - 1;
  const size_t n_folds = held_rasters.size();
  const MaterialOptions &mo = sel.mo;
  const int jobs = kmax * int(n_folds);
  // Largest K first: the dearest clustering starts at once and the cheap ones fill in around it.
#pragma omp parallel for schedule(dynamic, 1) if (jobs > 1)
  for (int i = 0; i < jobs; ++i) {
    const int K = kmax - i / int(n_folds);
    const size_t f = size_t(i % int(n_folds));
    Context ck = sel;
    ck.held_raster = &held_rasters[f];
    SpreadRingCache rings_k;
    std::vector<std::vector<Lobe>> lobes_k;
    ck.rings = &rings_k, ck.lobe_buffers = &lobes_k;
    Config cfg = K == 1 ? Config{1, ones, F.one[f]}
                        : cluster(ck, adj, F.train[f], kTrain,
                                  initial_labels(ck, adj, F.train[f], kTrain, F.one[f][1].alpha, K), K, mo.iterations);
    if (K == 1 || cfg.K == K || f > 0) {
      const std::vector<uint8_t> diffuse =
          diffuse_flags(cfg.lobes, median_kd_of(ck, fits, cfg.label, cfg.K), cfg.K, mo, sel.o.lobe);
      error_of[size_t(K)][f] =
          solve_vertices(ck, F.train[f], F.held[f], kTrain, kHeld, cfg.label, cfg.lobes, diffuse, cfg.K, choices, nullptr);
    }
    if (f == 0) config_of[size_t(K)] = std::move(cfg);
  }
}

// Step 1: K and the priors chosen on the training photos by the error at the held-out ones
// (summed over the folds), on the selection (`ones`: its vertices in one material). Fills R.heldout_error (per K), R.chosen_prior and
// R.chosen_alpha_prior and the report's facts of the choice; returns the chosen configuration
// (its twin materials merged) with its prior choice.
Config choose_configuration(Context &sel, const Adjacency &adj, const FoldSums &F,
                            const std::vector<std::vector<uint8_t>> &held_rasters, const std::vector<int32_t> &ones,
                            const std::vector<VertexFit> &fits, MaterialResult &R, MaterialReportFacts &facts,
                            Choice &chosen_choice) {
  const MaterialOptions &mo = sel.mo;
  const size_t n_folds = held_rasters.size();
  const std::vector<Choice> choices = prior_choices(mo);
  const int kmax = std::max(1, mo.max_materials);
  std::vector<Config> config_of(size_t(kmax) + 1);
  std::vector<std::vector<std::vector<double>>> error_of(size_t(kmax) + 1, std::vector<std::vector<double>>(n_folds));
  cluster_and_score(sel, adj, F, held_rasters, ones, fits, choices, config_of, error_of);
  std::vector<Config> configs;
  std::vector<Choice> best_choice;
  for (int K = 1; K <= kmax; ++K) {
    if (error_of[size_t(K)][0].empty()) {  // collapsed
      R.heldout_error.push_back(R.heldout_error.empty() ? 0 : R.heldout_error.back());
      configs.push_back(std::move(config_of[size_t(K)]));
      best_choice.push_back(best_choice.empty() ? choices.front() : best_choice.back());
      continue;
    }
    std::vector<double> err = error_of[size_t(K)][0];
    for (size_t f = 1; f < n_folds; ++f)
      for (size_t j = 0; j < err.size(); ++j) err[j] += error_of[size_t(K)][f][j];
    const size_t b = size_t(std::min_element(err.begin(), err.end()) - err.begin());
    R.heldout_error.push_back(err[b]);
    configs.push_back(std::move(config_of[size_t(K)]));
    best_choice.push_back(choices[b]);
  }
  facts.best_error = *std::min_element(R.heldout_error.begin(), R.heldout_error.end());
  size_t chosen = 0;
  while (chosen + 1 < R.heldout_error.size() && R.heldout_error[chosen] > (1 + mo.choose_tolerance) * facts.best_error)
    ++chosen;
  // Materials are told apart by their lobes (colour is no feature): two materials of the same lobe
  // are one material split in two, which the map would show as regions that are not there: merged.
  facts.k_within_tolerance = configs[chosen].K;
  facts.merged = merge_twin_materials(sel, F.train.front(), kTrain, fits, mo, configs[chosen]);
  facts.k_merged = configs[chosen].K;
  chosen_choice = best_choice[chosen];
  R.chosen_prior = chosen_choice.prior;
  R.chosen_alpha_prior = chosen_choice.alpha_prior;
  return std::move(configs[chosen]);
}

// Step 2: the chosen configuration refitted on all samples and vertices.
Config refit_on_all(const Context &c, const Context &sel, const Adjacency &adj, const std::vector<Static> &S,
                    const Config &chosen) {
  const int k_chosen = chosen.K;
  if (sel.subsampled && k_chosen > 1) {
    // The choice's lobes, refitted on every photo of its subsample, label every vertex by its own data
    // (assign_labels: not the subsample's labels spread over the mesh, which lost a 1 900-vertex
    // material of the benchmark scene), then one lobe fit on all of them. This replaced a k-means start
    // and four alternations on every vertex (0.18 -> 0.06 s on the benchmark grid's reference; the
    // pooled energy 1117 -> 1125 there, bunny's 58.91 -> 58.93, the frog's 7551 -> 7583).
    const std::vector<Static> S_sel = static_sums(sel, kAll);
    const std::vector<LobeFit> start_lobes = fit_lobes(sel, kAll, S_sel, chosen.label, k_chosen);
    std::vector<int32_t> start(c.n, 0);
    assign_labels(c, adj, S, kAll, start_lobes, k_chosen, start);
    return cluster(c, adj, S, kAll, std::move(start), k_chosen, 0, true);
  }
  std::vector<int32_t> start = chosen.label;
  if (sel.subsampled)  // one material: every eligible vertex in it
    for (size_t v = 0; v < c.n; ++v) start[v] = c.eligible[v] ? 1 : 0;
  return cluster(c, adj, S, kAll, start, k_chosen, k_chosen > 1 ? 2 : 0, true);
}

// Every glossy material's giving test (materials.h), summed over the folds, on the selection.
std::vector<GivingTest> giving_tests(Context &sel, const FoldSums &F, const std::vector<std::vector<uint8_t>> &held_rasters,
                                     const Config &fin, const std::vector<uint8_t> &diffuse, const Choice &choice,
                                     const std::vector<VertexFit> &fits, bool any_glossy) {
  std::vector<GivingTest> giving(size_t(fin.K) + 1);
  for (size_t f = 0; any_glossy && f < held_rasters.size(); ++f) {
    sel.held_raster = &held_rasters[f];
    const std::vector<GivingTest> g = test_giving(sel, F.train[f], fin.label, diffuse, fin.K, choice, fits);
    for (size_t m = 0; m < giving.size(); ++m) giving[m] += g[m];
  }
  sel.held_raster = &held_rasters.front();
  return giving;
}

// The vertices whose fit step 3 rewrites: the eligible, labelled ones that do not keep their own
// fit, in a diffuse material with a lobe of their own or in a glossy material that gives its lobe.
// The others need no parameters: on the benchmark scene 38 k of its 54 k, most of the solve's time.
std::vector<uint8_t> vertices_to_rewrite(const Context &c, const Config &fin, const std::vector<uint8_t> &diffuse,
                                         const std::vector<GivingTest> &giving, const std::vector<VertexFit> &fits,
                                         bool any_glossy) {
  std::vector<uint8_t> rewritten(c.n, 0);
  for (uint32_t v : c.verts) {
    const size_t m = size_t(std::max(0, fin.label[v]));
    rewritten[v] = any_glossy && m > 0 && !keeps_own_fit(c.mo, diffuse[m] != 0, fits[v]) &&
                   (diffuse[m] ? fits[v].ks > 0 : giving[m].gives(c.mo));
  }
  return rewritten;
}

// Labels every eligible vertex with its material and counts each material's vertices, samples and
// vertices with specular information of their own.
void count_members(const Context &c, const std::vector<Static> &S, const std::vector<Lobe> &L, const Config &fin,
                   MaterialResult &R) {
  R.materials.resize(size_t(fin.K));
  for (size_t v = 0; v < c.n; ++v) {
    if (!c.eligible[v] || fin.label[v] <= 0) continue;
    const size_t m = size_t(fin.label[v]);
    R.label[v] = int32_t(m);
    Material &mat = R.materials[m - 1];
    ++mat.vertices;
    mat.samples += S[v].n, mat.highlight_samples += S[v].n_high;
    double info, rhs;
    ks_equation(S[v], L[v], info, rhs);
    mat.evidence_vertices += info > 0;
  }
}

// Step 3: the rewritten vertices' fits from their own samples (in parallel): a diffuse material's
// vertex its robust diffuse-only reflectance where it has one, else the solved k_s, alpha and k_d C
// with the quality recomputed. Counts the vertices that gained or lost a lobe.
void rewrite_fits(const Context &c, const std::vector<Static> &S, const Config &fin, const std::vector<uint8_t> &diffuse,
                  const std::vector<uint8_t> &rewritten, const Params &P, const float *diffuse_rgb,
                  const uint8_t *diffuse_valid, std::vector<VertexFit> &fits, MaterialResult &R) {
  const ReflectanceFitOptions &o = c.o;
  uint64_t to_specular = 0, to_diffuse = 0;
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : to_specular, to_diffuse) if (c.n > 20000)
  for (long long vi = 0; vi < (long long)c.n; ++vi) {
    const size_t v = size_t(vi);
    if (!rewritten[v]) continue;  // (a rewritten vertex is eligible and labelled)
    const size_t m = size_t(fin.label[v]);
    VertexFit &f = fits[v];
    const bool had_ks = f.ks > 0;
    const bool weak = f.status == kFitFromWeakSamples;
    const std::vector<Sample> samples = c.store.as_samples(v);
    if (diffuse[m] && diffuse_rgb && diffuse_valid && diffuse_valid[v] && !weak) {
      set_diffuse_only_reflectance(samples.data(), samples.size(), o, diffuse_rgb + 3 * v, f);
    } else {
      double rho[3] = {P.rho[3 * v], P.rho[3 * v + 1], P.rho[3 * v + 2]};
      if (c.mo.robust_colour) robust_rho(c, v, diffuse[m] ? 0.0 : P.ks[v], P.alpha[v], rho);
      if (!(S[v].a > 0) && !diffuse[m]) {
        // No diffuse information (cannot happen with a usable sample, but stay safe): keep k_d C.
      } else {
        set_kd_color(rho, f);
        f.kd = std::min(f.kd, o.kd_max);  // C from the uncapped k_d, as the per-vertex fit stores it
      }
      f.ks = diffuse[m] ? 0.0f : float(P.ks[v]);
      f.shininess = f.ks > 0 ? float(P.alpha[v]) : 0.0f;
      if (!weak) f.status = f.ks > 0 ? kFitFull : kFitDiffuseOnly;
      recompute_fit_quality(samples.data(), samples.size(), o, weak, f);
    }
    to_specular += !had_ks && f.ks > 0;
    to_diffuse += had_ks && !(f.ks > 0);
  }
  R.vertices_changed_to_specular = to_specular, R.vertices_set_diffuse = to_diffuse;
}

// Each material's lobe as the result states it: a diffuse material's k_s and alpha are 0.
void describe_materials(const Config &fin, const std::vector<uint8_t> &diffuse, const std::vector<double> &median_kd,
                        MaterialResult &R) {
  for (int m = 1; m <= fin.K; ++m) {
    Material &mat = R.materials[size_t(m) - 1];
    const LobeFit &lf = fin.lobes[size_t(m)];
    mat.diffuse = diffuse[size_t(m)] != 0;
    mat.ks = mat.diffuse ? 0 : lf.ks;
    mat.shininess = mat.diffuse ? 0 : lf.alpha;
    mat.shininess_lo = lf.alpha_lo, mat.shininess_hi = lf.alpha_hi;
    mat.median_kd = median_kd[size_t(m)];
    mat.lobe_gain = lf.energy_zero > 0 ? (lf.energy_zero - lf.energy) / lf.energy_zero : 0;
  }
}

// The context of the stage: the vertices it refits (eligible: fitted from their own samples, with
// samples kept) and the lobe keys of the kept samples.
Context stage_context(const MeshView &mesh, const MaterialSampleStore &store, const ReflectanceFitOptions &o,
                      const MaterialOptions &mo, const std::vector<VertexFit> &fits) {
  Context c{store, o, mo, {}, {}, {}, std::min(mesh.vertex_count, std::min(store.vertex_count(), fits.size()))};
  c.eligible.assign(c.n, 0);
  for (size_t v = 0; v < c.n; ++v) {
    const uint8_t st = fits[v].status;
    c.eligible[v] = (st == kFitFull || st == kFitDiffuseOnly || st == kFitFromWeakSamples) && store.last(v) > store.first(v);
    if (c.eligible[v]) c.verts.push_back(uint32_t(v));
  }
  c.ggx = o.lobe == LobeForm::GgxNH;
  return c;
}

double seconds_from(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace

MaterialResult fit_materials(const MeshView &mesh, const MaterialSampleStore &store, const ReflectanceFitOptions &o,
                             const MaterialOptions &mo, const float *diffuse_rgb, const uint8_t *diffuse_valid,
                             std::vector<VertexFit> &fits) {
  const auto t0 = std::chrono::steady_clock::now();
  MaterialResult R;
  MaterialReportFacts facts;
  Context c = stage_context(mesh, store, o, mo, fits);
  R.label.assign(fits.size(), 0);
  R.bytes_kept = store.bytes();
  facts.eligible_vertices = c.verts.size();
  if (c.verts.empty()) {
    R.report = material_report(R, facts, mo, o.lobe);
    return R;
  }
  // The held-out splits (heldout_folds.h): below pool_folds_below photos folds until
  // min_heldout_photos were held out, else one.
  const std::vector<uint8_t> present = rasters_present(store);
  facts.photos = size_t(std::count(present.begin(), present.end(), uint8_t(1)));
  const std::vector<std::vector<uint8_t>> held_rasters =
      held_out_tables(present, facts.photos < mo.pool_folds_below ? mo.min_heldout_photos : 1);
  c.held_raster = &held_rasters.front();
  R.folds = int(held_rasters.size());
  std::vector<float> lobe_keys(store.entries().size());
  for (size_t k = 0; k < lobe_keys.size(); ++k) lobe_keys[k] = lobe_key(store.entries()[k].s, c.ggx);
  c.lobe_keys = &lobe_keys;
  const Adjacency adj = build_mesh_adjacency(mesh);
  const std::vector<uint32_t> component = connected_components(adj, &c.component_count);
  c.component = &component;
  SpreadRingCache rings_all;
  std::vector<std::vector<Lobe>> lobes_all;
  c.rings = &rings_all, c.lobe_buffers = &lobes_all;

  // 1. Choose K and the priors on an even subsample of the eligible vertices (selection_subsample).
  Context sel = selection_subsample(c, c.verts.size());
  SpreadRingCache rings_sel;
  std::vector<std::vector<Lobe>> lobes_sel;
  sel.rings = &rings_sel, sel.lobe_buffers = &lobes_sel;
  std::vector<int32_t> ones(c.n, 0);
  for (size_t v = 0; v < c.n; ++v) ones[v] = sel.eligible[v] ? 1 : 0;
  const FoldSums F = fold_sums(sel, held_rasters, ones);
  Choice choice{};
  const Config chosen = choose_configuration(sel, adj, F, held_rasters, ones, fits, R, facts, choice);
  facts.seconds_choice = seconds_from(t0);
  facts.selection_vertices = sel.verts.size();

  // 2. Refit the chosen configuration on all samples and vertices, and decide whom it rewrites.
  const std::vector<Static> S = static_sums(c, kAll);
  const Config fin = refit_on_all(c, sel, adj, S, chosen);
  const int K = fin.K;
  R.chosen_k = K;
  std::vector<double> alpha_of(size_t(K) + 1, 1.0);
  for (int m = 1; m <= K; ++m) alpha_of[size_t(m)] = fin.lobes[size_t(m)].alpha;
  const std::vector<Lobe> L = lobe_sums(c, kAll, fin.label, alpha_of);
  const std::vector<double> median_kd = median_kd_of(c, fits, fin.label, K);
  const std::vector<uint8_t> diffuse = diffuse_flags(fin.lobes, median_kd, K, mo, c.o.lobe);
  // A material is diffuse against a glossy one. Where the data pools into no glossy material at all
  // (the real photometric-stereo objects: one material whose pooled lobe explains 1-2 % of the
  // energy), there is no shared lobe to give and nothing that makes a vertex's own highlights a
  // misfit: every vertex keeps its own fit (stripping those lobes raises horse's mean / p95 from
  // 2.88 / 6.02 to 2.93 / 6.40 at its held-out lights; ctest psm_real_materials).
  facts.any_glossy = std::count(diffuse.begin() + 1, diffuse.end(), uint8_t(0)) > 0;
  facts.giving = giving_tests(sel, F, held_rasters, fin, diffuse, choice, fits, facts.any_glossy);
  const std::vector<uint8_t> rewritten = vertices_to_rewrite(c, fin, diffuse, facts.giving, fits, facts.any_glossy);
  Params P;
  solve_vertices(c, S, S, kAll, kAll, fin.label, fin.lobes, diffuse, K, {choice}, &P, &rewritten);

  // 3. Write the fits.
  count_members(c, S, L, fin, R);
  rewrite_fits(c, S, fin, diffuse, rewritten, P, diffuse_rgb, diffuse_valid, fits, R);
  describe_materials(fin, diffuse, median_kd, R);
  facts.lobes = fin.lobes;
  R.seconds = seconds_from(t0);
  R.report = material_report(R, facts, mo, o.lobe);
  return R;
}

void propagate_material_labels(const MeshView &mesh, const std::vector<VertexFit> &fits, std::vector<int32_t> &label) {
  const size_t n = std::min({mesh.vertex_count, fits.size(), label.size()});
  const Adjacency adj = build_mesh_adjacency(mesh);
  for (int pass = 0; pass < 1000; ++pass) {
    std::vector<int32_t> next = label;
    size_t changed = 0;
    for (size_t v = 0; v < n; ++v) {
      if (label[v] > 0 || !has_model(fits[v])) continue;
      std::vector<int32_t> seen;
      for (uint32_t k = adj.offsets[v]; k < adj.offsets[v + 1]; ++k)
        if (adj.neighbours[k] < n && label[adj.neighbours[k]] > 0) seen.push_back(label[adj.neighbours[k]]);
      if (seen.empty()) continue;
      std::sort(seen.begin(), seen.end());
      int32_t best = seen[0];
      size_t best_count = 0;
      for (size_t i = 0; i < seen.size();) {
        size_t j = i;
        while (j < seen.size() && seen[j] == seen[i]) ++j;
        if (j - i > best_count) best_count = j - i, best = seen[i];
        i = j;
      }
      next[v] = best, ++changed;
    }
    label.swap(next);
    if (!changed) break;
  }
}

} // namespace vbrdf
