#include "pipeline.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "errors.h"
#include "file_util.h"
#include "light_file.h"
#include "output_ply.h"
#include "visibility_gl.h"

namespace vbrdf {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string fixed(double v, int digits = 2) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

std::string percent(uint64_t part, uint64_t whole) {
  return whole ? fixed(100.0 * double(part) / double(whole), 1) + "%" : "0%";
}

std::string strip_extension(const std::string &path) {
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of('/');
  return (dot == std::string::npos || (slash != std::string::npos && dot < slash)) ? path : path.substr(0, dot);
}

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

std::vector<std::array<float, 3>> resolve_light_directions(const std::vector<Raster> &rasters,
                                                           const std::string &lp_path) {
  const std::vector<LightEntry> lights = read_light_file(lp_path);
  std::vector<bool> used(lights.size(), false);
  std::vector<std::array<float, 3>> dirs(rasters.size());
  for (size_t r = 0; r < rasters.size(); ++r) {
    const int i = find_light_for_image(lights, rasters[r].image_path);
    if (i < 0)
      throw InputError("Light file '" + lp_path + "' has no entry for raster '" + rasters[r].label + "' (image '" +
                       file_name_of(rasters[r].image_path) + "'): add a line for it or choose the matching .lp.");
    used[size_t(i)] = true;
    camera_to_world_direction(rasters[r].shot, lights[size_t(i)].dir_cam, dirs[r].data());
  }
  if (lights.size() != rasters.size()) {
    for (size_t i = 0; i < lights.size(); ++i)
      if (!used[i])
        throw InputError("Light file '" + lp_path + "' has " + std::to_string(lights.size()) + " lights but the project has " +
                         std::to_string(rasters.size()) + " rasters; entry '" + lights[i].image +
                         "' matches no raster. Use the .lp written for these photos.");
  }
  return dirs;
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
        throw ProcessingError("The OpenGL visibility back end was requested but no GL context is available.");
      log("Visibility: no GL context, using the CPU ray caster.");
    } else {
      try {
        auto gl = make_gl_visibility(mesh, get_proc, settings.visibility);
        log(std::string("Visibility: ") + gl->name() + ".");
        return gl;
      } catch (const ProcessingError &e) {
        if (settings.visibility_choice == VisibilityChoice::GL) throw;
        log(std::string("Visibility: GL depth passes unavailable (") + e.what() + "); using the CPU ray caster.");
      }
    }
  }
  auto cpu = make_cpu_visibility(mesh, settings.visibility);
  log(std::string("Visibility: ") + cpu->name() + ".");
  return cpu;
}

FitResult run_fit(const FitInput &input, const FitSettings &settings, VisibilityBackend &visibility,
                  const ProgressFn &progress, const LogFn &log) {
  validate_input(input);
  const MeshView &mesh = input.mesh;
  FitResult result;
  result.visibility_backend = visibility.name();

  result.light_file = settings.light_file.empty()
                          ? find_default_light_file(input.project_path, input.rasters.front().image_path)
                          : settings.light_file;
  if (result.light_file.empty())
    throw InputError("No light file (.lp) found beside the project or the images: set 'lightFile' to the .lp "
                     "that gives each photo's light direction.");
  const auto lights = resolve_light_directions(input.rasters, result.light_file);
  log("Lights: " + std::to_string(lights.size()) + " directions from '" + result.light_file + "'.");

  result.output_ply = settings.output_ply.empty() ? default_output_path(input.project_path) : settings.output_ply;
  for (const std::string &protected_path : {input.project_path, input.mesh_path})
    if (!protected_path.empty() && result.output_ply == protected_path)
      throw InputError("The output '" + result.output_ply + "' would overwrite an input file: choose another 'outputPly'.");

  // Photos are validated (size, bit depth) before the long passes start.
  PhotoCache photos(settings.gather.encoding, settings.gather.saturation_level, settings.gather.photo_cache_bytes);
  for (const Raster &r : input.rasters) photos.get(r.image_path, r.width(), r.height());

  auto t = Clock::now();
  const ProgressFn vis_progress = [&](float f, const char *s) { return !progress || progress(0.4f * f, s); };
  const VisibilityMasks masks = compute_visibility(mesh, input.rasters, lights, visibility, vis_progress);
  result.seconds_visibility = seconds_since(t);

  t = Clock::now();
  result.diffuse.resize(mesh.vertex_count);
  const ProgressFn gather_progress = [&](float f, const char *s) { return !progress || progress(0.4f + 0.5f * f, s); };
  result.gather = gather_samples(
      mesh, input.rasters, lights, masks, settings.gather, photos,
      [&](const SampleChunk &chunk) { estimate_diffuse_chunk(chunk, &result.diffuse[chunk.first_vertex]); },
      gather_progress);
  result.seconds_gather = seconds_since(t);

  // Outputs: colour where estimated, input colour elsewhere (never silently painted).
  t = Clock::now();
  const size_t n = mesh.vertex_count;
  result.colors_rgba.resize(4 * n);
  const char *names[] = {"diffuse_r", "diffuse_g", "diffuse_b", "n_visible", "n_diffuse", "n_specular", "coloured"};
  for (const char *name : names) result.attributes.push_back({name, std::vector<float>(n, 0.0f)});
  for (size_t v = 0; v < n; ++v) {
    const DiffuseEstimate &e = result.diffuse[v];
    for (int c = 0; c < 3; ++c) result.attributes[size_t(c)].values[v] = e.valid ? e.rgb[c] : 0.0f;
    result.attributes[3].values[v] = e.n_seen;
    result.attributes[4].values[v] = e.n_diffuse;
    result.attributes[5].values[v] = e.n_specular;
    result.attributes[6].values[v] = e.valid ? (e.from_mixed_pixels ? 2.0f : 1.0f) : 0.0f;
    if (e.valid && e.from_mixed_pixels) ++result.vertices_from_mixed;
    if (e.valid) {
      for (int c = 0; c < 3; ++c) result.colors_rgba[4 * v + size_t(c)] = srgb_byte(e.rgb[c]);
      result.colors_rgba[4 * v + 3] = 255;
      ++result.vertices_coloured;
    } else {
      for (int c = 0; c < 4; ++c)
        result.colors_rgba[4 * v + size_t(c)] =
            input.mesh_colors.size() == 4 * n ? input.mesh_colors[4 * v + size_t(c)] : uint8_t(255);  // MeshLab default: white
      if (e.n_seen == 0) ++result.vertices_unseen; else ++result.vertices_no_diffuse;
    }
  }

  // Report.
  const GatherStats &g = result.gather;
  std::ostringstream rep;
  rep << "filter_vertex_brdf report\n"
      << "mesh: " << input.mesh_name << " (" << n << " vertices, " << mesh.index_count / 3 << " triangles)\n"
      << "photos: " << input.rasters.size() << ", lights: " << result.light_file << "\n"
      << "visibility back end: " << result.visibility_backend << "\n"
      << "thresholds: T_s (R.E) = " << settings.gather.specular_threshold
      << ", T_d (N.L) = " << settings.gather.diffuse_threshold << "\n"
      << "vertices coloured: " << result.vertices_coloured << " (" << percent(result.vertices_coloured, n) << ")\n"
      << "  of which from mixed pixels only (silhouette/border/contact; coloured = 2): " << result.vertices_from_mixed << "\n"
      << "vertices seen but without a diffuse sample (kept their colour): " << result.vertices_no_diffuse << "\n"
      << "vertices seen by no photo (kept their colour; need another viewpoint): " << result.vertices_unseen << "\n"
      << "vertex-photo pairs: " << g.pairs << ", samples stored (seen): " << g.stored << "\n";
  const std::pair<uint16_t, const char *> flag_names[] = {
      {kOffImage, "off image / behind camera"}, {kBackFacing, "back-facing"}, {kOccluded, "occluded"},
      {kAttachedShadow, "facing away from the light"}, {kCastShadow, "in cast shadow"},
      {kSaturated, "saturated (not used)"}, {kMixedPixel, "mixed pixel at a silhouette/border (not used)"}, {kGrazing, "grazing light (N.L < T_d)"}, {kHighlight, "highlight (R.E > T_s)"}};
  for (const auto &f : flag_names)
    rep << "  " << f.second << ": " << g.flag_counts[bit(f.first)] << " (" << percent(g.flag_counts[bit(f.first)], g.pairs) << ")\n";
  size_t blind = 0;
  for (size_t r = 0; r < input.rasters.size(); ++r)
    if (g.raster_seen_vertices[r] == 0) {
      ++blind;
      rep << "warning: raster '" << input.rasters[r].label << "' sees no vertex (check its registration)\n";
    }
  rep << "time: visibility " << fixed(result.seconds_visibility) << " s, samples + colour " << fixed(result.seconds_gather)
      << " s (" << g.chunks << " chunk(s), " << g.photo_loads << " photo decodes)\n";
  result.report = rep.str();

  write_result_ply(result.output_ply, mesh, result.colors_rgba, result.attributes);
  result.seconds_output = seconds_since(t);
  result.report += "output: " + result.output_ply + " (written in " + fixed(result.seconds_output) + " s)\n";
  write_text_file_atomically(report_path_for(result.output_ply), result.report);

  std::istringstream lines(result.report);
  for (std::string line; std::getline(lines, line);) log(line);
  if (blind) log(std::to_string(blind) + " raster(s) see no vertex and were skipped.");
  if (progress) progress(1.0f, "done");
  return result;
}

} // namespace vbrdf
