#include "tools/relight.h"

#include <algorithm>
#include <cmath>

#include "base/color_difference.h"
#include "base/errors.h"
#include "samples/footprint_weights.h"
#include "tools/rti_baselines.h"

namespace vbrdf {

namespace {
double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const size_t k = std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + long(k), v.end());
  return v[k];
}

ErrorSummary summarise(const std::vector<double> &de) {
  ErrorSummary s;
  s.samples = de.size();
  if (de.empty()) return s;
  double sum = 0;
  for (double d : de) sum += d;
  s.mean = sum / double(de.size());
  s.median = percentile(de, 0.5);
  s.p95 = percentile(de, 0.95);
  return s;
}

// Training photos of one held-out viewpoint, with what the baselines need of them.
struct BaselineViewpoint {
  std::vector<size_t> training;     // indices into the combined raster list
  std::vector<float> dirs_world;    // 3 per training raster
  std::vector<float> uv;            // 2 per training raster: (lu, lv) in the viewpoint's camera frame
  float sigma = 0;
};

struct BaselinePlan {
  std::vector<BaselineViewpoint> viewpoints;
  std::vector<int> viewpoint_of_heldout;   // -1: no training photo of that viewpoint
  std::vector<std::array<float, 2>> heldout_uv;
  std::vector<int> slot_of_raster;         // combined index -> slot in its viewpoint's training list (-1)
  std::vector<int> viewpoint_of_raster;    // combined index -> viewpoint (-1)
};

BaselinePlan plan_baselines(const std::vector<Raster> &heldout, const std::vector<std::array<float, 3>> &heldout_lights,
                            const std::vector<Raster> &training,
                            const std::vector<std::array<float, 3>> &training_lights) {
  BaselinePlan plan;
  const size_t n_held = heldout.size();
  plan.viewpoint_of_heldout.assign(n_held, -1);
  plan.heldout_uv.resize(n_held);
  plan.slot_of_raster.assign(n_held + training.size(), -1);
  plan.viewpoint_of_raster.assign(n_held + training.size(), -1);
  for (size_t h = 0; h < n_held; ++h) {
    float cam[3];
    world_to_camera_direction(heldout[h].shot, heldout_lights[h].data(), cam);
    plan.heldout_uv[h] = {{cam[0], cam[1]}};
    // An earlier held-out raster of the same viewpoint already collected its training photos.
    for (size_t g = 0; g < h && plan.viewpoint_of_heldout[h] < 0; ++g)
      if (plan.viewpoint_of_heldout[g] >= 0 && same_shot(heldout[g].shot, heldout[h].shot))
        plan.viewpoint_of_heldout[h] = plan.viewpoint_of_heldout[g];
    if (plan.viewpoint_of_heldout[h] >= 0) continue;
    BaselineViewpoint vp;
    for (size_t t = 0; t < training.size(); ++t) {
      if (!same_shot(training[t].shot, heldout[h].shot) || plan.viewpoint_of_raster[n_held + t] >= 0) continue;
      plan.slot_of_raster[n_held + t] = int(vp.training.size());
      plan.viewpoint_of_raster[n_held + t] = int(plan.viewpoints.size());
      vp.training.push_back(n_held + t);
      world_to_camera_direction(heldout[h].shot, training_lights[t].data(), cam);
      vp.uv.push_back(cam[0]);
      vp.uv.push_back(cam[1]);
      for (int k = 0; k < 3; ++k) vp.dirs_world.push_back(training_lights[t][k]);
    }
    if (vp.training.empty()) continue;
    vp.sigma = rbf_sigma(vp.dirs_world.data(), vp.training.size());
    plan.viewpoint_of_heldout[h] = int(plan.viewpoints.size());
    plan.viewpoints.push_back(std::move(vp));
  }
  return plan;
}

// PTM and RBF of one vertex in one viewpoint, from its usable training samples.
struct VertexBaseline {
  bool fitted = false;
  size_t count = 0;                 // usable training samples (0: no prediction)
  float ptm[3 * kPtmCoefficients];
  std::vector<float> dirs, weights; // RBF centres and weights
};

void fit_vertex_baseline(const BaselinePlan &plan, int viewpoint, const Sample *samples, size_t count,
                         float rbf_ridge, VertexBaseline &out) {
  const BaselineViewpoint &vp = plan.viewpoints[size_t(viewpoint)];
  std::vector<float> uv, rgb;
  out.dirs.clear();
  for (size_t k = 0; k < count; ++k) {
    const Sample &s = samples[k];
    if (plan.viewpoint_of_raster[s.raster] != viewpoint || (s.flags & kSaturated)) continue;
    const size_t slot = size_t(plan.slot_of_raster[s.raster]);
    uv.insert(uv.end(), {vp.uv[2 * slot], vp.uv[2 * slot + 1]});
    out.dirs.insert(out.dirs.end(), vp.dirs_world.begin() + long(3 * slot), vp.dirs_world.begin() + long(3 * slot + 3));
    rgb.insert(rgb.end(), {s.rgb[0], s.rgb[1], s.rgb[2]});
  }
  out.fitted = true;
  out.count = uv.size() / 2;
  if (out.count == 0) return;
  fit_ptm(uv.data(), rgb.data(), out.count, out.ptm);
  out.weights.resize(3 * out.count);
  fit_rbf(out.dirs.data(), rgb.data(), out.count, vp.sigma, rbf_ridge, out.weights.data());
}

// One scored held-out sample: what RelightOptions::per_sample keeps, and the bookkeeping of the summaries.
struct Scored {
  ScoredSample sample;
  float squared_error;  // over the 3 channels, prediction clamped to 1
  bool modelled, has_baseline;
};

// The prediction of the photo's bilinear sample at image point (x, y) whose footprint pixels
// `own` (visibility.h's mask, from the camera pass) show the vertex's own surface
// (RelightOptions::rendered): those take the vertex's model, the others the rendered image there
// (background, another surface).
void predict_footprint(const cv::Mat &rendered, float x, float y, uint8_t own, const float vertex_rgb[3],
                       float out[3]) {
  const float fx = x - 0.5f, fy = y - 0.5f;
  const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  const float ax = fx - float(x0), ay = fy - float(y0);
  const float w[4] = {(1 - ax) * (1 - ay), ax * (1 - ay), (1 - ax) * ay, ax * ay};
  for (int c = 0; c < 3; ++c) out[c] = 0;
  for (int k = 0; k < 4; ++k) {
    const float *texel = vertex_rgb;
    if (!(own >> k & 1u)) {
      const int xi = std::min(std::max(x0 + k % 2, 0), rendered.cols - 1);
      const int yi = std::min(std::max(y0 + k / 2, 0), rendered.rows - 1);
      texel = rendered.ptr<float>(yi) + 3 * xi;
    }
    for (int c = 0; c < 3; ++c) out[c] += w[k] * texel[c];
  }
}

// The diffuse reflectance each held-out camera records at the deconvolved vertices
// (RelightOptions::diffuse_deconvolved): k_d C seen through the camera's pixel footprints.
struct SeenAlbedo {
  std::vector<int32_t> camera_of_raster;  // -1: not a held-out raster
  std::vector<std::vector<float>> rgb;    // per camera: 3 per vertex
  std::vector<std::vector<uint8_t>> known;  // per camera: 1 per vertex where rgb is set

  // `fit` with k_d C replaced by what raster r's camera records at v (unchanged where not known).
  VertexFit as_seen(const VertexFit &fit, size_t r, size_t v) const {
    if (r >= camera_of_raster.size() || camera_of_raster[r] < 0) return fit;
    const size_t c = size_t(camera_of_raster[r]);
    if (!known[c][v]) return fit;
    VertexFit seen = fit;
    const float *rgb_v = &rgb[c][3 * v];
    const double rho[3] = {rgb_v[0], rgb_v[1], rgb_v[2]};
    set_kd_color(rho, seen);
    return seen;
  }
};

SeenAlbedo seen_albedo(const MeshView &mesh, const std::vector<VertexFit> &fits, const std::vector<Raster> &all,
                       size_t n_held, const VisibilityMasks &masks, const RelightOptions &options) {
  SeenAlbedo out;
  if (!options.diffuse_deconvolved) return out;
  const size_t n = mesh.vertex_count;
  std::vector<uint8_t> wanted(n, 0);
  for (size_t v = 0; v < n; ++v)
    wanted[v] = (*options.diffuse_deconvolved)[v] && has_model(fits[v]) &&
                (!options.vertex_filter || (*options.vertex_filter)[v]);
  if (std::none_of(wanted.begin(), wanted.end(), [](uint8_t w) { return w != 0; })) return out;
  std::vector<size_t> held(n_held);
  for (size_t r = 0; r < n_held; ++r) held[r] = r;
  const FootprintRows rows = footprint_rows(mesh, all, masks, held, wanted.data(),
                                            VisibilitySettings().depth_tolerance * compute_bounds(mesh).diagonal());
  std::vector<float> rho(3 * n, 0.0f), blurred(3 * rows.rows());
  for (size_t v = 0; v < n; ++v)
    if (has_model(fits[v]))
      for (int c = 0; c < 3; ++c) rho[3 * v + size_t(c)] = fits[v].kd * fits[v].color[c];
  blur_through_footprints(rows, rho.data(), blurred.data());
  out.camera_of_raster = rows.camera_of_raster;
  out.rgb.assign(rows.camera_count, std::vector<float>(3 * n, 0.0f));
  out.known.assign(rows.camera_count, std::vector<uint8_t>(n, 0));
  for (size_t k = 0; k < rows.rows(); ++k) {
    const size_t c = rows.row_camera[k], v = rows.row_vertex[k];
    out.known[c][v] = 1;
    for (int ch = 0; ch < 3; ++ch) out.rgb[c][3 * v + size_t(ch)] = blurred[3 * k + size_t(ch)];
  }
  return out;
}

void clamp_below_zero(float rgb[3]) {
  for (int c = 0; c < 3; ++c) rgb[c] = std::max(rgb[c], 0.0f);
}

void check_sizes(const MeshView &mesh, const std::vector<VertexFit> &fits, const std::vector<Raster> &rasters,
                 const std::vector<std::array<float, 3>> &lights, const RelightOptions &options) {
  if (fits.size() != mesh.vertex_count)
    throw InputError("Relighting evaluation: " + std::to_string(fits.size()) + " fits for a mesh of " +
                     std::to_string(mesh.vertex_count) + " vertices.");
  if (lights.size() != rasters.size())
    throw InputError("Relighting evaluation: one light direction per held-out photo is needed.");
  if (options.vertex_filter && options.vertex_filter->size() != mesh.vertex_count)
    throw InputError("Relighting evaluation: the vertex filter has " + std::to_string(options.vertex_filter->size()) +
                     " entries for a mesh of " + std::to_string(mesh.vertex_count) + " vertices.");
  if (options.rendered && options.rendered->size() != rasters.size())
    throw InputError("Relighting evaluation: one rendered image per held-out photo is needed.");
  if (options.rendered)
    for (size_t r = 0; r < rasters.size(); ++r)
      if ((*options.rendered)[r].type() != CV_32FC3 || (*options.rendered)[r].cols != rasters[r].width() ||
          (*options.rendered)[r].rows != rasters[r].height())
        throw InputError("Relighting evaluation: the rendered image of '" + rasters[r].label +
                         "' is not a linear RGB float image of the photo's size.");
  if (options.diffuse_deconvolved && options.diffuse_deconvolved->size() != mesh.vertex_count)
    throw InputError("Relighting evaluation: the deconvolution flags have " +
                     std::to_string(options.diffuse_deconvolved->size()) + " entries for a mesh of " +
                     std::to_string(mesh.vertex_count) + " vertices.");
  if (options.lit_filter && options.lit_filter->size() != mesh.vertex_count * rasters.size())
    throw InputError("Relighting evaluation: the lit filter has " + std::to_string(options.lit_filter->size()) +
                     " entries; expected held-out photos x vertices = " +
                     std::to_string(mesh.vertex_count * rasters.size()) + ".");
  if (bool(options.training_rasters) != bool(options.training_lights) ||
      (options.training_rasters && options.training_rasters->size() != options.training_lights->size()))
    throw InputError("Relighting evaluation: the baselines need one light direction per training photo.");
}
} // namespace

namespace {

// What scoring a held-out sample reads: the model, the photos (held-out first, then training),
// their visibility and the baselines' plan.
struct Evaluation {
  const MeshView &mesh;
  const std::vector<VertexFit> &fits;
  const std::vector<Raster> &rasters;     // held-out
  const std::vector<LightSource> &lights; // held-out
  const std::vector<std::array<float, 3>> &light_dirs_world;
  const VisibilityMasks &masks;
  const BaselinePlan &plan;
  const SeenAlbedo &seen_albedo_of;
  const RelightOptions &options;
  size_t n_held;
  bool baselines;
};

// The errors of every scored sample, in vertex order.
struct ErrorLists {
  std::vector<double> all, clean, base_product, ptm, rbf, fp_product[2], fp_rbf[2];
  double squared_error = 0;
};

// Whether sample `s` of vertex v is a held-out sample the evaluation scores: unsaturated and lit
// (RelightOptions::lit_filter where given).
bool scores(const Evaluation &ev, const Sample &s, size_t v) {
  if (s.raster >= ev.n_held) return false;  // training photo
  if (s.flags & kSaturated) return false;
  return ev.options.lit_filter ? (*ev.options.lit_filter)[size_t(s.raster) * ev.mesh.vertex_count + v] != 0
                               : !((s.flags & kShadowed) || !(s.d > 0));
}

// The model's prediction of sample `s` of vertex v: under the light's irradiance at the vertex,
// and through the rendered image's footprint where the pixel straddles a depth jump.
void predict_sample(const Evaluation &ev, const Sample &s, size_t v, float predicted[3]) {
  const VertexFit &fit = ev.fits[v];
  evaluate_reflectance(ev.seen_albedo_of.as_seen(fit, s.raster, v), s.d, s.lobe_cos, ev.options.gather.lobe, predicted,
                 s.footprint);
  const float irradiance = light_irradiance_at(ev.lights[s.raster], ev.mesh.positions + 3 * v);
  for (int c = 0; c < 3; ++c) predicted[c] *= irradiance;
  const uint8_t own = ev.masks.own_texels(s.raster, v);
  if (ev.options.rendered && own != kAllFootprintTexels) {
    const ImagePoint ip = project_to_image(ev.rasters[s.raster].shot, ev.mesh.positions + 3 * v);
    const float at_vertex[3] = {predicted[0], predicted[1], predicted[2]};
    predict_footprint((*ev.options.rendered)[s.raster], ip.x, ip.y, own, at_vertex, predicted);
  }
}

// The per-pixel PTM and RBF baselines' errors for sample `s`, fitted on the vertex's training
// samples of the held-out photo's viewpoint (once per vertex and viewpoint, in `fitted`).
void score_baselines(const Evaluation &ev, const Sample &s, const Sample *samples, size_t count,
                     std::vector<VertexBaseline> &fitted, Scored &r) {
  const int vp = ev.baselines ? ev.plan.viewpoint_of_heldout[s.raster] : -1;
  if (vp < 0) return;
  VertexBaseline &b = fitted[size_t(vp)];
  if (!b.fitted) fit_vertex_baseline(ev.plan, vp, samples, count, ev.options.rbf_ridge, b);
  if (b.count == 0) return;
  float p[3];
  evaluate_ptm(b.ptm, ev.plan.heldout_uv[s.raster][0], ev.plan.heldout_uv[s.raster][1], p);
  clamp_below_zero(p);
  r.sample.de_ptm = float(delta_e2000_linear_srgb(p, s.rgb));
  evaluate_rbf(b.dirs.data(), b.weights.data(), b.count, ev.plan.viewpoints[size_t(vp)].sigma,
               ev.light_dirs_world[s.raster].data(), p);
  clamp_below_zero(p);
  r.sample.de_rbf = float(delta_e2000_linear_srgb(p, s.rgb));
  r.has_baseline = true;
}

// Every scored held-out sample of chunk vertex i, into `out`.
void score_vertex(const Evaluation &ev, const SampleChunk &chunk, uint32_t i, std::vector<Scored> &out) {
  const size_t v = chunk.first_vertex + i;
  const Sample *samples = chunk.samples.data() + chunk.offsets[i];
  const size_t count = chunk.offsets[i + 1] - chunk.offsets[i];
  const VertexFit &fit = ev.fits[v];
  std::vector<VertexBaseline> fitted(ev.plan.viewpoints.size());
  for (size_t k = 0; k < count; ++k) {
    const Sample &s = samples[k];
    if (!scores(ev, s, v)) continue;
    Scored r{};
    ScoredSample &o = r.sample;
    o.vertex = uint32_t(v);
    o.raster = s.raster;
    o.fit_status = fit.status;
    o.mixed = (s.flags & kMixedPixel) != 0;
    o.d = s.d;
    r.modelled = has_model(fit);
    float predicted[3];
    predict_sample(ev, s, v, predicted);
    for (int c = 0; c < 3; ++c) o.observed[c] = s.rgb[c], o.predicted[c] = predicted[c];
    o.de = float(delta_e2000_linear_srgb(predicted, s.rgb));
    o.de_ptm = o.de_rbf = -1.0f;
    for (int c = 0; c < 3; ++c) {
      const float e = std::min(predicted[c], 1.0f) - s.rgb[c];
      r.squared_error += e * e;
    }
    score_baselines(ev, s, samples, count, fitted, r);
    out.push_back(r);
  }
}

// A scored sample into the error lists and the per-raster and count figures.
void collect(const Scored &scored, bool baselines, const RelightOptions &options, ErrorLists &errors,
             RelightStats &stats) {
  const ScoredSample &r = scored.sample;
  if (options.per_sample) options.per_sample->push_back(r);
  errors.all.push_back(r.de);
  errors.squared_error += scored.squared_error;
  stats.per_raster_mean_de2000[r.raster] += r.de;
  ++stats.per_raster_samples[r.raster];
  if (!scored.modelled) ++stats.unmodelled_samples;
  if (scored.modelled && !r.mixed) errors.clean.push_back(r.de);
  if (!baselines) return;
  if (!scored.has_baseline) {
    ++stats.baseline_excluded;
    return;
  }
  errors.base_product.push_back(r.de);
  errors.ptm.push_back(r.de_ptm);
  errors.rbf.push_back(r.de_rbf);
  errors.fp_product[r.mixed].push_back(r.de);
  errors.fp_rbf[r.mixed].push_back(r.de_rbf);
}

// The summaries of the error lists.
void summarise_errors(const ErrorLists &errors, size_t n_held, RelightStats &stats) {
  for (size_t r = 0; r < n_held; ++r)
    if (stats.per_raster_samples[r]) stats.per_raster_mean_de2000[r] /= double(stats.per_raster_samples[r]);
  const ErrorSummary whole = summarise(errors.all);
  stats.samples = whole.samples;
  stats.mean_de2000 = whole.mean;
  stats.median_de2000 = whole.median;
  stats.p95_de2000 = whole.p95;
  if (!errors.all.empty()) {
    const double mse = errors.squared_error / double(3 * errors.all.size());
    stats.psnr_db = mse > 0 ? 10 * std::log10(1.0 / mse) : 99.0;
    stats.unmodelled_share = double(stats.unmodelled_samples) / double(errors.all.size());
  }
  stats.clean_modelled = summarise(errors.clean);
  stats.product_on_baseline_set = summarise(errors.base_product);
  stats.ptm = summarise(errors.ptm);
  stats.rbf = summarise(errors.rbf);
  stats.product_clean_footprint = summarise(errors.fp_product[0]);
  stats.rbf_clean_footprint = summarise(errors.fp_rbf[0]);
  stats.product_mixed_footprint = summarise(errors.fp_product[1]);
  stats.rbf_mixed_footprint = summarise(errors.fp_rbf[1]);
}

} // namespace

RelightStats evaluate_relighting(const MeshView &mesh, const std::vector<VertexFit> &fits,
                                 const std::vector<Raster> &rasters,
                                 const std::vector<LightSource> &lights, VisibilityBackend &visibility,
                                 const RelightOptions &options) {
  const std::vector<std::array<float, 3>> light_dirs_world = light_directions(lights);
  check_sizes(mesh, fits, rasters, light_dirs_world, options);
  const size_t n_held = rasters.size();
  const bool baselines = options.training_rasters != nullptr;
  RelightStats stats;
  stats.has_baselines = baselines;
  stats.per_raster_mean_de2000.assign(n_held, 0.0);
  stats.per_raster_samples.assign(n_held, 0);

  // Held-out and training photos are gathered in one pass: raster indices >= n_held are training.
  std::vector<Raster> all = rasters;
  std::vector<LightSource> all_lights = lights;
  BaselinePlan plan;
  if (baselines) {
    all.insert(all.end(), options.training_rasters->begin(), options.training_rasters->end());
    all_lights.insert(all_lights.end(), options.training_lights->begin(), options.training_lights->end());
    plan = plan_baselines(rasters, light_dirs_world, *options.training_rasters, light_directions(*options.training_lights));
    stats.rbf_sigma_per_raster.assign(n_held, 0.0f);
    for (size_t h = 0; h < n_held; ++h)
      if (plan.viewpoint_of_heldout[h] >= 0)
        stats.rbf_sigma_per_raster[h] = plan.viewpoints[size_t(plan.viewpoint_of_heldout[h])].sigma;
  }
  GatherSettings settings = options.gather;
  settings.own_surface_texels = false;
  const VisibilityMasks masks = compute_visibility(mesh, all, all_lights, visibility);
  PhotoCache photos(settings.encoding, settings.saturation_level, settings.photo_cache_bytes);
  const SeenAlbedo seen_albedo_of = seen_albedo(mesh, fits, all, n_held, masks, options);
  const Evaluation ev{mesh, fits, rasters, lights, light_dirs_world, masks, plan, seen_albedo_of, options, n_held, baselines};

  ErrorLists errors;
  std::vector<std::vector<Scored>> scored;
  gather_samples(mesh, all, all_lights, masks, settings, photos, [&](const SampleChunk &chunk) {
    scored.assign(chunk.vertex_count, {});
    std::vector<uint8_t> seen(chunk.vertex_count, 0);
#pragma omp parallel for schedule(dynamic, 256)
    for (long long ii = 0; ii < (long long)chunk.vertex_count; ++ii) {
      const uint32_t i = uint32_t(ii);
      if (options.vertex_filter && !(*options.vertex_filter)[chunk.first_vertex + i]) continue;
      seen[i] = chunk.offsets[i + 1] > chunk.offsets[i];
      score_vertex(ev, chunk, i, scored[i]);
    }
    for (uint32_t i = 0; i < chunk.vertex_count; ++i) {
      if (seen[i]) {
        ++stats.seen_vertices;
        if (!has_model(fits[chunk.first_vertex + i])) ++stats.seen_unmodelled_vertices;
      }
      for (const Scored &s : scored[i]) collect(s, baselines, options, errors, stats);
    }
  });
  summarise_errors(errors, n_held, stats);
  return stats;
}

} // namespace vbrdf
