// bench_fit: time and accuracy of the per-vertex reflectance fit (CPU reference vs GPU compute shader)
// on synthetic samples with known parameters, for several iteration caps.
//   bench_fit [--vertices 100000] [--photos 32] [--backend cpu|gpu|both] [--caps 1,2,5,10,20,50,400]
//             [--noise 0.02] [--seed 1] [--csv file]
// Scene (a relief seen from the front): vertex normals in a 40-degree cone around +z; per photo a
// camera in a 40-degree cone and a light within 25 degrees of it, so a vertex shows highlights in
// the photos whose half-vector is near its normal (about 2-3 per vertex at 32 photos). About 60 %
// of photos see a vertex; 5 % of the seen samples are in cast shadow; clipped pixels are flagged
// saturated. Materials: k_d 0.05-0.6 with a random colour, k_s 0.05-0.5 (75 %) or 0, alpha 5-300
// log-uniform; relative Gaussian noise plus a small absolute floor.
// Errors (over vertices whose fit is full and whose true k_s > 0): median relative error of rho
// (per channel, relative to max rho), k_s and alpha; model RMSE: sqrt(sum w |f_fit - f_true|^2 /
// (3 sum w)) over usable samples of every fitted vertex (noise-free truth, so it measures the fit,
// not the noise).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "base/errors.h"
#include "osmesa_context.h"
#include "fit/reflectance_fit.h"
#include "fit/reflectance_fit_gpu.h"
#include "thesis_settings.h"

using namespace vbrdf;

namespace {

struct Args {
  uint32_t vertices = 100000;
  int photos = 32;
  std::string backend = "both";
  std::vector<int> caps = {1, 2, 5, 10, 20, 50, 400};
  float noise = 0.02f;
  unsigned seed = 1;
  std::string csv;
};

struct Truth {
  float rho[3];
  float ks, alpha;
};

struct V3 {
  float x, y, z;
};
V3 operator*(V3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
float dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 normalized(V3 a) { return a * (1.0f / std::sqrt(dot(a, a))); }

// Uniform direction in the cone of half-angle `max_angle` around +z.
V3 cone_direction(std::mt19937 &rng, float max_angle) {
  std::uniform_real_distribution<float> u(0, 1);
  const float z = 1 - u(rng) * (1 - std::cos(max_angle)), phi = 6.2831853f * u(rng);
  const float r = std::sqrt(std::max(0.0f, 1 - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Rotates `d` by up to `max_angle` towards a random direction (light near the camera).
V3 perturbed(V3 d, std::mt19937 &rng, float max_angle) {
  const V3 c = cone_direction(rng, max_angle);
  // Frame with d as its z axis.
  const V3 helper = std::fabs(d.x) < 0.6f ? V3{1, 0, 0} : V3{0, 1, 0};
  V3 x = normalized(V3{helper.y * d.z - helper.z * d.y, helper.z * d.x - helper.x * d.z,
                       helper.x * d.y - helper.y * d.x});
  const V3 y{d.y * x.z - d.z * x.y, d.z * x.x - d.x * x.z, d.x * x.y - d.y * x.x};
  return normalized(V3{x.x * c.x + y.x * c.y + d.x * c.z, x.y * c.x + y.y * c.y + d.y * c.z,
                       x.z * c.x + y.z * c.y + d.z * c.z});
}

Truth random_material(std::mt19937 &rng) {
  std::uniform_real_distribution<float> u(0, 1);
  Truth t;
  const float kd = 0.05f + 0.55f * u(rng);
  const int main_channel = int(u(rng) * 3) % 3;
  for (int c = 0; c < 3; ++c) t.rho[c] = kd * (c == main_channel ? 1.0f : 0.2f + 0.8f * u(rng));
  t.ks = u(rng) < 0.25f ? 0.0f : 0.05f + 0.45f * u(rng);
  t.alpha = 5.0f * std::exp(u(rng) * std::log(60.0f));
  return t;
}

void true_model(const Truth &t, float d, float s, float out[3]) {
  const float g = (d > 0 && s > 0) ? std::pow(std::min(s, 1.0f), t.alpha) : 0.0f;
  for (int c = 0; c < 3; ++c) out[c] = t.rho[c] * std::max(d, 0.0f) + t.ks * g;
}

void make_scene(const Args &a, SampleChunk &chunk, std::vector<Truth> &truth) {
  std::mt19937 rng(a.seed);
  std::uniform_real_distribution<float> u(0, 1);
  std::normal_distribution<float> gauss(0, 1);
  std::vector<V3> cams(size_t(a.photos)), lights(size_t(a.photos));
  for (int p = 0; p < a.photos; ++p) {
    cams[size_t(p)] = cone_direction(rng, 0.70f);
    lights[size_t(p)] = perturbed(cams[size_t(p)], rng, 0.44f);
  }
  chunk = SampleChunk();
  chunk.vertex_count = a.vertices;
  chunk.offsets.reserve(a.vertices + 1);
  chunk.offsets.push_back(0);
  chunk.samples.reserve(size_t(a.vertices) * size_t(a.photos) * 6 / 10 + 16);
  truth.resize(a.vertices);
  for (uint32_t v = 0; v < a.vertices; ++v) {
    const V3 n = cone_direction(rng, 0.70f);
    truth[v] = random_material(rng);
    for (int p = 0; p < a.photos; ++p) {
      if (u(rng) >= 0.6f) continue;  // not seen by this photo
      const V3 l = lights[size_t(p)], e = cams[size_t(p)];
      Sample s{};
      s.raster = uint16_t(p);
      s.d = dot(n, l);
      s.lobe_cos = dot(n * (2 * s.d) - l, e);
      float clean[3];
      true_model(truth[v], s.d, s.lobe_cos, clean);
      for (int c = 0; c < 3; ++c)
        s.rgb[c] = std::max(0.0f, clean[c] * (1 + a.noise * gauss(rng)) + 0.1f * a.noise * gauss(rng));
      uint16_t f = 0;
      if (s.d <= 0) f |= kAttachedShadow;
      else if (u(rng) < 0.05f) f |= kCastShadow, s.rgb[0] *= 0.1f, s.rgb[1] *= 0.1f, s.rgb[2] *= 0.1f;
      if (std::max(s.rgb[0], std::max(s.rgb[1], s.rgb[2])) >= 1.0f) f |= kSaturated;
      for (float &c : s.rgb) c = std::min(c, 1.0f);
      if (s.d > 0 && s.d < 0.5f) f |= kGrazing;
      if (s.lobe_cos > 0.9f) f |= kHighlight;
      s.flags = f;
      chunk.samples.push_back(s);
    }
    chunk.offsets.push_back(uint32_t(chunk.samples.size()));
  }
}

// ---------------------------------------------------------------------------------------------

struct Row {
  std::string backend;
  int cap = 0;
  double seconds = 0;
  size_t full = 0, diffuse = 0, none = 0, converged = 0;
  double mean_iterations = 0;
  double err_rho = 0, err_ks = 0, err_alpha = 0, model_rmse = 0, fit_rmse = 0;
};

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

bool usable(const Sample &s) {
  return !(s.flags & (kShadowed | kSaturated | kNotSeen)) && s.d > 0;
}

void score(const SampleChunk &chunk, const std::vector<Truth> &truth, const std::vector<VertexFit> &fits, Row &r) {
  std::vector<double> e_rho, e_ks, e_alpha;
  double model_e = 0, model_w = 0, fit_rmse_sum = 0, iterations = 0;
  for (uint32_t v = 0; v < chunk.vertex_count; ++v) {
    const VertexFit &f = fits[v];
    const Truth &t = truth[v];
    r.none += f.status == kFitNone;
    r.diffuse += f.status == kFitDiffuseOnly;
    r.full += f.status == kFitFull;
    r.converged += f.converged;
    iterations += f.iterations;
    if (f.status == kFitNone) continue;
    fit_rmse_sum += f.rmse;
    if (f.status == kFitFull && t.ks > 0) {
      const float rho_max = std::max(t.rho[0], std::max(t.rho[1], t.rho[2]));
      double worst = 0;
      for (int c = 0; c < 3; ++c) worst = std::max(worst, double(std::fabs(f.kd * f.color[c] - t.rho[c]) / rho_max));
      e_rho.push_back(worst);
      e_ks.push_back(std::fabs(f.ks - t.ks) / t.ks);
      e_alpha.push_back(std::fabs(f.shininess - t.alpha) / t.alpha);
    }
    for (uint32_t i = chunk.offsets[v]; i < chunk.offsets[v + 1]; ++i) {
      const Sample &s = chunk.samples[i];
      if (!usable(s)) continue;
      float fit[3], tru[3];
      evaluate_reflectance(f, std::min(s.d, 1.0f), s.lobe_cos, LobeForm::PhongRE, fit);
      true_model(t, std::min(s.d, 1.0f), s.lobe_cos, tru);
      for (int c = 0; c < 3; ++c) model_e += s.d * double(fit[c] - tru[c]) * double(fit[c] - tru[c]);
      model_w += 3 * s.d;
    }
  }
  r.err_rho = median(e_rho);
  r.err_ks = median(e_ks);
  r.err_alpha = median(e_alpha);
  r.model_rmse = model_w > 0 ? std::sqrt(model_e / model_w) : 0;
  const size_t fitted = r.full + r.diffuse;
  r.fit_rmse = fitted ? fit_rmse_sum / double(fitted) : 0;
  r.mean_iterations = chunk.vertex_count ? iterations / chunk.vertex_count : 0;
}

double time_fit(const std::string &backend, ReflectanceFitGpu *gpu, const SampleChunk &chunk, const ReflectanceFitOptions &o,
                std::vector<VertexFit> &out) {
  out.assign(chunk.vertex_count, VertexFit());
  const auto t0 = std::chrono::steady_clock::now();
  if (backend == "gpu") gpu->fit_chunk(chunk, o, out.data());
  else fit_chunk_cpu(chunk, o, out.data());
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void print_row(const Row &r, uint32_t vertices, FILE *csv) {
  std::printf("%-4s %5d %9.3f %10.0f %7zu %7zu %6zu %6.1f%% %6.2f %9.2e %9.2e %9.2e %9.2e %9.2e\n", r.backend.c_str(),
              r.cap, r.seconds, vertices / r.seconds, r.full, r.diffuse, r.none,
              100.0 * double(r.converged) / vertices, r.mean_iterations, r.err_rho, r.err_ks, r.err_alpha,
              r.model_rmse, r.fit_rmse);
  if (csv)
    std::fprintf(csv, "%s,%d,%.6f,%.1f,%zu,%zu,%zu,%.4f,%.4f,%.6e,%.6e,%.6e,%.6e,%.6e\n", r.backend.c_str(), r.cap,
                 r.seconds, vertices / r.seconds, r.full, r.diffuse, r.none, double(r.converged) / vertices,
                 r.mean_iterations, r.err_rho, r.err_ks, r.err_alpha, r.model_rmse, r.fit_rmse);
}

std::vector<int> parse_caps(const std::string &list) {
  std::vector<int> caps;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) caps.push_back(std::stoi(item));
  return caps;
}

int usage() {
  std::fprintf(stderr, "usage: bench_fit [--vertices N] [--photos P] [--backend cpu|gpu|both] [--caps 1,2,5]\n"
                       "                 [--noise X] [--seed S] [--csv file]\n");
  return 2;
}

bool parse(int argc, char **argv, Args &a) {
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    if (i + 1 >= argc) return false;
    const std::string v = argv[++i];
    if (k == "--vertices") a.vertices = uint32_t(std::stoul(v));
    else if (k == "--photos") a.photos = std::stoi(v);
    else if (k == "--backend") a.backend = v;
    else if (k == "--caps") a.caps = parse_caps(v);
    else if (k == "--noise") a.noise = std::stof(v);
    else if (k == "--seed") a.seed = unsigned(std::stoul(v));
    else if (k == "--csv") a.csv = v;
    else return false;
  }
  return (a.backend == "cpu" || a.backend == "gpu" || a.backend == "both") && a.photos > 0 && a.photos <= 65535 &&
         !a.caps.empty();
}

} // namespace

int main(int argc, char **argv) {
  Args a;
  try {
    if (!parse(argc, argv, a)) return usage();
  } catch (const std::exception &) {
    return usage();
  }
  SampleChunk chunk;
  std::vector<Truth> truth;
  make_scene(a, chunk, truth);
  size_t highlights = 0;
  for (const Sample &s : chunk.samples) highlights += usable(s) && s.lobe_cos > 0.9f;
  std::printf("%u vertices x %d photos: %zu samples (%.1f per vertex, %.2f usable highlights per vertex), %.0f MB\n",
              a.vertices, a.photos, chunk.samples.size(), double(chunk.samples.size()) / a.vertices,
              double(highlights) / a.vertices, chunk.samples.size() * sizeof(Sample) / 1e6);

  std::vector<std::string> backends;
  if (a.backend != "gpu") backends.push_back("cpu");
  std::unique_ptr<test::OsMesaContext> context;
  std::unique_ptr<ReflectanceFitGpu> gpu;
  if (a.backend != "cpu") {
    std::string why;
    context = test::OsMesaContext::try_create(&why);
    try {
      if (!context) throw ProcessingError("no OSMesa context: " + why);
      gpu.reset(new ReflectanceFitGpu(context->get_proc_address()));
      std::printf("GPU: %s\n", gpu->device().c_str());
      std::vector<VertexFit> warm(std::min<uint32_t>(chunk.vertex_count, 256));
      SampleChunk head;  // first dispatch compiles the shader variant (llvmpipe JIT): not timed
      head.vertex_count = uint32_t(warm.size());
      head.offsets.assign(chunk.offsets.begin(), chunk.offsets.begin() + long(warm.size()) + 1);
      head.samples.assign(chunk.samples.begin(), chunk.samples.begin() + long(head.offsets.back()));
      gpu->fit_chunk(head, vbrdf::test::thesis_fit_options(), warm.data());
      backends.push_back("gpu");
    } catch (const std::exception &e) {
      std::fprintf(stderr, "GPU back end unavailable: %s\n", e.what());
      if (a.backend == "gpu") return 3;
    }
  }

  FILE *csv = a.csv.empty() ? nullptr : std::fopen(a.csv.c_str(), "w");
  if (!a.csv.empty() && !csv) {
    std::fprintf(stderr, "cannot write %s\n", a.csv.c_str());
    return 2;
  }
  if (csv)
    std::fprintf(csv, "backend,cap,seconds,vertices_per_s,full,diffuse_only,none,converged_fraction,mean_iterations,"
                      "median_rel_err_rho,median_rel_err_ks,median_rel_err_alpha,model_rmse,mean_fit_rmse\n");
  std::printf("%-4s %5s %9s %10s %7s %7s %6s %7s %6s %9s %9s %9s %9s %9s\n", "back", "cap", "seconds", "vert/s", "full",
              "diffuse", "none", "conv", "iters", "err rho", "err ks", "err alpha", "model rms", "fit rmse");
  std::vector<VertexFit> fits;
  for (const std::string &b : backends)
    for (int cap : a.caps) {
      ReflectanceFitOptions o = vbrdf::test::thesis_fit_options();
      o.max_iterations = cap;
      Row r;
      r.backend = b;
      r.cap = cap;
      r.seconds = time_fit(b, gpu.get(), chunk, o, fits);
      score(chunk, truth, fits, r);
      print_row(r, a.vertices, csv);
      std::fflush(stdout);
    }
  if (csv) std::fclose(csv);
  return 0;
}
