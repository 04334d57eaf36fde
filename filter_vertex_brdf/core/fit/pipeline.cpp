#include "fit/pipeline.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <sstream>

#include "base/errors.h"
#include "base/file_util.h"
#include "inputs/light_file.h"
#include "calibration/color_plan.h"
#include "inputs/light_source.h"
#include "inputs/mesh_file.h"
#include "inputs/photo_content.h"
#include "samples/light_check.h"
#include "io/output_ply.h"
#include "fit/phong_fit_gpu.h"
#include "io/result_schema.h"
#include "visibility/visibility_gl.h"
#include "base/vec3.h"

namespace vbrdf {

namespace {



std::string report_path_for(const std::string &ply) { return strip_extension(ply) + "_report.txt"; }

uint8_t srgb_byte(float linear) { return uint8_t(std::lround(255.0f * linear_to_srgb(linear))); }

int bit(uint16_t flag) {
  int i = 0;
  while (flag > 1) flag >>= 1, ++i;
  return i;
}

} // namespace

std::string default_output_path(const std::string &project_path) {
  if (project_path.empty()) return "vertex_brdf.ply";
  return strip_extension(project_path) + "_brdf.ply";
}

void validate_input(const FitInput &input) {
  validate_mesh(input.mesh, input.mesh_name);
  if (input.rasters.empty())
    throw InputError("The project has no rasters: load the registered photos (File > Import Raster) or open the .mlp.");
  for (size_t r = 0; r < input.rasters.size(); ++r) {
    const Raster &raster = input.rasters[r];
    if (!shot_is_valid(raster.shot))
      throw InputError("Raster " + std::to_string(r) + " ('" + raster.label +
                       "') has no valid camera: register it to the mesh first.");
    if (shot_is_identity(raster.shot))
      throw InputError("Raster " + std::to_string(r) + " ('" + raster.label +
                       "') has an identity camera (at the world origin, looking along -z): it was not registered. "
                       "Register it to the mesh first, or remove the raster.");
    if (!file_exists(raster.image_path))
      throw InputError("Raster " + std::to_string(r) + " ('" + raster.label + "'): photo '" + raster.image_path +
                       "' is missing. Restore the file or fix the path in the project.");
  }
}

std::unique_ptr<VisibilityBackend> make_visibility_backend(const MeshView &mesh, const FitSettings &settings,
                                                           const std::function<void *(const char *)> &get_proc,
                                                           const LogFn &log) {
  if (settings.visibility_choice != VisibilityChoice::CPU) {
    if (!get_proc) {
      if (settings.visibility_choice == VisibilityChoice::GL)
        throw ProcessingError("'Visibility' is set to GPU (OpenGL), but no GL context is available: set 'Visibility' "
                            "to Auto or CPU (ray cast).");
      log("Visibility: no GL context, using the CPU ray caster.");
    } else {
      try {
        auto gl = make_gl_visibility(mesh, get_proc, settings.visibility);
        log(std::string("Visibility: ") + gl->name() + ".");
        return gl;
      } catch (const ProcessingError &e) {
        if (settings.visibility_choice == VisibilityChoice::GL)
          throw ProcessingError(std::string("'Visibility' is set to GPU (OpenGL), but ") + e.what() +
                                " Set 'Visibility' to Auto or CPU (ray cast).");
        log(std::string("Visibility: GL depth passes unavailable (") + e.what() + "); using the CPU ray caster.");
      }
    }
  }
  auto cpu = make_cpu_visibility(mesh, settings.visibility);
  log(std::string("Visibility: ") + cpu->name() + ".");
  return cpu;
}

namespace {
class CpuFitter : public PhongFitter {
public:
  // `why`: how it came to be chosen, appended to the name (the report shows it).
  explicit CpuFitter(const std::string &why = "") : name_("CPU (double, OpenMP)" + (why.empty() ? "" : "; " + why)) {}
  const char *name() const override { return name_.c_str(); }
  void fit_chunk(const SampleChunk &chunk, const PhongFitOptions &o, VertexFit *out) override {
    fit_chunk_cpu(chunk, o, out);
  }

private:
  std::string name_;
};

class GpuFitter : public PhongFitter {
public:
  explicit GpuFitter(const GetProcAddressFn &get_proc) : gpu_(get_proc), name_("GPU compute shader, " + gpu_.device()) {}
  const char *name() const override { return name_.c_str(); }
  std::string device() const { return gpu_.device(); }
  void fit_chunk(const SampleChunk &chunk, const PhongFitOptions &o, VertexFit *out) override {
    gpu_.fit_chunk(chunk, o, out);
  }

private:
  PhongFitGpu gpu_;
  std::string name_;
};

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
  return plan_color_correction(input.rasters, lights_world, cs, load, log);
}

std::string color_report(const FitResult &r, const FitSettings &settings) {
  if (settings.color_correction == ColorCorrectionChoice::Off) return "colour correction: off\n";
  std::ostringstream rep;
  for (size_t v = 0; v < r.colors.size(); ++v) {
    const ColorCalibration &c = r.colors[v];
    rep << "colour correction, viewpoint " << v + 1 << " (" << c.divisor.size() << " photos): ";
    if (!c.corrected) {
      rep << (c.patches.empty() ? "no chart found" : "chart not usable") << ": colours uncorrected\n";
      continue;
    }
    const double heldout = std::min({c.fit.heldout_matrix, c.fit.heldout_curve_matrix, c.fit.heldout_polynomial});
    const std::string exposure = c.exposure_normalised
                                     ? "normalised per photo (light intensity varies)"
                                     : "one for all photos (divisor " + fixed(c.divisor.at(0), 4) + ")";
    rep << correction_model_name(c.correction.model) << " from " << (c.chart.detected ? "the detected" : "the given")
        << " chart, " << c.fit.patches << " patches, CIEDE2000 " << fixed(c.fit.before) << " -> " << fixed(c.fit.after)
        << " (held-out " << fixed(heldout) << "); exposure " << exposure
        << "; samples corrected in linear space before the fit\n";
  }
  return rep.str();
}

// Everything the chunk consumer produces, per vertex.
void consume_chunk(SampleChunk &chunk, PhongFitter *fitter, const PhongFitOptions &options, FitResult &r,
                   double &fit_seconds) {
  r.rim_samples_demoted += prefer_clean_samples(chunk);
  estimate_diffuse_chunk(chunk, &r.diffuse[chunk.first_vertex]);
  if (!fitter) return;
  const auto t = Clock::now();
  fitter->fit_chunk(chunk, options, &r.fits[chunk.first_vertex]);
  // Diffuse-only vertices take the robust basic colour (outlier rejection) when it is clean.
  for (uint32_t i = 0; i < chunk.vertex_count; ++i) {
    VertexFit &f = r.fits[chunk.first_vertex + i];
    const DiffuseEstimate &e = r.diffuse[chunk.first_vertex + i];
    if (f.status == kFitDiffuseOnly && e.valid && !e.from_mixed_pixels)
      set_diffuse_only_reflectance(chunk.samples.data() + chunk.offsets[i], chunk.offsets[i + 1] - chunk.offsets[i],
                                   options, e.rgb, f);
  }
  // Vertices the strict rules left without a sample (all grazing, all mixed): the fallback fit
  // from what there is, on the CPU for either back end (few vertices, and one code path).
#pragma omp parallel for schedule(dynamic, 64)
  for (long long i = 0; i < (long long)chunk.vertex_count; ++i) {
    VertexFit &f = r.fits[chunk.first_vertex + size_t(i)];
    const uint32_t begin = chunk.offsets[size_t(i)], end = chunk.offsets[size_t(i) + 1];
    if (f.status == kFitNone && end > begin) fit_vertex_weak(chunk.samples.data() + begin, end - begin, options, f);
  }
  fit_seconds += seconds_since(t);
}

// Material stage hook (materials.h, issue 16): after the per-vertex fit of every chunk, before the
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
  r.materials = fit_materials(input.mesh, store, settings.phong, settings.material_options, rgb.data(), valid.data(), r.fits);
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

// Linear diffuse reflectance shown and written: the fitted k_d C where the Phong fit has samples,
// else the basic estimate (mixed-pixel fallback included), else nothing.
bool displayed_reflectance(const FitResult &r, size_t v, float rho[3]) {
  if (!r.fits.empty() && r.fits[v].status != kFitNone) {
    for (int c = 0; c < 3; ++c) rho[c] = r.fits[v].kd * r.fits[v].color[c];
    return true;
  }
  for (int c = 0; c < 3; ++c) rho[c] = r.diffuse[v].valid ? r.diffuse[v].rgb[c] : 0.0f;
  return r.diffuse[v].valid;
}

void build_outputs(const FitInput &input, const FitSettings &settings, FitResult &r) {
  const size_t n = input.mesh.vertex_count;
  r.colors_rgba.assign(4 * n, 0);
  r.quality.assign(n, 0.0f);
  std::vector<VertexRecord> records(n);
  for (size_t v = 0; v < n; ++v) {
    const DiffuseEstimate &e = r.diffuse[v];
    VertexRecord &rec = records[v];
    float rho[3];
    const bool coloured = displayed_reflectance(r, v, rho);
    for (int c = 0; c < 3; ++c) rec.diffuse[c] = rho[c];
    rec.n_visible = e.n_seen, rec.n_diffuse = e.n_diffuse, rec.n_specular = e.n_specular;
    // coloured = 2: the colour comes only from pixels at a silhouette or contact (own-surface texels
    // of a straddling footprint, or mixed pixels): lower confidence than clean pixels.
    const bool mixed = e.from_mixed_pixels || e.from_rim_pixels;
    const bool from_neighbours = !r.fits.empty() && r.fits[v].status == kFitFromNeighbours;
    rec.coloured = coloured ? (from_neighbours ? 3.0f : mixed ? 2.0f : 1.0f) : 0.0f;
    if (v < r.materials.label.size()) rec.material = float(r.materials.label[v]);
    if (!r.fits.empty()) {
      const VertexFit &f = r.fits[v];
      rec.fit = f;
      r.quality[v] = settings.quality == QualityOutput::SQ ? f.sq : settings.quality == QualityOutput::RMSE ? f.rmse : f.dq;
      r.fit_full += f.status == kFitFull, r.fit_diffuse_only += f.status == kFitDiffuseOnly, r.fit_none += f.status == kFitNone;
      r.fit_weak += f.status == kFitFromWeakSamples, r.fit_neighbours += f.status == kFitFromNeighbours;
      r.fit_converged += f.status == kFitFull && f.converged, r.fit_iterations += f.iterations;
    }
    if (coloured) {
      for (int c = 0; c < 3; ++c) r.colors_rgba[4 * v + size_t(c)] = srgb_byte(rho[c]);
      r.colors_rgba[4 * v + 3] = 255;
      ++r.vertices_coloured;
      r.vertices_from_mixed += mixed;
    } else {
      // Never silently painted: the input colour stays (MeshLab's default white when none).
      for (int c = 0; c < 4; ++c)
        r.colors_rgba[4 * v + size_t(c)] = input.mesh_colors.size() == 4 * n ? input.mesh_colors[4 * v + size_t(c)] : 255;
      if (e.n_seen == 0) ++r.vertices_unseen; else ++r.vertices_no_diffuse;
    }
  }
  r.attributes = result_attributes(records, !r.fits.empty());  // by name, in the schema's file order
}

std::string build_report(const FitInput &input, const FitSettings &settings, const FitResult &r) {
  const MeshView &mesh = input.mesh;
  const size_t n = mesh.vertex_count;
  const GatherStats &g = r.gather;
  std::ostringstream rep;
  rep << "filter_vertex_brdf report\n";
  for (const std::string &w : r.warnings) rep << w << "\n";
  rep << "mesh: " << input.mesh_name << " (" << n << " vertices, " << mesh.index_count / 3 << " triangles)\n"
      << r.normals_source << "\n"
      << (r.memory_note.empty() ? std::string() : r.memory_note + "\n")
      << "photos: " << input.rasters.size() << ", lights: " << r.light_file << " (" << r.light_model << ")\n"
      << "lights against the photos (predicted irradiance vs brightness): "
      << (r.light_agreement.empty() ? std::string("too few samples to tell") : r.light_agreement) << "\n"
      << "visibility back end: " << r.visibility_backend << "\n"
      << color_report(r, settings)
      << "thresholds: T_s (R.E) = " << settings.gather.specular_threshold
      << ", T_d (N.L) = " << settings.gather.diffuse_threshold << "\n"
      << "vertices coloured: " << r.vertices_coloured << " (" << percent(r.vertices_coloured, n) << ")\n"
      << "  of which from mixed pixels only (silhouette/border/contact; coloured = 2): " << r.vertices_from_mixed << "\n"
      << "vertices seen but without a usable sample (kept their colour): " << r.vertices_no_diffuse << "\n"
      << "vertices seen by no photo (skipped, kept their colour; need another viewpoint): " << r.vertices_unseen << "\n"
      << "vertex-photo pairs: " << g.pairs << ", samples stored (seen): " << g.stored << "\n";
  const std::pair<uint16_t, const char *> flag_names[] = {
      {kOffImage, "off image / behind camera"}, {kBackFacing, "back-facing"}, {kOccluded, "occluded"},
      {kAttachedShadow, "facing away from the light"}, {kCastShadow, "in cast shadow"},
      {kSaturated, "saturated (not used)"},
      {kMixedPixel, "mixed pixel at a silhouette/contact, no own-surface texel (used only where nothing else is: fit_status 4)"},
      {kRimFootprint, "rim footprint: colour from its own-surface texels (used where the vertex has < 2 clean samples)"},
      {kGrazing, "grazing light (N.L < T_d)"}, {kHighlight, "highlight (R.E > T_s)"}};
  for (const auto &f : flag_names)
    rep << "  " << f.second << ": " << g.flag_counts[bit(f.first)] << " (" << percent(g.flag_counts[bit(f.first)], g.pairs) << ")\n";
  rep << "  rim samples left out because their vertex has >= 2 clean samples: " << r.rim_samples_demoted << "\n";
  if (!r.fits.empty()) {
    rep << "Phong fit back end: " << r.fit_backend << "\n"
        << "  full fits (k_d, k_s, alpha, C): " << r.fit_full << "\n"
        << "  diffuse-only (k_s = 0; k_s/alpha stages skipped: fewer than " << settings.phong.min_specular_samples
        << " clean highlight samples and fewer than " << settings.phong.min_lobe_samples
        << " samples with R.E > " << settings.phong.lobe_threshold << ", or no specular term): " << r.fit_diffuse_only << "\n"
        << "  from weak samples only (grazing N.L < T_d and/or mixed pixels; fit_status 4): " << r.fit_weak << "\n"
        << "  from neighbours (no usable sample of their own; fit_status 3): " << r.fit_neighbours << "\n"
        << "  no model (sentinels: k_d = k_s = shininess = 0; unseen, or no modelled neighbour): " << r.fit_none << "\n"
        << "  converged before the cap of " << settings.phong.max_iterations << " iterations: " << r.fit_converged
        << " of " << r.fit_full << " full fits; alpha iterations run: " << r.fit_iterations << " of at most "
        << uint64_t(r.fit_full + r.fit_diffuse_only) * uint64_t(std::max(0, settings.phong.max_iterations)) << "\n";
    rep << (settings.materials ? r.materials.report : "materials: off (per-vertex lobes only)\n");
  } else {
    rep << "Phong fit: off (basic diffuse colour only)\n";
  }
  // What skipping saved, estimated from the measured rates (the skipped work was never run).
  const double per_pair = r.seconds_gather > 0 && g.stored ? (r.seconds_gather - r.seconds_fit) / double(g.stored) : 0;
  rep << "skipped work (estimated saving): " << g.rasters_skipped << " raster x chunk pairs not read; "
      << (g.pairs - g.stored) << " vertex-photo pairs not sampled (not seen), ~"
      << fixed(per_pair * double(g.pairs - g.stored), 2) << " s";
  if (!r.fits.empty()) {
    const uint64_t fitted = r.fit_full + r.fit_diffuse_only;
    const uint64_t cap_work = fitted * uint64_t(std::max(0, settings.phong.max_iterations));
    // Cost model: set-up of a vertex ~ 2 iterations (tests/bench/FIT_PERFORMANCE.md).
    const double per_iteration = r.seconds_fit / double(std::max<uint64_t>(1, r.fit_iterations + 2 * fitted));
    rep << "; " << (cap_work - std::min<uint64_t>(cap_work, r.fit_iterations))
        << " shininess iterations not run (diffuse-only or converged vertices), ~"
        << fixed(per_iteration * double(cap_work - std::min<uint64_t>(cap_work, r.fit_iterations)), 2) << " s";
  }
  rep << "\n";
  rep << "time: visibility " << fixed(r.seconds_visibility) << " s, samples " << fixed(r.seconds_gather - r.seconds_fit)
      << " s, fit " << fixed(r.seconds_fit) << " s (" << g.chunks << " chunk(s), " << g.photo_loads << " photo decodes, "
      << g.rasters_skipped << " raster x chunk pairs skipped)\n";
  return rep.str();
}
} // namespace

namespace {
// True for GL implementations that rasterise on the CPU (Mesa llvmpipe/softpipe/swrast, lavapipe,
// Microsoft's GDI renderer): there the compute shader runs on the same cores as the CPU fit, and
// slower (tests/bench/FIT_PERFORMANCE.md: the CPU reference is 2.4-3.7x faster at the same error).
bool software_renderer(const std::string &device) {
  std::string d = device;
  std::transform(d.begin(), d.end(), d.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  for (const char *name : {"llvmpipe", "softpipe", "swrast", "software rasterizer", "lavapipe", "gdi generic"})
    if (d.find(name) != std::string::npos) return true;
  return false;
}
} // namespace

std::unique_ptr<PhongFitter> make_phong_fitter(const FitSettings &settings,
                                               const std::function<void *(const char *)> &get_proc, const LogFn &log) {
  if (settings.fit_backend != FitBackendChoice::CPU) {
    if (get_proc) {
      try {
        std::unique_ptr<GpuFitter> gpu(new GpuFitter(get_proc));
        if (settings.fit_backend == FitBackendChoice::Auto && software_renderer(gpu->device())) {
          std::unique_ptr<PhongFitter> cpu(new CpuFitter(
              "Auto chose it over the compute shader: the GL context is a software renderer (" + gpu->device() + ")"));
          log(std::string("Phong fit: ") + cpu->name() + ". Set 'fitBackend' to GPU to use the shader anyway.");
          return cpu;
        }
        log(std::string("Phong fit: ") + gpu->name() + ".");
        return std::unique_ptr<PhongFitter>(gpu.release());
      } catch (const ProcessingError &e) {
        if (settings.fit_backend == FitBackendChoice::GPU)
          throw ProcessingError(std::string("'Fit back end' is set to GPU (compute shader), but ") + e.what() +
                                " Set 'Fit back end' to Auto or CPU (reference).");
        log(std::string("Phong fit: GPU back end unavailable (") + e.what() + "); using the CPU reference.");
      }
    } else if (settings.fit_backend == FitBackendChoice::GPU) {
      throw ProcessingError("'Fit back end' is set to GPU (compute shader), but no GL context is available: set "
                            "'Fit back end' to Auto or CPU (reference).");
    }
  }
  std::unique_ptr<PhongFitter> cpu(new CpuFitter());
  log(std::string("Phong fit: ") + cpu->name() + ".");
  return cpu;
}

FitResult run_fit(const FitInput &input, const FitSettings &settings_in, VisibilityBackend &visibility,
                  PhongFitter *fitter, const ProgressFn &progress, const LogFn &log) {
  validate_input(input);
  FitSettings settings = settings_in;
  settings.phong.specular_threshold = settings.gather.specular_threshold;  // one T_s for all stages
  if (settings.fit_reflectance && !fitter) throw ProcessingError("internal: no Phong fit back end");
  const MeshView &mesh = input.mesh;
  FitResult result;
  result.visibility_backend = visibility.name();
  result.fit_backend = settings.fit_reflectance ? fitter->name() : "";

  std::vector<std::string> checked;
  result.light_file = settings.light_file.empty() ? find_default_light_file(input.rasters, input.project_path, &checked)
                                                  : settings.light_file;
  if (result.light_file.empty() && checked.empty())
    throw InputError("No light file (.lp) found beside the project or the photos: set 'lightFile' to the .lp "
                     "that gives each photo's light direction.");
  if (result.light_file.empty()) {
    std::string why;
    for (const std::string &c : checked) why += "\n  " + c;
    throw InputError("No light file (.lp) beside the project or the photos has an entry for every raster: set "
                     "'lightFile' to the .lp that gives each photo's light direction, or add the missing lines." +
                     why);
  }
  const LightPlacement placement =
      light_placement_of(mesh, settings.dome_radius, settings.light_unit_scale);
  const std::vector<LightSource> lights = resolve_lights(input.rasters, result.light_file, placement);
  result.light_model = describe_lights(lights, placement);
  log("Lights: " + result.light_model + ", from '" + result.light_file + "'.");

  result.output_ply = settings.output_ply.empty() ? default_output_path(input.project_path) : settings.output_ply;
  for (const std::string &protected_path : {input.project_path, input.mesh_path})
    if (!protected_path.empty() && result.output_ply == protected_path)
      throw InputError("The output '" + result.output_ply + "' would overwrite an input file: choose another 'outputPly'.");

  check_output_path(report_path_for(result.output_ply), settings.overwrite, "Output PLY");
  result.output_note = check_output_path(result.output_ply, settings.overwrite, "Output PLY");
  result.normals_source = describe_normals_source(input.mesh_path);
  log(result.normals_source + ".");

  // Photos are validated (size, bit depth, content) before the long passes start.
  PhotoCache photos(settings.gather.encoding, settings.gather.saturation_level, settings.gather.photo_cache_bytes);
  std::vector<PhotoContent> contents;
  size_t largest_photo = 0;
  for (const Raster &r : input.rasters) {
    const auto photo = photos.get(r.image_path, r.width(), r.height());
    contents.push_back(analyse_photo(*photo));
    largest_photo = std::max(largest_photo, photo->pixels.total() * photo->pixels.elemSize());
  }
  if (largest_photo > settings.gather.photo_cache_bytes) {
    result.memory_note = "photo memory: a decoded photo needs " + std::to_string((largest_photo >> 20) + 1) +
                         " MB, more than 'Photo memory (MB)' (" + std::to_string(settings.gather.photo_cache_bytes >> 20) +
                         " MB): photos are kept one at a time and decoded again for each vertex chunk (slower); "
                         "raise 'Photo memory (MB)' to keep them";
    log("Vertex BRDF: " + result.memory_note + ".");
  }
  result.warnings = check_photo_contents(input.rasters, contents);
  for (const std::string &w : result.warnings) log(w);
  // Before the long passes: a required chart that is missing fails early.
  if (progress) progress(0.0f, "colour calibration");
  ColorPlan colors = plan_colors(input, settings, light_directions(lights), photos, log);
  const bool correct = colors.any_corrected();
  result.color_viewpoints_corrected = size_t(std::count_if(
      colors.viewpoints.begin(), colors.viewpoints.end(), [](const ColorCalibration &c) { return c.corrected; }));

  auto t = Clock::now();
  const ProgressFn vis_progress = [&](float f, const char *s) { return !progress || progress(0.4f * f, s); };
  const VisibilityMasks masks = compute_visibility(mesh, input.rasters, lights, visibility, vis_progress);
  result.seconds_visibility = seconds_since(t);
  if (std::all_of(masks.seen_count.begin(), masks.seen_count.end(), [](uint32_t c) { return c == 0; }))
    throw InputError("No raster's camera sees the mesh (every vertex is outside every photo, behind its camera or "
                     "back-facing): the registration does not match this mesh. Check that the project's rasters "
                     "were registered to it. Nothing was written.");
  for (size_t i = 0; i < input.rasters.size(); ++i)
    if (masks.seen_count[i] == 0) {
      result.warnings.push_back("WARNING: raster '" + input.rasters[i].label +
                                "' sees no vertex of the mesh (its camera points elsewhere: check its registration); "
                                "the other photos were used without it.");
      log(result.warnings.back());
    }

  t = Clock::now();
  result.diffuse.resize(mesh.vertex_count);
  if (settings.fit_reflectance) result.fits.resize(mesh.vertex_count);
  LightAgreement agreement(input.rasters.size());  // a light file that contradicts the photos fails below
  const ProgressFn gather_progress = [&](float f, const char *s) { return !progress || progress(0.4f + 0.55f * f, s); };
  const bool with_materials = settings.fit_reflectance && settings.materials;  // material stage hook (issue 16)
  MaterialSampleStore material_samples(with_materials ? mesh.vertex_count : 0);
  result.gather = gather_samples(
      mesh, input.rasters, lights, masks, settings.gather, photos,
      [&](SampleChunk &chunk) {
        if (correct) correct_samples(colors, chunk);
        agreement.add(chunk, mesh, lights);
        apply_light_falloff(chunk, mesh, lights);  // after the correction, which need not be linear
        consume_chunk(chunk, settings.fit_reflectance ? fitter : nullptr, settings.phong, result, result.seconds_fit);
        if (with_materials) material_samples.add_chunk(chunk, &result.fits[chunk.first_vertex], settings.phong);
      },
      gather_progress);
  result.seconds_gather = seconds_since(t);
  result.light_agreement = weakest_light_agreement(agreement, input.rasters);
  check_light_agreement(agreement, input.rasters, result.light_file);  // before anything is written
  result.colors = std::move(colors.viewpoints);
  if (with_materials) run_material_stage(input, settings, material_samples, log, result);
  if (settings.fit_reflectance) fill_gaps(input, settings, log, result);
  if (with_materials) propagate_material_labels(mesh, result.fits, result.materials.label);

  t = Clock::now();
  build_outputs(input, settings, result);
  if (result.vertices_coloured == 0) {
    result.warnings.push_back("WARNING: no vertex got a colour or a model: every sample was shadowed, saturated or "
                              "unusable (see the counts below).");
    log(result.warnings.back());
  }
  result.report = build_report(input, settings, result);
  {
    // PLY and report are committed together: a concurrent run writing the same files waits here.
    OutputFolderLock lock(directory_of(result.output_ply));
    if (settings.overwrite == OverwritePolicy::Refuse)  // again: another run may have written it meanwhile
      check_output_path(result.output_ply, settings.overwrite, "Output PLY");
    AtomicOutput ply(result.output_ply), report(report_path_for(result.output_ply));
    stage_result_ply(ply, mesh, result.colors_rgba, result.attributes);
    result.seconds_output = seconds_since(t);
    result.report += "output: " + result.output_ply + " (" + result.output_note + "; written in " +
                     fixed(result.seconds_output) + " s)\n";
    stage_text_file(report, result.report);
    ply.commit();
    report.commit((long long)result.report.size());
  }

  std::istringstream lines(result.report);
  for (std::string line; std::getline(lines, line);) log(line);
  if (progress) progress(1.0f, "done");
  return result;
}

} // namespace vbrdf
