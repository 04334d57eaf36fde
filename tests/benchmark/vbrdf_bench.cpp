// vbrdf_bench: the measuring tool behind tests/benchmark/run_benchmark.py (no MeshLab; GL through
// OSMesa, i.e. llvmpipe here).
//
//   vbrdf_bench fit --project P.mlp [--lp L.lp] [--photo-dir D] [--photos N] [--mesh M.ply]
//                   [--backend gpu|cpu|cpu-all] [--iterations N] [--heldout H.mlp [--heldout-lp L]
//                   [--heldout-photo-dir D]] [--gt GT.ply [--albedo-factors f0,f1,...]] --work DIR
//                   [--relight-dir DIR] [--name NAME] [--materials on|off] [--min-heldout-photos N]
//                   [--shading-normals on|off]
//       One configuration: runs the filter's pipeline (run_fit) timed per stage, then scores it:
//       held-out relit error in image space (relight_render.h; the held-out photos colour-corrected
//       from their chart as the fit corrects its samples) and the parameter error against a ground
//       truth. Prints "RESULT {json}" on stdout.
//       --photos N: N of the project's photos, chosen by farthest-point sampling of the light
//       directions (0 = all). --mesh: another mesh (e.g. decimated) in the project's frame; the
//       ground truth is then transferred by nearest vertex. --backend: gpu = OpenGL visibility +
//       GPU (compute shader) fit, cpu = OpenGL visibility + CPU fit, cpu-all = CPU ray-cast
//       visibility + CPU fit. --albedo-factors: per material_id factor on the GT albedo (the
//       Lambertian-equivalent albedo of a coated material, shared scenes). --materials: the
//       material stage (default: the filter's, on); --min-heldout-photos: its MaterialOptions value
//       (1: one held-out split whatever the photo count).
//   vbrdf_bench decimate --in M.ply --out O.ply --vertices N
//   vbrdf_bench srgb8 --in-dir D --out-dir D2      16-bit linear PNGs -> 8-bit sRGB PNGs
//   vbrdf_bench plot --points P.csv --out plot.png [--title T] [--x-label X] [--y-label Y]
// Exit status: 0 success, 2 bad input, 3 processing error.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <QDir>
#include <opencv2/imgcodecs.hpp>

#include "tool_errors.h"
#include "bench_mesh.h"
#include "bench_plot.h"
#include "base/color_difference.h"
#include "base/errors.h"
#include "base/file_util.h"
#include "inputs/light_file.h"
#include "tools/mesh_io.h"
#include "osmesa_context.h"
#include "io/output_ply.h"
#include "inputs/photo.h"
#include "run/fit_run.h"
#include "inputs/project.h"
#include "tools/relight.h"
#include "relight/orbit_camera.h"
#include "relight/relight_render.h"
#include "relight/relight_report.h"
#include "io/result_ply.h"
#include "visibility/visibility_gl.h"
#include "thesis_settings.h"

using namespace vbrdf;

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct Args {
  std::map<std::string, std::string> values;
  std::string get(const std::string &k, const std::string &def = "") const {
    const auto it = values.find(k);
    return it == values.end() ? def : it->second;
  }
};

Args parse(int argc, char **argv, int first) {
  Args a;
  for (int i = first; i < argc; ++i) {
    const std::string k = argv[i];
    if (k.rfind("--", 0) != 0 || i + 1 >= argc) throw InputError("bad argument '" + k + "' (expected --name value)");
    a.values[k.substr(2)] = argv[++i];
  }
  return a;
}

// Flat JSON object of numbers and strings.
class Json {
public:
  void num(const std::string &k, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", std::isfinite(v) ? v : -1.0);
    add(k, buf);
  }
  void str(const std::string &k, const std::string &v) {
    std::string q = "\"";
    for (char c : v) q += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
    add(k, q + "\"");
  }
  std::string text() const { return "{" + body_ + "}"; }

private:
  void add(const std::string &k, const std::string &v) { body_ += (body_.empty() ? "\"" : ", \"") + k + "\": " + v; }
  std::string body_;
};

// ---------------------------------------------------------------------------------------------
// Photo subsets

// Greedy farthest-point sampling of unit directions, starting from the first: a well-spread subset.
std::vector<size_t> spread_subset(const std::vector<std::array<float, 3>> &dirs, size_t count) {
  std::vector<size_t> chosen;
  if (count == 0 || count >= dirs.size()) {
    for (size_t i = 0; i < dirs.size(); ++i) chosen.push_back(i);
    return chosen;
  }
  std::vector<double> nearest(dirs.size(), 1e9);
  size_t next = 0;
  while (chosen.size() < count) {
    chosen.push_back(next);
    for (size_t i = 0; i < dirs.size(); ++i) {
      const double dot = dirs[i][0] * dirs[next][0] + dirs[i][1] * dirs[next][1] + dirs[i][2] * dirs[next][2];
      nearest[i] = std::min(nearest[i], std::acos(std::max(-1.0, std::min(1.0, dot))));
    }
    next = size_t(std::max_element(nearest.begin(), nearest.end()) - nearest.begin());
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

void use_photo_dir(std::vector<Raster> &rasters, const std::string &dir) {
  if (dir.empty()) return;
  for (Raster &r : rasters) r.image_path = join_path(dir, file_name_of(r.image_path));
}

std::string default_lp(const Project &p) {
  const std::string lp = find_default_light_file(p.rasters, p.project_path);
  if (lp.empty()) throw InputError("no .lp beside " + p.project_path + ": pass --lp");
  return lp;
}

// Keeps `count` rasters (spread lights) and writes their .lp into `work`; returns its path.
std::string subset_photos(std::vector<Raster> &rasters, const std::string &lp, size_t count, const std::string &work) {
  const auto dirs = light_directions(resolve_lights(rasters, lp, LightPlacement()));
  const std::vector<LightEntry> entries = read_light_file(lp);
  std::vector<Raster> kept;
  std::vector<LightEntry> kept_lights;
  for (size_t i : spread_subset(dirs, count)) {
    kept.push_back(rasters[i]);
    LightEntry e = entries[size_t(find_light_for_image(entries, rasters[i].image_path))];
    e.image = file_name_of(rasters[i].image_path);
    kept_lights.push_back(e);
  }
  rasters = kept;
  const std::string out = join_path(work, "lights_subset.lp");
  write_light_file(out, kept_lights);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Ground truth

struct Truth {
  std::vector<std::array<float, 3>> albedo;  // per mesh vertex (transferred)
  std::vector<float> visible, ks, shininess; // empty when absent
};

const std::vector<float> *property(const ResultPly &p, const std::string &name) {
  const auto it = p.vertex_properties.find(name);
  return it == p.vertex_properties.end() ? nullptr : &it->second;
}

std::vector<double> parse_factors(const std::string &s) {
  std::vector<double> out;
  std::stringstream ss(s);
  for (std::string cell; std::getline(ss, cell, ',');)
    if (!cell.empty()) out.push_back(std::stod(cell));
  return out;
}

Truth load_truth(const std::string &path, const MeshData &mesh, const std::string &factors_text) {
  const ResultPly gt = read_result_ply(path);
  const auto *r = property(gt, "albedo_r"), *g = property(gt, "albedo_g"), *b = property(gt, "albedo_b");
  if (!r || !g || !b) throw InputError("ground truth " + path + " has no albedo_r/g/b");
  const size_t n = mesh.positions.size() / 3;
  std::vector<size_t> map(n);
  const bool same = gt.mesh.positions == mesh.positions;
  if (same)
    for (size_t v = 0; v < n; ++v) map[v] = v;
  else
    map = bench::nearest_vertices(gt.mesh.view(), mesh.view());
  const std::vector<double> factors = parse_factors(factors_text);
  const auto *material = property(gt, "material_id");
  const auto *visible = property(gt, "visible") ? property(gt, "visible") : property(gt, "visible_any");
  const auto *ks = property(gt, "ks"), *shininess = property(gt, "shininess");
  Truth t;
  for (size_t v = 0; v < n; ++v) {
    const size_t s = map[v];
    double f = 1;
    if (material && !factors.empty()) f = factors[std::min(factors.size() - 1, size_t(std::max(0.0f, (*material)[s])))];
    t.albedo.push_back({{float((*r)[s] * f), float((*g)[s] * f), float((*b)[s] * f)}});
    if (visible) t.visible.push_back((*visible)[s]);
    if (ks && shininess) t.ks.push_back((*ks)[s]), t.shininess.push_back((*shininess)[s]);
  }
  return t;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return -1;
  const size_t k = std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + long(k), v.end());
  return v[k];
}

double mean(const std::vector<double> &v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? -1 : s / double(v.size());
}

// Diffuse reflectance k_d C against the GT albedo after one global least-squares scale (absolute
// irradiance and exposure are unknown), over GT-visible fitted vertices; k_s and shininess on
// glossy vertices (GT k_s > 0.2) with a full fit from >= 2 clean highlight samples (`n_specular`),
// as tests/e2e/check_output.py counts them (fits freed by the broad-lobe rule trade k_s against
// alpha and are only counted in glossy_full).
void parameter_errors(const std::vector<VertexFit> &fits, const std::vector<float> &n_specular, const Truth &t,
                      Json &out) {
  std::vector<size_t> set;
  size_t gt_visible = 0;
  for (size_t v = 0; v < fits.size(); ++v) {
    const bool vis = t.visible.empty() || t.visible[v] > 0.5f;
    gt_visible += vis;
    if (vis && fits[v].status != kFitNone) set.push_back(v);
  }
  double num = 0, den = 0;
  for (size_t v : set)
    for (int c = 0; c < 3; ++c) {
      const double e = double(fits[v].kd) * fits[v].color[c];
      num += e * t.albedo[v][size_t(c)], den += e * e;
    }
  const double scale = den > 0 ? num / den : 1;
  std::vector<double> de, ks_rel, alpha_rel;
  size_t glossy = 0, glossy_full = 0;
  for (size_t v : set) {
    float est[3];
    for (int c = 0; c < 3; ++c) est[c] = float(scale * fits[v].kd * fits[v].color[c]);
    de.push_back(delta_e2000_linear_srgb(est, t.albedo[v].data()));
    if (t.ks.empty() || !(t.ks[v] > 0.2f)) continue;
    ++glossy;
    if (fits[v].status != kFitFull) continue;
    ++glossy_full;
    if (n_specular.size() == fits.size() && n_specular[v] < 2) continue;
    ks_rel.push_back(std::fabs(fits[v].ks - t.ks[v]) / t.ks[v]);
    alpha_rel.push_back(std::fabs(fits[v].shininess - t.shininess[v]) / std::max(1e-6f, t.shininess[v]));
  }
  out.num("gt_visible", double(gt_visible));
  out.num("coverage", gt_visible ? double(set.size()) / double(gt_visible) : 0);
  out.num("rho_scale", scale);
  out.num("rho_de_mean", mean(de));
  out.num("rho_de_p95", percentile(de, 0.95));
  if (t.ks.empty()) return;
  out.num("glossy", double(glossy));
  out.num("glossy_full", double(glossy_full));
  out.num("glossy_determined", double(ks_rel.size()));
  out.num("ks_rel_median", percentile(ks_rel, 0.5));
  out.num("alpha_rel_median", percentile(alpha_rel, 0.5));
}

// ---------------------------------------------------------------------------------------------
// fit

struct HeldOut {
  std::vector<Raster> rasters;
  std::vector<LightSource> lights;
};

HeldOut load_heldout(const Args &a, const MeshData &mesh) {
  HeldOut h;
  Project p = read_project(a.get("heldout"));
  const std::string lp = a.get("heldout-lp").empty() ? default_lp(p) : a.get("heldout-lp");
  const MeshView view = mesh.view();
  h.lights = resolve_lights(p.rasters, lp, light_placement_of(view, 0.0f, 0.0f));
  use_photo_dir(p.rasters, a.get("heldout-photo-dir"));
  h.rasters = p.rasters;
  return h;
}

// Held-out relit error two ways: image space over the lit interior pixels (relit_*: silhouettes
// and depth jumps left out), and over the whole visible surface as RTI tools are judged (ws_*:
// every seen, lit, unsaturated vertex sample, the held-out photo sampled bilinearly at the
// vertex's pixel, vertices without a model black) beside per-pixel PTM and Relight-style RBF fitted
// on the training photos of the same camera and scored on the same samples (relight.h).
// `lobe`, `diffuse`: the forms the fit used (FitSettings::reflectance.lobe, FitResult::diffuse_forms), and
// `deconvolved` its FitResult::albedo_deconvolved:
// the renderer and the sample-based evaluation must evaluate the model the fit made.
void evaluate_heldout(const Args &a, const MeshData &mesh, const std::vector<VertexFit> &fits, LobeForm lobe,
                      const DiffuseForms &diffuse, const std::vector<uint8_t> &deconvolved,
                      const std::vector<Raster> &training,
                      const std::vector<LightSource> &training_lights, const GetProcAddressFn &get_proc, Json &out) {
  const HeldOut h = load_heldout(a, mesh);
  const auto t = Clock::now();
  RelightRenderSettings render_settings = vbrdf::test::thesis_render_settings();
  render_settings.lobe = lobe;
  render_settings.diffuse = diffuse;
  RelightRenderer renderer(mesh.view(), fits, get_proc, render_settings);
  RelightOutputOptions options;
  options.folder = a.get("relight-dir");
  const RelightReport report = relight_rasters(renderer, h.rasters, h.lights, options);
  const PixelComparison &c = report.overall.comparison;
  out.num("heldout_photos", double(h.rasters.size()));
  out.num("relit_pixels", double(c.pixels));
  out.num("relit_mean", c.mean_de2000);
  out.num("relit_median", c.median_de2000);
  out.num("relit_p95", c.p95_de2000);
  out.num("relit_psnr", c.psnr_db);
  std::vector<cv::Mat> rendered;
  for (size_t r = 0; r < h.rasters.size(); ++r)
    rendered.push_back(render_as_photographed(renderer, h.rasters[r].shot, h.lights[r]));
  auto visibility = make_gl_visibility(mesh.view(), get_proc, VisibilitySettings());
  RelightOptions ro = vbrdf::test::thesis_relight_options();
  ro.gather.lobe = lobe;  // the samples' lobe cosine and diffuse factor in the fit's forms
  ro.gather.diffuse = diffuse;
  ro.rendered = &rendered;
  if (!deconvolved.empty()) ro.diffuse_deconvolved = &deconvolved;  // albedo seen through the footprints
  ro.training_rasters = &training;
  ro.training_lights = &training_lights;
  const RelightStats ws = evaluate_relighting(mesh.view(), fits, h.rasters, h.lights, *visibility, ro);
  out.num("ws_samples", double(ws.samples));
  out.num("ws_mean", ws.mean_de2000);
  out.num("ws_p95", ws.p95_de2000);
  out.num("ws_unmodelled_vertices", double(ws.seen_unmodelled_vertices));
  out.num("ptm_mean", ws.ptm.mean);
  out.num("ptm_p95", ws.ptm.p95);
  out.num("rbf_mean", ws.rbf.mean);
  out.num("rbf_p95", ws.rbf.p95);
  out.num("t_eval", since(t));
}

FitSettings settings_for(const Args &a, const std::string &work, const std::string &lp) {
  FitSettings s;
  const std::string backend = a.get("backend", "gpu");
  if (backend != "gpu" && backend != "cpu" && backend != "cpu-all")
    throw InputError("--backend must be gpu, cpu or cpu-all (got '" + backend + "')");
  s.fit_backend = backend == "gpu" ? FitBackendChoice::GPU : FitBackendChoice::CPU;
  s.visibility_choice = backend == "cpu-all" ? VisibilityChoice::CPU : VisibilityChoice::GL;
  if (!a.get("iterations").empty()) s.reflectance.max_iterations = std::stoi(a.get("iterations"));  // else the filter's default
  const std::string materials = a.get("materials", s.materials ? "on" : "off");
  if (materials != "on" && materials != "off") throw InputError("--materials must be on or off (got '" + materials + "')");
  s.materials = materials == "on";
  const std::string normals = a.get("shading-normals", s.shading_normals.enabled ? "on" : "off");
  if (normals != "on" && normals != "off") throw InputError("--shading-normals must be on or off (got '" + normals + "')");
  s.shading_normals.enabled = normals == "on";
  if (!a.get("normal-min-gain").empty()) s.shading_normals.min_gain = std::stof(a.get("normal-min-gain"));
  if (!a.get("min-heldout-photos").empty()) s.material_options.min_heldout_photos = size_t(std::stoul(a.get("min-heldout-photos")));
  s.light_file = lp;
  s.output_ply = join_path(work, "fit.ply");
  return s;
}

int cmd_fit(const Args &a) {
  const std::string work = a.get("work");
  if (work.empty() || !QDir().mkpath(QString::fromStdString(work))) throw InputError("--work DIR is required");
  Project project = read_project(a.get("project"));
  const std::string mesh_path = a.get("mesh", project.mesh_path);
  const MeshData mesh = load_mesh_ply(mesh_path);
  std::string lp = a.get("lp").empty() ? default_lp(project) : a.get("lp");
  use_photo_dir(project.rasters, a.get("photo-dir"));
  const size_t photos = size_t(std::stoul(a.get("photos", "0")));
  if (photos > 0 && photos < project.rasters.size()) lp = subset_photos(project.rasters, lp, photos, work);
  const FitSettings settings = settings_for(a, work, lp);

  FitInput input;
  input.mesh = mesh.view();
  input.mesh_name = input.mesh_path = mesh_path;
  input.mesh_colors = mesh.colors;
  input.rasters = project.rasters;
  input.project_path = project.project_path;
  validate_input(input);

  test::OsMesaContext gl;
  const GetProcAddressFn get_proc = gl.get_proc_address();
  const LogFn quiet = [](const std::string &) {};
  auto t = Clock::now();
  auto visibility = make_visibility_backend(input.mesh, settings.visibility_choice, settings.visibility, get_proc, quiet);
  auto fitter = make_reflectance_fitter(settings.fit_backend, get_proc, quiet);
  const double t_init = since(t);
  t = Clock::now();
  const FitResult r = run_fit(input, settings, *visibility, fitter.get(), {}, quiet);
  const double t_run = since(t);

  Json out;
  out.str("name", a.get("name", project.project_path));
  out.num("vertices", double(mesh.positions.size() / 3));
  out.num("photos", double(project.rasters.size()));
  out.str("backend", a.get("backend", "gpu"));
  out.num("iterations", settings.reflectance.max_iterations);
  out.str("visibility_backend", r.visibility_backend);
  out.str("fit_backend", r.fit_backend);
  out.num("t_init", t_init);
  out.num("t_prepare", std::max(0.0, t_run - r.seconds_visibility - r.seconds_gather - r.seconds_output));
  out.num("t_visibility", r.seconds_visibility);
  out.num("t_gather", r.seconds_gather - r.seconds_fit);
  out.num("t_fit", r.seconds_fit);
  out.num("t_output", r.seconds_output);
  out.num("t_total", t_init + t_run);
  out.num("samples", double(r.gather.stored));
  out.num("full_fits", double(r.fit_full));
  out.num("diffuse_only_fits", double(r.fit_diffuse_only));
  out.num("converged", double(r.fit_converged));
  out.num("alpha_iterations", double(r.fit_iterations));
  out.num("t_normals", r.seconds_normals);
  MeshData shaded = mesh;  // the model is evaluated with the normals it was fitted with (the PLY's nx ny nz)
  if (r.shading_normals.size() == shaded.normals.size()) shaded.normals = r.shading_normals;
  if (!a.get("heldout").empty())
    evaluate_heldout(a, shaded, r.fits, settings.reflectance.lobe, r.diffuse_forms, r.albedo_deconvolved, input.rasters,
                     resolve_lights(input.rasters, r.light_file,
                                    light_placement_of(mesh.view(), 0.0f, 0.0f)),
                     get_proc, out);
  if (!a.get("gt").empty()) {
    std::vector<float> n_specular;
    for (const VertexAttribute &attr : r.attributes)
      if (attr.name == "n_specular") n_specular = attr.values;
    parameter_errors(r.fits, n_specular, load_truth(a.get("gt"), mesh, a.get("albedo-factors")), out);
  }
  std::cout << "RESULT " << out.text() << std::endl;
  return 0;
}

// ---------------------------------------------------------------------------------------------
// decimate, srgb8, plot

int cmd_decimate(const Args &a) {
  const MeshData in = load_mesh_ply(a.get("in"), true);
  const MeshData out = bench::decimate(in, size_t(std::stoul(a.get("vertices"))));
  const size_t n = out.positions.size() / 3;
  write_result_ply(a.get("out"), out.view(), std::vector<uint8_t>(4 * n, 255), {});
  std::cout << "decimated " << in.positions.size() / 3 << " -> " << n << " vertices, " << out.indices.size() / 3
            << " faces\n";
  return 0;
}

int cmd_srgb8(const Args &a) {
  const QDir in(QString::fromStdString(a.get("in-dir")));
  const std::string out_dir = a.get("out-dir");
  if (!in.exists() || out_dir.empty() || !QDir().mkpath(QString::fromStdString(out_dir)))
    throw InputError("--in-dir must exist and --out-dir be creatable");
  int count = 0;
  for (const QString &name : in.entryList(QStringList() << "*.png", QDir::Files, QDir::Name)) {
    const std::string src = in.filePath(name).toStdString();
    const cv::Mat m = cv::imread(src, cv::IMREAD_UNCHANGED);
    if (m.empty() || m.depth() != CV_16U || m.channels() != 3) throw InputError(src + " is not a 16-bit RGB PNG");
    cv::Mat out(m.size(), CV_8UC3);
    for (int y = 0; y < m.rows; ++y)
      for (int x = 0; x < 3 * m.cols; ++x)
        out.ptr<uint8_t>(y)[x] = uint8_t(std::lround(255.0f * linear_to_srgb(m.ptr<uint16_t>(y)[x] / 65535.0f)));
    write_png_atomically(join_path(out_dir, name.toStdString()), out);
    ++count;
  }
  std::cout << "converted " << count << " photos\n";
  return 0;
}

int cmd_plot(const Args &a) {
  bench::PlotOptions o;
  o.title = a.get("title");
  o.x_label = a.get("x-label", "time (s, log scale)");
  o.y_label = a.get("y-label", "error");
  write_png_atomically(a.get("out"), bench::draw_scatter(bench::read_plot_points(a.get("points")), o));
  return 0;
}

int usage() {
  std::cerr << "usage: vbrdf_bench fit|decimate|srgb8|plot --option value ... (see the top of vbrdf_bench.cpp)\n";
  return 2;
}

} // namespace

int main(int argc, char **argv) {
  if (argc < 2) return usage();
  const std::string cmd = argv[1];
  const std::map<std::string, std::function<int(const Args &)>> commands = {
      {"fit", cmd_fit}, {"decimate", cmd_decimate}, {"srgb8", cmd_srgb8}, {"plot", cmd_plot}};
  const auto it = commands.find(cmd);
  if (it == commands.end()) return usage();
  return test::run_tool([&]() -> int {
    return it->second(parse(argc, argv, 2));
  });
}
