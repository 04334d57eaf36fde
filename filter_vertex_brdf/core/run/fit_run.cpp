#include "run/fit_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <future>
#include <sstream>

#include <omp.h>

#include "base/errors.h"
#include "base/file_util.h"
#include "inputs/mesh_file.h"
#include "inputs/photo_content.h"
#include "base/mesh_adjacency.h"
#include "base/vec3.h"
#include "calibration/color_plan.h"
#include "inputs/light_file.h"
#include "inputs/light_source.h"
#include "inputs/photo_prefetch.h"
#include "inputs/input_check.h"
#include "fit/diffuse_choice.h"
#include "samples/footprint.h"
#include "run/fit_outputs.h"
#include "io/registered_project.h"
#include "io/output_ply.h"
#include "samples/light_check.h"
#include "samples/reshade.h"
#include "samples/sample_colors.h"
#include "visibility/camera_pass_cache.h"
#include "visibility/pass_size.h"
#include "visibility/visibility_masks.h"

namespace vbrdf {

std::string default_output_path(const std::string &project_path) {
  if (project_path.empty()) return "vertex_brdf.ply";
  return strip_extension(project_path) + "_brdf.ply";
}

std::string registered_project_path(const std::string &output_ply) {
  return strip_extension(output_ply) + "_registered.mlp";
}

void validate_input(const FitInput &input) {
  validate_mesh_and_rasters(input.mesh, input.mesh_name, input.rasters, input.vertex_mask);
}

namespace {

// ---- Colour correction (color_chart.h), per viewpoint ----

// Every viewpoint's colour correction (color_plan.h), photos decoded as their samples are.
ColorPlan plan_colors(const FitInput &input, const FitSettings &settings,
                      const std::vector<std::array<float, 3>> &lights_world, PhotoCache &photos, const LogFn &log) {
  if (settings.color_correction == ColorCorrectionChoice::Off) {
    log("Colour correction: off (colorCorrection = Off): samples are used as decoded.");
    return ColorPlan();
  }
  ColorCorrectionSettings cs;
  cs.choice = settings.color_correction;
  cs.exposure = settings.exposure;
  cs.chart_corners = settings.chart_corners;
  const auto load = [&](size_t r) {
    const Raster &raster = input.rasters[r];
    return photo_linear_rgb(*photos.get(raster.image_path, raster.width(), raster.height()));
  };
  const auto detector_image = [&](size_t r) {  // 8-bit sRGB photos: their own codes, no float copy
    const Raster &raster = input.rasters[r];
    return photo_srgb8_bgr(*photos.get(raster.image_path, raster.width(), raster.height()));
  };
  const auto load_region = [&](size_t r, const cv::Rect &region) {  // the chart's part of a photo only
    const Raster &raster = input.rasters[r];
    Photo part = *photos.get(raster.image_path, raster.width(), raster.height());
    const cv::Rect inside = region & cv::Rect(0, 0, part.width(), part.height());
    if (inside.empty() || inside.tl() != region.tl()) return cv::Mat();
    part.pixels = part.pixels(inside);  // a header on the same pixels
    return photo_linear_rgb(part);
  };
  return plan_color_correction(input.rasters, lights_world, cs, load, log, detector_image, load_region);
}

// The colour plan, searched in a thread of its own while the GL passes run: it needs the photos
// only, and on a software renderer the passes leave a core idle between their draws (100 k x 32
// on llvmpipe: end to end 0.97x in turn, the search's 0.25-0.4 s hidden). It leaves one core to
// the passes. Its log lines are kept and written, in order, by take().
class ColorPlanBesidePasses {
public:
  ColorPlanBesidePasses(const FitInput &input, const FitSettings &settings,
                        std::vector<std::array<float, 3>> lights_world, PhotoCache &photos)
      : started_(Clock::now()) {
    search_ = std::async(std::launch::async, [this, &input, &settings, &photos, lights = std::move(lights_world)]() {
      omp_set_num_threads(std::max(1, omp_get_num_procs() - 1));
      ColorPlan plan = plan_colors(input, settings, lights, photos, [this](const std::string &l) { log_.push_back(l); });
      seconds_ = seconds_since(started_);
      return plan;
    });
  }
  // Throws the search's error once it has failed (InputError for a required chart not found).
  void rethrow_if_failed() {
    if (!done_ && search_.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
      plan_ = search_.get();
      done_ = true;
    }
  }
  // Waits for the search, writes its log lines and returns its plan.
  ColorPlan take(const LogFn &log, double &seconds) {
    if (!done_) plan_ = search_.get();
    done_ = true;
    for (const std::string &line : log_) log(line);
    seconds = seconds_;
    return std::move(plan_);
  }

private:
  Clock::time_point started_;
  std::vector<std::string> log_;  // written by the search thread only, read after it ends
  double seconds_ = 0;
  std::future<ColorPlan> search_;  // last: its destructor waits for the thread that uses the above
  ColorPlan plan_;  // once done_
  bool done_ = false;
};


// The chunk's reflectance from its samples as they are shaded now: the back end's fit, the robust
// basic colour for diffuse-only vertices, and the fallback fit where the strict rules left nothing.
// diffuse[i] and fits[i] belong to chunk vertex i.
void fit_chunk_models(SampleChunk &chunk, ReflectanceFitter &fitter, const ReflectanceFitOptions &options,
                      const DiffuseEstimate *diffuse, VertexFit *fits) {
  fitter.fit_chunk(chunk, options, fits);
  // Diffuse-only vertices take the robust basic colour (outlier rejection) when it is clean.
  for (uint32_t i = 0; i < chunk.vertex_count; ++i) {
    VertexFit &f = fits[i];
    const DiffuseEstimate &e = diffuse[i];
    if (f.status == kFitDiffuseOnly && e.valid && !e.from_mixed_pixels)
      set_diffuse_only_reflectance(chunk.samples.data() + chunk.offsets[i], chunk.offsets[i + 1] - chunk.offsets[i],
                                   options, e.rgb, f);
  }
  // Vertices the strict rules left without a sample (all grazing, all mixed): the fallback fit
  // from what there is, on the CPU for either back end (few vertices, and one code path).
#pragma omp parallel for schedule(dynamic, 64)
  for (long long i = 0; i < (long long)chunk.vertex_count; ++i) {
    VertexFit &f = fits[size_t(i)];
    const uint32_t begin = chunk.offsets[size_t(i)], end = chunk.offsets[size_t(i) + 1];
    if (f.status == kFitNone && end > begin) fit_vertex_weak(chunk.samples.data() + begin, end - begin, options, f);
  }
}

// The diffuse estimate and reflectance again at the chunk's vertices with selected[i] (their
// samples shaded anew), the others left as they are: those vertices' samples are copied into a
// chunk of their own, fitted, and the results put back.
void refit_selected(const SampleChunk &chunk, const std::vector<uint8_t> &selected, ReflectanceFitter &fitter,
                    const ReflectanceFitOptions &options, FitResult &r) {
  SampleChunk part;
  std::vector<uint32_t> index;
  part.first_vertex = chunk.first_vertex;
  part.offsets.push_back(0);
  for (uint32_t i = 0; i < chunk.vertex_count; ++i) {
    if (!selected[i]) continue;
    index.push_back(i);
    part.samples.insert(part.samples.end(), chunk.samples.begin() + chunk.offsets[i],
                        chunk.samples.begin() + chunk.offsets[i + 1]);
    part.offsets.push_back(uint32_t(part.samples.size()));
  }
  part.vertex_count = uint32_t(index.size());
  if (index.empty()) return;
  std::vector<DiffuseEstimate> diffuse(index.size());
  std::vector<VertexFit> fits(index.size());
  estimate_diffuse_chunk(part, diffuse.data());
  fit_chunk_models(part, fitter, options, diffuse.data(), fits.data());
  for (size_t k = 0; k < index.size(); ++k) {
    r.diffuse[chunk.first_vertex + index[k]] = diffuse[k];
    r.fits[chunk.first_vertex + index[k]] = fits[k];
  }
}

// Refines a chunk's shading normals from its fits and shades the samples of those that moved
// again (shading_normals.h): `active` (null: every vertex) limits it to the vertices still moving;
// `moved` says which moved. False when none did.
using NormalStep = std::function<bool(SampleChunk &, const uint8_t *active, std::vector<uint8_t> &moved)>;

// Everything the chunk consumer produces, per vertex. `refine_normals` (may be empty): up to
// `normal_rounds` alternations of a normal step and a refit of the vertices whose normal moved;
// a vertex whose normal stopped moving is not solved or fitted again.
void consume_chunk(SampleChunk &chunk, ReflectanceFitter *fitter, const ReflectanceFitOptions &options,
                   const PhotoShadowSettings &photo_shadows, const NormalStep &refine_normals, int normal_rounds,
                   FitResult &r, double &fit_seconds) {
  r.rim_samples_demoted += prefer_clean_samples(chunk);
  estimate_diffuse_chunk(chunk, &r.diffuse[chunk.first_vertex]);
  if (!fitter) return;
  auto t = Clock::now();
  fit_chunk_models(chunk, *fitter, options, &r.diffuse[chunk.first_vertex], &r.fits[chunk.first_vertex]);
  fit_seconds += seconds_since(t);
  std::vector<uint8_t> moved, active;
  for (int round = 0; round < normal_rounds && refine_normals; ++round) {
    if (!refine_normals(chunk, round == 0 ? nullptr : active.data(), moved)) break;
    t = Clock::now();
    refit_selected(chunk, moved, *fitter, options, r);
    fit_seconds += seconds_since(t);
    active.swap(moved);
  }
  t = Clock::now();
  refit_photo_shadows(chunk, options, photo_shadows, &r.fits[chunk.first_vertex], r.photo_shadow_samples,
                      r.photo_shadow_vertices);
  fit_seconds += seconds_since(t);
}

// Material stage hook (materials.h): after the per-vertex fit of every chunk, before the
// neighbour fill (which then copies the material-consistent parameters).
void run_material_stage(const FitInput &input, const FitSettings &settings, const MaterialSampleStore &store,
                        const LogFn &log, FitResult &r) {
  const size_t n = input.mesh.vertex_count;
  std::vector<float> rgb(3 * n, 0.0f);
  std::vector<uint8_t> valid(n, 0);
  for (size_t v = 0; v < n; ++v) {
    const DiffuseEstimate &e = r.diffuse[v];
    valid[v] = e.valid && !e.from_mixed_pixels;
    for (int c = 0; c < 3; ++c) rgb[3 * v + size_t(c)] = e.rgb[c];
  }
  r.materials = fit_materials(input.mesh, store, settings.reflectance, settings.material_options, rgb.data(), valid.data(), r.fits);
  std::istringstream lines(r.materials.report);
  for (std::string line; std::getline(lines, line);) log(line);
}

// Seen vertices still without a model (every sample shadowed or saturated) and, on request, small
// unseen gaps take the parameters of their nearest modelled neighbours (neighbour_fill.h).
void fill_gaps(const FitInput &input, const FitSettings &settings, const LogFn &log, FitResult &r) {
  const size_t n = input.mesh.vertex_count;
  std::vector<uint8_t> seen(n);
  for (size_t v = 0; v < n; ++v) seen[v] = r.diffuse[v].n_seen > 0;
  r.fill = fill_from_neighbours(input.mesh, seen.data(), settings.fill_unseen_rings, r.fits.data());
  if (r.fill.filled_seen || r.fill.filled_unseen)
    log("Neighbour fill: " + std::to_string(r.fill.filled_seen) + " seen vertices without a usable sample and " +
        std::to_string(r.fill.filled_unseen) + " unseen vertices took their neighbours' parameters (fit_status 3).");
  if (r.fill.filled_nearest)
    log("Neighbour fill: " + std::to_string(r.fill.filled_nearest) +
        " of them lie in a part of the mesh without any modelled vertex and copied the nearest modelled vertex in space.");
  if (r.fill.unreachable_seen)
    log("Neighbour fill: " + std::to_string(r.fill.unreachable_seen) +
        " seen vertices have no usable sample and no vertex of the mesh has a model: left without a model.");
}

// The fit's k_d C deconvolved through the photos' pixel footprints (albedo_deconvolution.h), at the
// vertices fitted from their own samples (fit_status 1, 2, 4): neighbour-filled ones are copies.
void deconvolve_fit_albedo(const FitInput &input, const FitSettings &settings, const VisibilityMasks &masks,
                           const LogFn &log, FitResult &r) {
  const MeshView &mesh = input.mesh;
  const size_t n = mesh.vertex_count;
  std::vector<uint8_t> own(n, 0);
  std::vector<float> b(3 * n, 0.0f), x(3 * n, 0.0f);
  for (size_t v = 0; v < n; ++v) {
    const VertexFit &f = r.fits[v];
    own[v] = f.status == kFitFull || f.status == kFitDiffuseOnly || f.status == kFitFromWeakSamples;
    if (has_model(f))
      for (int c = 0; c < 3; ++c) b[3 * v + size_t(c)] = f.kd * f.color[c];
  }
  std::vector<size_t> all(input.rasters.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  EdgeFilter edges;  // rows only where the footprint can span an edge
  edges.rgb = b.data();
  edges.contrast = settings.deconvolution.edge_contrast;
  const FootprintRows rows = footprint_rows(mesh, input.rasters, masks, all, own.data(),
                                            settings.visibility.depth_tolerance * compute_bounds(mesh).diagonal(), &edges);
  r.albedo_deconvolved.assign(n, 0);
  r.deconvolution =
      deconvolve_albedo(rows, n, b.data(), own.data(), settings.deconvolution, x.data(), r.albedo_deconvolved.data());
  if (r.deconvolution.solved) {
    for (size_t v = 0; v < n; ++v) {
      if (!r.albedo_deconvolved[v]) continue;
      const double rho[3] = {x[3 * v], x[3 * v + 1], x[3 * v + 2]};
      set_kd_color(rho, r.fits[v]);
    }
    r.deconvolution.note =
        std::to_string(r.deconvolution.written) + " vertices' k_d C deconvolved (of " +
        std::to_string(r.deconvolution.edge_vertices) + " whose pixel footprints span an albedo edge, contrast above " +
        std::to_string(int(std::lround(100 * settings.deconvolution.edge_contrast))) + " %; the others' footprints are "
        "not a blend of the vertices' colours, e.g. a texture finer than the mesh); lambda " +
        fixed(settings.deconvolution.lambda) + ", " + std::to_string(r.deconvolution.rounds) + " solve(s), " +
        std::to_string(r.deconvolution.iterations) + " CG iterations; through the footprints they give the fit's colours "
        "to " + fixed(100 * r.deconvolution.reblur_rms, 1) + " % RMS";
  }
  log("Albedo deconvolution: " + r.deconvolution.note + ".");
}

} // namespace

namespace {
// Sets settings.gather.diffuse (the diffuse forms of the samples, hence of the fit and the result)
// from settings.diffuse_choice; Auto runs the pilot of diffuse_choice.h.
void decide_diffuse_form(const FitInput &input, const std::vector<LightSource> &lights, const VisibilityMasks &masks,
                         PhotoCache &photos, const std::function<void(SampleChunk &)> &prepare, const LogFn &log,
                         FitSettings &settings, FitResult &result) {
  if (!settings.fit_reflectance || settings.diffuse_choice != DiffuseTermChoice::Auto) {
    result.diffuse_forms = DiffuseForms::everywhere(
        settings.diffuse_choice == DiffuseTermChoice::Coated ? DiffuseForm::Coated : DiffuseForm::Lambert);
    result.diffuse_choice_note = describe_diffuse_forms(result.diffuse_forms) +
                                 (settings.fit_reflectance ? " (as set)" : " (no reflectance fit: the thesis's form)");
  } else {
    const size_t loads_before = photos.loads();
    DiffuseChoiceOptions options;
    options.normals = settings.shading_normals;  // the pilot's normals refined as the fit will refine them
    const DiffuseChoice choice = choose_diffuse_forms(input.mesh, input.rasters, lights, masks, settings.gather,
                                                      settings.reflectance, photos, prepare, options);
    const size_t decoded_again = photos.loads() - loads_before;
    result.diffuse_forms = choice.forms;
    result.diffuse_choice_note = choice.note + (choice.piloted ? ", " + fixed(choice.seconds) + " s" : "") +
                                 (decoded_again ? ", " + std::to_string(decoded_again) +
                                                      " photo decodes (the photos exceed 'Photo memory (MB)'; "
                                                      "set 'Diffuse term' to skip the pilot)"
                                                : "");
    log("Vertex BRDF: diffuse term " + result.diffuse_choice_note + ".");
  }
  settings.gather.diffuse = result.diffuse_forms;
}
} // namespace

namespace {
// The chunk consumer's normal step (shading_normals.h): refine the chunk's normals from its fits,
// then shade its samples again with them (samples/reshade.h). Keeps the normals in result.
NormalStep shading_normal_refiner(const FitInput &input, const std::vector<LightSource> &lights,
                                  const FitSettings &settings, FitResult &result) {
  const MeshView &mesh = input.mesh;
  result.shading_normals.assign(mesh.normals, mesh.normals + 3 * mesh.vertex_count);
  result.normal_moved.assign(mesh.vertex_count, -1.0f);
  auto adjacency = std::make_shared<const MeshAdjacency>(build_mesh_adjacency(mesh));
  return [&input, &lights, &settings, &result, adjacency](SampleChunk &chunk, const uint8_t *active,
                                                           std::vector<uint8_t> &moved) {
    const auto t = Clock::now();
    moved.assign(chunk.vertex_count, 0);
    const ShadingNormalCounts counts = refine_shading_normals(
        chunk, input.mesh, *adjacency, input.rasters, lights, settings.gather.diffuse, settings.reflectance.lobe,
        &result.fits[chunk.first_vertex], settings.shading_normals, active, result.shading_normals.data(),
        result.normal_moved.data(), moved.data());
    if (!active) {  // the first round decides which vertices the photos determine
      result.shading_normal_counts.refined += counts.refined;
      result.shading_normal_counts.undetermined += counts.undetermined;
    }
    const bool any = std::any_of(moved.begin(), moved.end(), [](uint8_t c) { return c != 0; });
    if (any) {
      std::vector<float> gradients;  // the footprints see the refined normals' variation
      if (settings.gather.footprint && settings.gather.lobe == LobeForm::GgxNH) {
        MeshView shaded = input.mesh;
        shaded.normals = result.shading_normals.data();
        gradients = normal_gradients(shaded);
      }
      reshade_chunk(chunk, input.mesh, result.shading_normals.data(), moved.data(), input.rasters, lights,
                    settings.gather, gradients.empty() ? nullptr : gradients.data());
    }
    result.seconds_normals += seconds_since(t);
    return any;
  };
}

// The report's and log's account of the shading normals: how many the photos determined and how
// far they moved from the mesh's, over the mesh and per viewpoint (the vertices its photos see).
void summarise_shading_normals(const FitInput &input, const VisibilityMasks &masks, const FitSettings &settings,
                               const LogFn &log, FitResult &result) {
  const ShadingNormalCounts &c = result.shading_normal_counts;
  if (c.refined == 0) {
    result.shading_normals.clear();  // nothing moved: the mesh's normals are the shading normals
    result.shading_normal_note = "not refined: no vertex's samples determine its normal (" +
                                 std::to_string(c.undetermined) + " modelled vertices keep the mesh normal)";
    log("Shading normals: " + result.shading_normal_note + ".");
    return;
  }
  const MovedSummary all = summarise_moved(result.normal_moved);
  std::string note = "refined from the photos at " + std::to_string(c.refined) + " vertices (moved from the mesh "
                     "normal: median " + fixed(all.median) + " deg, p95 " + fixed(all.p95) + " deg); " +
                     std::to_string(c.undetermined) + " modelled vertices keep the mesh normal (fewer than " +
                     std::to_string(settings.shading_normals.min_samples) + " usable samples, or lights that do not "
                     "determine it); prior " + fixed(settings.shading_normals.mesh_normal_degrees, 1) + " deg";
  const std::vector<std::vector<size_t>> viewpoints = rasters_by_viewpoint(input.rasters);
  if (viewpoints.size() > 1)
    for (size_t k = 0; k < viewpoints.size(); ++k) {
      std::vector<uint8_t> seen(input.mesh.vertex_count, 0);
      for (size_t v = 0; v < seen.size(); ++v)
        for (size_t r : viewpoints[k])
          if (masks.is_seen(r, v)) {
            seen[v] = 1;
            break;
          }
      const MovedSummary s = summarise_moved(result.normal_moved, seen);
      note += "\n  viewpoint " + std::to_string(k + 1) + " ('" + input.rasters[viewpoints[k].front()].label +
              "'): " + std::to_string(s.count) + " vertices refined, median " + fixed(s.median) + " deg, p95 " +
              fixed(s.p95) + " deg";
    }
  result.shading_normal_note = note;
  log("Shading normals: " + note + ".");
}
} // namespace

namespace {

// One fit run's working state, shared by its steps.
struct FitRun {
  FitInput input;        // its rasters take the corrected cameras (registration); the caller's never change
  FitSettings settings;  // as every stage reads them (settings_for_run)
  VisibilityBackend &visibility;
  ReflectanceFitter *fitter;   // null when settings.fit_reflectance is false
  const ProgressFn &progress;
  const LogFn &log;
  LightPlacement placement;
  std::vector<LightSource> lights;  // per raster
  FitResult result;
};

// The settings as every stage reads them: one T_s and one lobe form for the samples and the fit,
// and the mesh's normal gradients computed once for the pilot's and the fit's gathers.
FitSettings settings_for_run(const FitSettings &given, const MeshView &mesh, const ReflectanceFitter *fitter) {
  FitSettings settings = given;
  settings.reflectance.specular_threshold = settings.gather.specular_threshold;  // one T_s for all stages
  settings.gather.lobe = settings.reflectance.lobe;  // one lobe form for the samples and the fit (lobe.h)
  if (settings.fit_reflectance && settings.gather.footprint && settings.gather.lobe == LobeForm::GgxNH)
    settings.gather.normal_gradients =  // once for the pilot's and the fit's gathers (footprint.h)
        std::make_shared<const std::vector<float>>(normal_gradients(mesh));
  if (settings.fit_reflectance && !fitter) throw ProcessingError("internal: no Reflectance fit back end");
  return settings;
}

// The light file (resolve_light_file) and every raster's light, placed for the mesh.
void resolve_run_lights(FitRun &run) {
  FitResult &result = run.result;
  result.light_file = resolve_light_file(run.settings.light_file, run.input.rasters, run.input.project_path);
  run.placement = light_placement_of(run.input.mesh, run.settings.dome_radius, run.settings.light_unit_scale);
  run.lights = resolve_lights(run.input.rasters, result.light_file, run.placement);
  result.light_model = describe_lights(run.lights, run.placement);
  run.log("Lights: " + result.light_model + ", from '" + result.light_file + "'.");
}

// Where the outputs go, checked before any work: never over an input file, and every output
// writable under the overwrite policy (base/output_file.h).
void check_output_paths(FitRun &run) {
  const FitInput &input = run.input;
  const FitSettings &settings = run.settings;
  FitResult &result = run.result;
  result.output_ply = settings.output_ply.empty() ? default_output_path(input.project_path) : settings.output_ply;
  for (const std::string &protected_path : {input.project_path, input.mesh_path})
    if (!protected_path.empty() && result.output_ply == protected_path)
      throw InputError("The output '" + result.output_ply + "' would overwrite an input file: choose another 'outputPly'.");
  check_output_path(report_path_for(result.output_ply), settings.overwrite, "Output PLY");
  if (settings.registration.enabled)
    check_output_path(registered_project_path(result.output_ply), settings.overwrite, "Output PLY");
  result.output_note = check_output_path(result.output_ply, settings.overwrite, "Output PLY");
}

// The rasters and lights of the run take the registration's current cameras.
void take_registered_cameras(FitRun &run) {
  run.input.rasters = run.result.registration.rasters;
  run.lights = resolve_lights(run.input.rasters, run.result.light_file, run.placement);
}

// Whether the registration's corrections wait for the residual check (check_corrections_by_residual)
// before the run takes them: then the depth passes run at the given cameras, so that a refused
// correction costs no second pass.
bool corrections_checked_by_residual(const FitSettings &settings) {
  return settings.registration.enabled && settings.registration_residual.enabled && settings.fit_reflectance;
}

// Each viewpoint's camera measured against its photos and corrected above the threshold
// (registration.h): the rest of the run uses the corrected cameras, and an .lp's directions,
// given in the camera frame, follow them; after the residual check where it runs.
void refine_cameras(FitRun &run, PhotoCache &photos) {
  if (!run.settings.registration.enabled) return;
  if (run.progress && !run.progress(0.0f, "registration")) throw ProcessingError("cancelled");
  FitResult &result = run.result;
  const auto started = Clock::now();
  result.registration = refine_registration(run.input.mesh, run.input.rasters, run.lights, photos, run.visibility,
                                            run.settings.registration, run.log);
  if (result.registration.any_applied()) {
    result.registered_project = registered_project_path(result.output_ply);
    if (!corrections_checked_by_residual(run.settings)) take_registered_cameras(run);  // else after the check
  }
  result.seconds_registration = seconds_since(started);
}

// The residual of viewpoint v's photos (fit/residual_alignment.h) at any camera, with `masks`.
ViewpointResidual viewpoint_residual(FitRun &run, const ViewpointRegistration &v, PhotoCache &photos,
                                     const VisibilityMasks &masks, const std::function<void(SampleChunk &)> &prepare) {
  const ResidualAlignmentSettings &check = run.settings.registration_residual;
  return ViewpointResidual(run.input.mesh, run.input.rasters, v.rasters, run.lights, masks, run.settings.gather,
                           run.settings.reflectance, photos, prepare, check.pilot_vertices, check.trimmed_share);
}

// Each viewpoint the registration corrected, checked by the fitted model's residual
// (fit/residual_alignment.h) with the masks made at the given cameras: refused (camera kept) where
// the corrected camera's residual is higher than the given one's by more than refuse_margin.
// Returns true when a correction was taken: the run then uses the corrected cameras and needs masks
// made at them.
bool check_corrections_by_residual(FitRun &run, PhotoCache &photos, const VisibilityMasks &masks,
                                   const std::function<void(SampleChunk &)> &prepare) {
  RegistrationResult &registration = run.result.registration;
  if (!corrections_checked_by_residual(run.settings) || !registration.any_applied()) return false;
  if (run.progress && !run.progress(0.4f, "registration check")) throw ProcessingError("cancelled");
  const auto started = Clock::now();
  for (ViewpointRegistration &v : registration.viewpoints) {
    if (!v.applied) continue;
    ViewpointResidual residual = viewpoint_residual(run, v, photos, masks, prepare);
    if (residual.pilot_vertices() < run.settings.registration.min_vertices) continue;  // taken unchecked
    v.residual_checked = true;
    v.residual_vertices = residual.pilot_vertices();
    v.residual_given = residual.at(v.given);
    v.residual_corrected = v.residual_final = residual.at(v.corrected);
    if (!(v.residual_corrected <= v.residual_given * (1 + run.settings.registration_residual.refuse_margin))) {
      v.refused = true, v.applied = false;
      v.corrected = v.given;
      for (size_t r : v.rasters) registration.rasters[r].shot = v.given;
      run.log("Registration: " + describe_registration(v, run.settings.registration) + ".");
    }
  }
  run.result.seconds_registration += seconds_since(started);
  if (!registration.any_applied()) {
    run.result.registered_project.clear();
    return false;
  }
  take_registered_cameras(run);
  return true;
}

// Each correction the residual confirmed, its shift and then its roll refined to the residual's
// minimum with masks made at the corrected camera. Returns true when a camera moved: the masks must be made again,
// because the camera pass's rim footprints follow the camera to a fraction of a pixel (masks made
// 0.06 px from the camera cost bunny 6 % of its relit error).
bool refine_corrections_by_residual(FitRun &run, PhotoCache &photos, const VisibilityMasks &masks,
                                    const std::function<void(SampleChunk &)> &prepare) {
  RegistrationResult &registration = run.result.registration;
  const auto started = Clock::now();
  bool moved = false;
  for (ViewpointRegistration &v : registration.viewpoints) {
    if (!v.applied || !v.residual_checked) continue;
    ViewpointResidual residual = viewpoint_residual(run, v, photos, masks, prepare);
    const ResidualAlignmentSettings &check = run.settings.registration_residual;
    const ResidualShift shift = refine_shift_by_residual(residual, v.corrected, check);
    v.residual_corrected = v.residual_final = shift.residual_start;
    if (shift.beyond_trust) {  // a biased residual refines no roll either
      v.residual_beyond_trust = true;
      v.residual_found_x = shift.found_dx, v.residual_found_y = shift.found_dy;
      v.residual_trusted_px = check.trusted_shift_px;
      run.log("Registration: " + describe_registration(v, run.settings.registration) + ".");
      continue;
    }
    const Shot shifted = shifted_shot(v.corrected, shift.dx, shift.dy);
    const ResidualRoll roll = refine_roll_by_residual(residual, shifted, check, shift.residual_end);
    v.residual_final = roll.residual_end;
    if (shift.moved || roll.moved) {
      v.corrected = rolled_shot(shifted, roll.roll);
      v.refined_x = shift.dx, v.refined_y = shift.dy, v.refined_roll = roll.roll;
      v.shift_x += shift.dx, v.shift_y += shift.dy;
      for (size_t r : v.rasters) registration.rasters[r].shot = v.corrected;
      moved = true;
    }
    run.log("Registration: " + describe_registration(v, run.settings.registration) + ".");
  }
  if (moved) take_registered_cameras(run);
  run.result.seconds_registration += seconds_since(started);
  return moved;
}

// The depth passes at the run's cameras (visibility masks restricted to the selection), timed and
// described for the report. `between_passes` runs at each progress step (the colour search's
// failure surfaces there).
VisibilityMasks depth_passes(FitRun &run, const std::function<void()> &between_passes = {}) {
  const FitInput &input = run.input;
  FitResult &result = run.result;
  const auto started = Clock::now();
  const ProgressFn vis_progress = [&](float f, const char *s) {
    if (between_passes) between_passes();
    return !run.progress || run.progress(0.4f * f, s);
  };
  VisibilityMasks masks = compute_visibility(input.mesh, input.rasters, run.lights, run.visibility, vis_progress);
  const std::string sizes = describe_pass_sizes(run.visibility.last_pass_sizes());
  result.depth_passes = std::to_string(masks.camera_passes) + " camera pass(es) for " +
                        std::to_string(input.rasters.size()) + " photos (photos of one camera share its pass)" +
                        (sizes.empty() ? std::string() : "; " + sizes);
  restrict_to_vertices(masks, input.vertex_mask);
  result.seconds_visibility += seconds_since(started);
  return masks;
}

// The depth passes (visibility masks restricted to the selection), with every viewpoint's colour
// plan searched beside them (ColorPlanBesidePasses); a required chart that is missing stops the
// passes.
VisibilityMasks visibility_and_colors(FitRun &run, PhotoCache &photos, ColorPlan &colors) {
  FitResult &result = run.result;
  if (run.progress) run.progress(0.0f, "colour calibration");
  ColorPlanBesidePasses color_search(run.input, run.settings, light_directions(run.lights), photos);
  VisibilityMasks masks = depth_passes(run, [&] { color_search.rethrow_if_failed(); });
  colors = color_search.take(run.log, result.seconds_colors);
  result.color_viewpoints_corrected = size_t(std::count_if(
      colors.viewpoints.begin(), colors.viewpoints.end(), [](const ColorCalibration &c) { return c.corrected; }));
  return masks;
}

// Every photo's content (photo_content.h), before any sample is gathered (mostly from the cache):
// the first photo in raster order that cannot be decoded fails the run; photos that are black,
// saturated or identical, and a photo larger than the photo memory, are logged and reported.
void check_photos(FitRun &run, PhotoCache &photos) {
  const std::vector<Raster> &rasters = run.input.rasters;
  FitResult &result = run.result;
  std::vector<PhotoContent> contents(rasters.size());
  std::vector<size_t> photo_bytes(rasters.size(), 0);
  std::vector<std::exception_ptr> photo_errors(rasters.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (long long i = 0; i < (long long)rasters.size(); ++i) {
    const Raster &r = rasters[size_t(i)];
    try {
      const auto photo = photos.get(r.image_path, r.width(), r.height());
      contents[size_t(i)] = analyse_photo(*photo);
      photo_bytes[size_t(i)] = photo->owner ? 0 : photo->pixels.total() * photo->pixels.elemSize();  // host images: not ours
    } catch (...) {
      photo_errors[size_t(i)] = std::current_exception();
    }
  }
  for (const std::exception_ptr &e : photo_errors)
    if (e) std::rethrow_exception(e);
  const size_t largest_photo = photo_bytes.empty() ? 0 : *std::max_element(photo_bytes.begin(), photo_bytes.end());
  const size_t cache_bytes = run.settings.gather.photo_cache_bytes;
  if (largest_photo > cache_bytes) {
    result.memory_note = "photo memory: a decoded photo needs " + std::to_string((largest_photo >> 20) + 1) +
                         " MB, more than 'Photo memory (MB)' (" + std::to_string(cache_bytes >> 20) +
                         " MB): photos are kept one at a time and decoded again for each vertex chunk (slower); "
                         "raise 'Photo memory (MB)' to keep them";
    run.log("Vertex BRDF: " + result.memory_note + ".");
  }
  result.warnings = check_photo_contents(rasters, contents);
  result.warnings.insert(result.warnings.end(), result.registration.warnings.begin(), result.registration.warnings.end());
  for (const std::string &w : result.warnings) run.log(w);
}

// Refuses a run in which no camera sees the mesh, and warns of every raster that sees none of it.
void check_cameras_see_mesh(FitRun &run, const VisibilityMasks &masks) {
  if (std::all_of(masks.seen_count.begin(), masks.seen_count.end(), [](uint32_t c) { return c == 0; }))
    throw InputError("No raster's camera sees the mesh (every vertex is outside every photo, behind its camera or "
                     "back-facing): the registration does not match this mesh. Check that the project's rasters "
                     "were registered to it. Nothing was written.");
  for (size_t i = 0; i < run.input.rasters.size(); ++i)
    if (masks.seen_count[i] == 0) {
      run.result.warnings.push_back("WARNING: raster '" + run.input.rasters[i].label +
                                    "' sees no vertex of the mesh (its camera points elsewhere: check its registration); "
                                    "the other photos were used without it.");
      run.log(run.result.warnings.back());
    }
}

// Every vertex's samples, gathered chunk by chunk and fitted as they stream (consume_chunk):
// colour-corrected, checked against the light file and divided by the lights' fall-off first.
// The material stage's samples are kept in `material_samples` (when it runs). Throws before
// anything is written when the light file contradicts the photos.
void gather_and_fit(FitRun &run, PhotoCache &photos, const VisibilityMasks &masks, ColorPlan &colors,
                    MaterialSampleStore &material_samples, bool with_materials) {
  const FitInput &input = run.input;
  const FitSettings &settings = run.settings;
  const MeshView &mesh = input.mesh;
  FitResult &result = run.result;
  const auto started = Clock::now();
  result.diffuse.resize(mesh.vertex_count);
  if (settings.fit_reflectance) result.fits.resize(mesh.vertex_count);
  const bool correct = colors.any_corrected();
  LightAgreement agreement(input.rasters.size());
  const ProgressFn gather_progress = [&](float f, const char *s) {
    return !run.progress || run.progress(0.4f + 0.55f * f, s);
  };
  const NormalStep refine_normals = settings.fit_reflectance && settings.shading_normals.enabled
                                        ? shading_normal_refiner(input, run.lights, settings, result)
                                        : NormalStep();
  ReflectanceFitter *fitter = settings.fit_reflectance ? run.fitter : nullptr;
  result.gather = gather_samples(
      mesh, input.rasters, run.lights, masks, settings.gather, photos,
      [&](SampleChunk &chunk) {
        if (correct) correct_samples(colors, chunk);
        agreement.add(chunk, mesh, run.lights);
        apply_light_falloff(chunk, mesh, run.lights);  // after the correction, which need not be linear
        consume_chunk(chunk, fitter, settings.reflectance, settings.photo_shadows, refine_normals,
                      settings.shading_normals.rounds, result, result.seconds_fit);
        if (with_materials) material_samples.add_chunk(chunk, &result.fits[chunk.first_vertex], settings.reflectance);
      },
      gather_progress);
  result.seconds_gather = seconds_since(started);
  if (refine_normals) summarise_shading_normals(input, masks, settings, run.log, result);
  result.light_agreement = weakest_light_agreement(agreement, input.rasters);
  check_light_agreement(agreement, input.rasters, result.light_file);
  result.colors = std::move(colors.viewpoints);
}

// The stages after the per-vertex fit, timed each: materials (materials.h), the neighbour fill,
// the material labels of the filled vertices, and the albedo deconvolution.
void stages_after_fit(FitRun &run, const VisibilityMasks &masks, const MaterialSampleStore &material_samples,
                      bool with_materials) {
  const FitSettings &settings = run.settings;
  FitResult &result = run.result;
  auto t = Clock::now();
  if (with_materials) run_material_stage(run.input, settings, material_samples, run.log, result);
  result.seconds_materials = seconds_since(t);
  t = Clock::now();
  if (settings.fit_reflectance) fill_gaps(run.input, settings, run.log, result);
  result.seconds_fill = seconds_since(t);
  if (with_materials) propagate_material_labels(run.input.mesh, result.fits, result.materials.label);
  t = Clock::now();
  if (settings.fit_reflectance && settings.deconvolve_albedo)
    deconvolve_fit_albedo(run.input, settings, masks, run.log, result);
  result.seconds_deconvolution = seconds_since(t);
}

// The PLY, its report and, when a camera was corrected, the registered project: committed
// together under a lock on their folder, so a concurrent run writing the same files waits here.
// `given` is the caller's input (the registered project rewrites its cameras); `started`: when
// the outputs' step began (the report's output time).
void commit_outputs(FitRun &run, const FitInput &given, Clock::time_point started) {
  const FitSettings &settings = run.settings;
  FitResult &result = run.result;
  OutputFolderLock lock(directory_of(result.output_ply));
  if (settings.overwrite == OverwritePolicy::Refuse)  // again: another run may have written it meanwhile
    check_output_path(result.output_ply, settings.overwrite, "Output PLY");
  AtomicOutput ply(result.output_ply), report(report_path_for(result.output_ply));
  std::unique_ptr<AtomicOutput> project;
  if (result.registration.any_applied()) {
    project = std::make_unique<AtomicOutput>(result.registered_project);
    stage_text_file(*project,
                    registered_project_text(given.project_path, given.mesh_path, given.rasters, result.registration));
  }
  MeshView shaded = run.input.mesh;  // the geometry as given, with the normals the model was fitted with
  if (!result.shading_normals.empty()) shaded.normals = result.shading_normals.data();
  stage_result_ply(ply, shaded, result.colors_rgba, result.attributes);
  result.seconds_output = seconds_since(started);
  result.report += output_report_line(result);
  stage_text_file(report, result.report);
  ply.commit();
  report.commit((long long)result.report.size());
  if (project) project->commit();
}

// Display colours, quality, attributes and report of a finished fit (run/fit_outputs.h), then
// the files (commit_outputs); the report is logged line by line.
void write_outputs(FitRun &run, const FitInput &given) {
  FitResult &result = run.result;
  const auto started = Clock::now();
  build_outputs(run.input, run.settings, result);
  if (result.vertices_coloured == 0) {
    result.warnings.push_back("WARNING: no vertex got a colour or a model: every sample was shadowed, saturated or "
                              "unusable (see the counts below).");
    run.log(result.warnings.back());
  }
  result.report = build_report(run.input, run.settings, result);
  commit_outputs(run, given, started);
  std::istringstream lines(result.report);
  for (std::string line; std::getline(lines, line);) run.log(line);
}

} // namespace

FitResult run_fit(const FitInput &given, const FitSettings &settings, VisibilityBackend &visibility,
                  ReflectanceFitter *fitter, const ProgressFn &progress, const LogFn &log) {
  validate_input(given);
  // The registration's camera pass at a given camera is the depth passes' first (camera_pass_cache.h).
  CameraPassCache passes(visibility, given.mesh.vertex_count);
  FitRun run{given, settings_for_run(settings, given.mesh, fitter), passes, fitter, progress, log, {}, {}, {}};
  FitResult &result = run.result;
  result.visibility_backend = visibility.name();
  result.fit_backend = run.settings.fit_reflectance ? fitter->name() : "";
  resolve_run_lights(run);
  check_output_paths(run);
  result.normals_source = describe_normals_source(given.mesh_path);
  log(result.normals_source + ".");

  // The photos decode in the background while the GL passes run (photo_prefetch.h); a photo that
  // cannot be decoded fails before any sample is gathered, so before anything is written.
  const GatherSettings &gather = run.settings.gather;
  PhotoCache photos(gather.encoding, gather.saturation_level, gather.photo_cache_bytes, gather.host_photos);
  const std::unique_ptr<PhotoPrefetch> prefetch = start_photo_prefetch(photos, run.input.rasters);
  refine_cameras(run, photos);
  ColorPlan colors;
  VisibilityMasks masks = visibility_and_colors(run, photos, colors);
  prefetch->finish();
  auto t = Clock::now();
  check_photos(run, photos);
  result.seconds_photo_checks = seconds_since(t);
  // The same colour correction and light fall-off as the fit, for the stages that fit a subset.
  const std::function<void(SampleChunk &)> prepare = [&](SampleChunk &chunk) {
    if (colors.any_corrected()) correct_samples(colors, chunk);
    apply_light_falloff(chunk, run.input.mesh, run.lights);
  };
  // The registration's corrections, checked and refined by the fitted model's residual: the masks
  // follow the cameras (a refused correction costs no second pass).
  if (check_corrections_by_residual(run, photos, masks, prepare)) {
    masks = depth_passes(run);
    if (refine_corrections_by_residual(run, photos, masks, prepare)) masks = depth_passes(run);
  }
  check_cameras_see_mesh(run, masks);

  t = Clock::now();
  decide_diffuse_form(run.input, run.lights, masks, photos, prepare, log, run.settings, result);
  result.seconds_pilot = seconds_since(t);

  const bool with_materials = run.settings.fit_reflectance && run.settings.materials;
  MaterialSampleStore material_samples(with_materials ? run.input.mesh.vertex_count : 0);
  gather_and_fit(run, photos, masks, colors, material_samples, with_materials);
  stages_after_fit(run, masks, material_samples, with_materials);
  write_outputs(run, given);
  if (progress) progress(1.0f, "done");
  return std::move(run.result);
}

} // namespace vbrdf
