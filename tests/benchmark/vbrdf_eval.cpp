// vbrdf_eval: scores a fit result (the PLY written by the filter) on photos held out from the fit,
// over the whole visible surface (the RTI protocol): every held-out sample that is seen, lit
// (not shadowed, N.L > 0) and unsaturated, the photo sampled bilinearly at the vertex's pixel,
// mixed (silhouette / contact) pixels included; vertices without a model (fit_status 0) are
// predicted black, as relighting the PLY shows them. Relit CIEDE2000 (mean, median, p95) and PSNR.
// Beside it, labelled, the former measure "clean pixels, modelled vertices only", and how many
// scored samples and seen vertices have no model. With --training, per-pixel PTM and
// Relight-style RBF baselines are fitted at each vertex's pixel on the training photos of the same
// camera (plain bilinear, shadowed kept, saturated dropped) and scored on the same samples.
//   vbrdf_eval --result fit.ply --project heldout/project.mlp [--lp heldout/lights.lp|.json|.dome]
//              [--dome-radius R] [--light-unit-scale S]
//              [--photo-dir DIR] [--visibility gl|cpu]
//              [--training train/project.mlp [--training-lp L] [--training-photo-dir DIR]]
//              [--gt-visible gt_vertex.ply]
//              [--max-mean-de X] [--max-p95-de Y] [--max-clean-mean-de X] [--max-clean-p95-de Y]
//              [--below-baselines]
// --lp / --training-lp: any light file the fit reads (light_source.h: .lp directions, .json
//   positions, Relight .dome); --dome-radius / --light-unit-scale as the fit's domeRadius /
//   lightUnitScale. Point lights: the product predicts with their fall-off; the per-pixel baselines
//   use one direction per photo (from the object's centre), as RTI tools do.
// --photo-dir / --training-photo-dir: take each raster's photo (same file name) from DIR instead
//   (e.g. 16-bit linear/).
// --predict: how the product predicts a held-out sample. render (default): as the camera records
// it (relight.h RelightOptions::rendered): the vertex's model where its pixel footprint shows its
// own surface, the model rendered with 4x4 subpixels where it covers background or another surface
// (silhouettes, contacts), and at vertices whose albedo was deconvolved (diffuse_deconvolved = 1) the
// diffuse reflectance seen through the footprint (tools/relight.h RelightOptions::diffuse_deconvolved);
// vertex: the vertex's model alone (ignores what else the footprint covers).
// --gt-lit: ground-truth lit flags per held-out light (load_lit below) instead of our shadow passes.
// --samples-csv FILE: every scored sample (vertex, held-out photo, fit_status, mixed footprint, diffuse
//   factor, observed and predicted linear RGB, CIEDE2000 of the product, PTM and RBF: -1 where not
//   scored), to locate the error (e.g. tests/tools/error_map.py).
// --footprint on|off: predict the GGX lobe through each held-out photo's pixel footprint
//   (samples/footprint.h; on, as the fit does) or at the vertex alone (a fit made with it off).
// --gt-visible: score only vertices whose uchar `visible` property (ground-truth PLY, same vertex
//   order as the result) is non-zero.
// --max-mean-de / --max-p95-de: bounds on the whole-surface product figure.
// --max-clean-mean-de / --max-clean-p95-de: bounds on the labelled "clean pixels, modelled vertices
//   only" figure (the former measure; the e2e tests gate on it until every seen vertex has a model).
// --below-baselines: fail unless the product's mean and p95 are below both PTM's and RBF's on the
//   common sample set (needs --training).
// Exit status 1 when a bound is exceeded (or nothing was scored), 2 on bad input.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>

#include "tool_errors.h"
#include "base/errors.h"
#include "base/file_util.h"
#include "inputs/light_file.h"
#include "osmesa_context.h"
#include "run/fit_run.h"
#include "inputs/project.h"
#include "tools/relight.h"
#include "relight/relight_render.h"
#include "io/result_ply.h"
#include "visibility/visibility_gl.h"
#include "thesis_settings.h"

using namespace vbrdf;

namespace {
void write_samples_csv(const std::string &path, const std::vector<ScoredSample> &samples,
                       const std::vector<Raster> &rasters) {
  std::ofstream out(path);
  if (!out) throw InputError("--samples-csv: cannot write '" + path + "'.");
  out << "vertex,photo,fit_status,mixed,d,obs_r,obs_g,obs_b,pred_r,pred_g,pred_b,de,de_ptm,de_rbf\n";
  for (const ScoredSample &s : samples) {
    out << s.vertex << ',' << rasters[s.raster].label << ',' << int(s.fit_status) << ',' << int(s.mixed) << ','
        << s.d;
    for (float v : s.observed) out << ',' << v;
    for (float v : s.predicted) out << ',' << v;
    out << ',' << s.de << ',' << s.de_ptm << ',' << s.de_rbf << '\n';
  }
  if (!out) throw InputError("--samples-csv: writing '" + path + "' failed.");
}

struct Photos {
  Project project;
  std::vector<LightSource> lights;
};

Photos load_photos(const std::string &mlp, std::string lp, const std::string &photo_dir, const LightPlacement &placement) {
  Photos p{read_project(mlp), {}};
  if (p.project.rasters.empty()) throw InputError(mlp + " has no raster");
  if (lp.empty()) lp = find_default_light_file(p.project.rasters, p.project.project_path);
  p.lights = resolve_lights(p.project.rasters, lp, placement);
  if (!photo_dir.empty())
    for (Raster &r : p.project.rasters) r.image_path = join_path(photo_dir, file_name_of(r.image_path));
  return p;
}

std::vector<uint8_t> load_visible(const std::string &path, const MeshData &mesh) {
  const ResultPly gt = read_result_ply(path);
  const auto it = gt.vertex_properties.find("visible");
  if (it == gt.vertex_properties.end()) throw InputError(path + " has no vertex property 'visible'");
  const size_t n = mesh.positions.size() / 3;
  if (it->second.size() != n || gt.mesh.positions.size() != mesh.positions.size())
    throw InputError(path + " has " + std::to_string(it->second.size()) + " vertices, the result " + std::to_string(n));
  float extent = 0, worst = 0;
  for (size_t k = 0; k < mesh.positions.size(); ++k) {
    extent = std::max(extent, std::fabs(mesh.positions[k]));
    worst = std::max(worst, std::fabs(mesh.positions[k] - gt.mesh.positions[k]));
  }
  // Another vertex order moves vertices by about the object's size; a scan's copy of the mesh
  // (decimated and resampled, vbrdf_perturb_mesh) by a small fraction of it.
  if (!(worst <= 0.02f * std::max(extent, 1e-6f)))
    throw InputError(path + ": vertex positions differ from the result's (another vertex order?)");
  std::vector<uint8_t> visible(n);
  for (size_t v = 0; v < n; ++v) visible[v] = it->second[v] != 0;
  return visible;
}

// Ground-truth "lit" per held-out light and vertex: a text file whose first line is
// "<vertices> <lights>", then one line per vertex of <lights> characters '0'/'1' (light order =
// the held-out project's rasters). tests/benchmark/whole_surface_eval.sh writes it from the
// scenes' gt_vertex.npz (heldout_lit). Returned raster-major, as RelightOptions::lit_filter.
std::vector<uint8_t> load_lit(const std::string &path, size_t vertices, size_t rasters) {
  std::ifstream in(path);
  size_t n = 0, h = 0;
  if (!(in >> n >> h)) throw InputError(path + ": expected '<vertices> <lights>' on the first line");
  if (n != vertices || h != rasters)
    throw InputError(path + " is for " + std::to_string(n) + " vertices x " + std::to_string(h) + " lights; the result has " +
                     std::to_string(vertices) + " vertices and the held-out project " + std::to_string(rasters) + " photos");
  std::vector<uint8_t> lit(n * h, 0);
  std::string line;
  for (size_t v = 0; v < n; ++v) {
    if (!(in >> line) || line.size() != h) throw InputError(path + ": line " + std::to_string(v + 2) + " is not " +
                                                            std::to_string(h) + " characters of 0/1");
    for (size_t r = 0; r < h; ++r) lit[r * n + v] = line[r] == '1';
  }
  return lit;
}

void row(const char *name, const ErrorSummary &s) {
  std::printf("  %-44s %9zu %8.3f %8.3f %8.3f\n", name, s.samples, s.mean, s.median, s.p95);
}
} // namespace

int main(int argc, char **argv) {
  std::string result_path, mlp, lp, photo_dir, backend = "gl", train_mlp, train_lp, train_photo_dir, gt_path,
      gt_lit_path, predict = "render", samples_csv;
  double max_mean = -1, max_p95 = -1, max_clean_mean = -1, max_clean_p95 = -1;
  float dome_radius = 0, light_unit_scale = 0;
  bool below_baselines = false;
  bool footprint = true;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--below-baselines") {
      below_baselines = true;
      continue;
    }
    if (i + 1 >= argc) {
      std::cerr << "error: " << a << " needs a value\n";
      return 2;
    }
    const std::string v = argv[++i];
    if (a == "--result") result_path = v;
    else if (a == "--project") mlp = v;
    else if (a == "--lp") lp = v;
    else if (a == "--photo-dir") photo_dir = v;
    else if (a == "--dome-radius") dome_radius = std::stof(v);
    else if (a == "--light-unit-scale") light_unit_scale = std::stof(v);
    else if (a == "--visibility") backend = v;
    else if (a == "--training") train_mlp = v;
    else if (a == "--training-lp") train_lp = v;
    else if (a == "--training-photo-dir") train_photo_dir = v;
    else if (a == "--gt-visible") gt_path = v;
    else if (a == "--gt-lit") gt_lit_path = v;
    else if (a == "--samples-csv") samples_csv = v;
    else if (a == "--predict") predict = v;
    else if (a == "--footprint") footprint = v == "on";
    else if (a == "--max-mean-de") max_mean = std::stod(v);
    else if (a == "--max-p95-de") max_p95 = std::stod(v);
    else if (a == "--max-clean-mean-de") max_clean_mean = std::stod(v);
    else if (a == "--max-clean-p95-de") max_clean_p95 = std::stod(v);
    else {
      std::cerr << "error: unknown option " << a << "\n";
      return 2;
    }
  }
  if (result_path.empty() || mlp.empty() || (below_baselines && train_mlp.empty())) {
    std::cerr << "usage: vbrdf_eval --result fit.ply --project heldout/project.mlp [--lp F] [--photo-dir D]\n"
                 "                  [--dome-radius R] [--light-unit-scale S]\n"
                 "                  [--visibility gl|cpu] [--training train.mlp [--training-lp F]\n"
                 "                  [--training-photo-dir D]] [--gt-visible gt_vertex.ply] [--gt-lit lit.txt]\n"
                 "                  [--predict render|vertex] [--footprint on|off]\n"
                 "                  [--max-mean-de X] [--max-p95-de Y] [--max-clean-mean-de X] [--max-clean-p95-de Y]\n"
                 "                  [--below-baselines (needs --training)]\n";
    return 2;
  }
  return test::run_tool([&]() -> int {
    const ResultPly result = read_result_ply(result_path);
    LobeForm lobe = LobeForm::PhongRE;
    DiffuseForms diffuse;
    std::vector<uint8_t> deconvolved;
    const std::vector<VertexFit> fits = fits_from_result(result, result_path, &lobe, &diffuse, &deconvolved);
    const MeshView mesh_view = result.mesh.view();
    const LightPlacement placement =
        light_placement_of(mesh_view, dome_radius, light_unit_scale);
    const Photos heldout = load_photos(mlp, lp, photo_dir, placement);
    Photos training;
    RelightOptions options = vbrdf::test::thesis_relight_options();
    options.gather.lobe = lobe;  // the samples' lobe cosine in the form the fit used
    options.gather.diffuse = diffuse;  // and their diffuse factor
    options.gather.footprint = footprint;
    if (!train_mlp.empty()) {
      training = load_photos(train_mlp, train_lp, train_photo_dir, placement);
      options.training_rasters = &training.project.rasters;
      options.training_lights = &training.lights;
    }
    std::vector<uint8_t> visible;
    if (!gt_path.empty()) {
      visible = load_visible(gt_path, result.mesh);
      options.vertex_filter = &visible;
    }
    std::vector<uint8_t> lit;
    if (!gt_lit_path.empty()) {
      lit = load_lit(gt_lit_path, result.mesh.view().vertex_count, heldout.project.rasters.size());
      options.lit_filter = &lit;
    }
    std::unique_ptr<test::OsMesaContext> context;
    std::unique_ptr<VisibilityBackend> visibility;
    if (backend == "gl") {
      context.reset(new test::OsMesaContext());
      visibility = make_gl_visibility(result.mesh.view(), context->get_proc_address(), VisibilitySettings());
    } else {
      visibility = make_cpu_visibility(result.mesh.view(), VisibilitySettings());
    }
    std::vector<cv::Mat> rendered;
    std::unique_ptr<RelightRenderer> renderer;
    if (predict == "render") {
      if (!context) context.reset(new test::OsMesaContext());
      RelightRenderSettings render_settings = vbrdf::test::thesis_render_settings();
      render_settings.lobe = lobe;
      render_settings.diffuse = diffuse;
      renderer.reset(new RelightRenderer(result.mesh.view(), fits, context->get_proc_address(), render_settings));
      for (size_t r = 0; r < heldout.project.rasters.size(); ++r)
        rendered.push_back(render_as_photographed(*renderer, heldout.project.rasters[r].shot, heldout.lights[r]));
      options.rendered = &rendered;
      options.diffuse_deconvolved = &deconvolved;  // their albedo as each camera records it
    } else if (predict != "vertex") {
      throw InputError("--predict takes 'render' or 'vertex'");
    }
    std::vector<ScoredSample> per_sample;
    if (!samples_csv.empty()) options.per_sample = &per_sample;
    const RelightStats s =
        evaluate_relighting(result.mesh.view(), fits, heldout.project.rasters, heldout.lights, *visibility, options);

    const auto &rasters = heldout.project.rasters;
    if (!samples_csv.empty()) write_samples_csv(samples_csv, per_sample, rasters);
    std::printf("relit on %zu held-out photos%s; scored vertices: %s; lit as %s says\n", rasters.size(),
                s.has_baselines ? ", baselines from the training photos of the same camera" : "",
                gt_path.empty() ? "all" : "ground-truth visible",
                gt_lit_path.empty() ? "our shadow passes" : "the ground truth");
    std::printf("  %-44s %9s %8s %8s %8s\n", "CIEDE2000", "samples", "mean", "median", "p95");
    row("whole surface: product", ErrorSummary{s.samples, s.mean_de2000, s.median_de2000, s.p95_de2000});
    if (s.has_baselines) {
      row("  same samples with training data: product", s.product_on_baseline_set);
      row("  same samples: PTM (per pixel)", s.ptm);
      row("  same samples: RBF (per pixel, Relight-style)", s.rbf);
      row("  clean footprint: product", s.product_clean_footprint);
      row("  clean footprint: RBF", s.rbf_clean_footprint);
      row("  mixed footprint (silhouette/contact): product", s.product_mixed_footprint);
      row("  mixed footprint (silhouette/contact): RBF", s.rbf_mixed_footprint);
      std::printf("  (%zu whole-surface samples without training data are excluded from these three rows)\n",
                  s.baseline_excluded);
    }
    row("clean pixels, modelled vertices only: product", s.clean_modelled);
    std::printf("  whole-surface PSNR %.2f dB\n", s.psnr_db);
    std::printf("  scored samples at vertices without a model: %zu (%.1f %%); seen vertices without a model: %zu of %zu\n",
                s.unmodelled_samples, 100.0 * s.unmodelled_share, s.seen_unmodelled_vertices, s.seen_vertices);
    for (size_t r = 0; r < rasters.size(); ++r)
      std::printf("  %-32s %7zu samples, mean CIEDE2000 %.3f%s\n", rasters[r].label.c_str(), s.per_raster_samples[r],
                  s.per_raster_mean_de2000[r],
                  s.has_baselines && s.rbf_sigma_per_raster[r] == 0 ? " (no training photo of this camera)" : "");

    bool ok = s.samples > 0;
    if (!ok) std::printf("FAIL: no sample scored\n");
    if (max_mean >= 0 && s.mean_de2000 > max_mean) ok = false, std::printf("FAIL: mean %.3f > %.3f\n", s.mean_de2000, max_mean);
    if (max_p95 >= 0 && s.p95_de2000 > max_p95) ok = false, std::printf("FAIL: p95 %.3f > %.3f\n", s.p95_de2000, max_p95);
    const ErrorSummary &c = s.clean_modelled;
    if (max_clean_mean >= 0 && !(c.samples > 0 && c.mean <= max_clean_mean))
      ok = false, std::printf("FAIL: clean-pixel mean %.3f > %.3f\n", c.mean, max_clean_mean);
    if (max_clean_p95 >= 0 && !(c.samples > 0 && c.p95 <= max_clean_p95))
      ok = false, std::printf("FAIL: clean-pixel p95 %.3f > %.3f\n", c.p95, max_clean_p95);
    if (below_baselines) {
      const ErrorSummary &p = s.product_on_baseline_set;
      for (const auto &b : {std::make_pair("PTM", s.ptm), std::make_pair("RBF", s.rbf)}) {
        if (p.samples == 0 || !(p.mean < b.second.mean) || !(p.p95 < b.second.p95)) {
          ok = false;
          std::printf("FAIL: product mean/p95 %.3f/%.3f not below %s's %.3f/%.3f\n", p.mean, p.p95, b.first,
                      b.second.mean, b.second.p95);
        }
      }
    }
    return ok ? 0 : 1;
  });
}
