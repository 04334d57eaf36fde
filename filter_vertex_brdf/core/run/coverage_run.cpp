#include "run/coverage_run.h"

#include <algorithm>
#include <sstream>

#include "base/errors.h"
#include "base/file_util.h"
#include "base/vec3.h"
#include "inputs/input_check.h"
#include "inputs/light_file.h"
#include "inputs/photo_prefetch.h"
#include "run/coverage_outputs.h"

namespace vbrdf {

std::vector<std::array<float, 3>> lights_for_rasters(const std::vector<Raster> &rasters, const std::string &lp_path,
                                                     std::vector<std::string> *unused) {
  const std::vector<LightEntry> lights = read_light_file(lp_path);
  std::vector<bool> used(lights.size(), false);
  std::vector<std::array<float, 3>> dirs(rasters.size());
  for (size_t r = 0; r < rasters.size(); ++r) {
    const int i = find_light_for_image(lights, rasters[r].image_path);
    if (i < 0)
      throw InputError("Light file '" + lp_path + "' has no entry for raster '" + rasters[r].label + "' (image '" +
                       file_name_of(rasters[r].image_path) + "'): add its light (or estimate it from the sphere when "
                       "importing the photo) or choose the .lp written for these photos.");
    used[size_t(i)] = true;
    camera_to_world_direction(rasters[r].shot, lights[size_t(i)].dir_cam, dirs[r].data());
  }
  if (unused)
    for (size_t i = 0; i < lights.size(); ++i)
      if (!used[i]) unused->push_back(lights[i].image);
  return dirs;
}

namespace {

void report_progress(const ProgressFn &progress, float fraction, const char *stage) {
  if (progress && !progress(fraction, stage)) throw ProcessingError("cancelled by the user");
}

// Seen with some own-surface footprint texel (samples.h: kRimFootprint) in the viewpoint's first
// raster: where its photos can give samples.
std::vector<uint8_t> viewpoint_visible(const VisibilityMasks &masks, const Viewpoint &vp) {
  std::vector<uint8_t> visible(masks.vertex_count, 0);
  const size_t r = vp.rasters.front();
  for (size_t v = 0; v < masks.vertex_count; ++v) visible[v] = masks.is_seen(r, v) && masks.own_texels(r, v) != 0;
  return visible;
}

std::string suggestion_path(const CoverageInput &input, const CoverageSettings &settings) {
  return settings.suggestion_file.empty() ? default_suggestion_path(input.project_path) : settings.suggestion_file;
}

// Everything that can be checked before any work: the mesh and rasters as the fit checks them
// (inputs/input_check.h), a suggestion file the policy forbids replacing, and fit quality of one
// value per vertex.
void check_coverage_input(const CoverageInput &input, const CoverageSettings &settings) {
  validate_mesh_and_rasters(input.mesh, input.mesh_name, input.rasters, input.vertex_mask);
  if (settings.write_files && settings.overwrite == OverwritePolicy::Refuse)
    check_output_path(suggestion_path(input, settings), settings.overwrite, "Suggestion file");
  const size_t n = input.mesh.vertex_count;
  if ((!input.dq.empty() && input.dq.size() != n) || (!input.sq.empty() && input.sq.size() != n) ||
      input.dq.size() != input.sq.size())
    throw InputError("The fit quality (" + (input.quality_source.empty() ? std::string("dq/sq") : input.quality_source) +
                     ") has " + std::to_string(input.dq.size()) + " values but the mesh has " + std::to_string(n) +
                     " vertices: use the result of a fit of this mesh, or none.");
}

// The rasters grouped into viewpoints, and the one the suggestions are for (settings.viewpoint_raster's).
void choose_viewpoint(const CoverageInput &input, const CoverageSettings &settings, CoverageResult &r) {
  r.viewpoints = group_viewpoints(input.rasters);
  const int chosen = settings.viewpoint_raster;
  if (chosen < -1 || chosen >= int(input.rasters.size()))
    throw InputError("Viewpoint raster " + std::to_string(chosen) + " does not exist: the project has " +
                     std::to_string(input.rasters.size()) + " rasters (0 to " + std::to_string(input.rasters.size() - 1) +
                     "; -1 = the last one).");
  r.viewpoint = viewpoint_of_raster(r.viewpoints, chosen < 0 ? input.rasters.size() - 1 : size_t(chosen));
}

// Every raster's light. An .lp may hold entries for photos not imported yet (an acquisition in
// progress: lights_for_rasters); light-position files (.json, .dome) and a dome radius go
// through the fit's resolve_lights.
std::vector<LightSource> coverage_lights(const CoverageInput &input, const CoverageSettings &settings,
                                         CoverageResult &r, const LogFn &log) {
  r.light_file = resolve_light_file(settings.light_file, input.rasters, input.project_path);
  std::vector<std::string> unused;
  const LightPlacement placement = light_placement_of(input.mesh, settings.dome_radius, settings.light_unit_scale);
  const bool plain_lp = placement.dome_radius <= 0 && extension_of(r.light_file) == "lp";
  std::vector<LightSource> sources = plain_lp
                                         ? directional_lights(lights_for_rasters(input.rasters, r.light_file, &unused))
                                         : resolve_lights(input.rasters, r.light_file, placement);
  log("Lights: " + describe_lights(sources, placement) + " from '" + r.light_file + "'" +
      (unused.empty() ? std::string(".") : " (" + std::to_string(unused.size()) + " entries for photos not imported yet)."));
  return sources;
}

// Every vertex's coverage counts from its samples (visibility, then the samples streamed), with
// the photos decoded in the background during the depth passes as the fit does.
VisibilityMasks count_coverage(const CoverageInput &input, const CoverageSettings &settings,
                               const std::vector<LightSource> &sources, VisibilityBackend &visibility,
                               const ProgressFn &progress, CoverageResult &r) {
  const MeshView &mesh = input.mesh;
  PhotoCache photos(settings.gather.encoding, settings.gather.saturation_level, settings.gather.photo_cache_bytes,
                    settings.gather.host_photos);
  const std::unique_ptr<PhotoPrefetch> prefetch = start_photo_prefetch(photos, input.rasters);
  auto t = Clock::now();
  VisibilityMasks masks = compute_visibility(mesh, input.rasters, sources, visibility,
                                             [&](float f, const char *s) { return !progress || progress(0.45f * f, s); });
  r.seconds_visibility = seconds_since(t);
  prefetch->finish();
  t = Clock::now();
  r.counts.assign(mesh.vertex_count, CoverageCounts());
  gather_samples(mesh, input.rasters, sources, masks, settings.gather, photos,
                 [&](const SampleChunk &chunk) { count_coverage_chunk(chunk, &r.counts[chunk.first_vertex]); },
                 [&](float f, const char *s) { return !progress || progress(0.45f + 0.45f * f, s); });
  r.seconds_gather = seconds_since(t);
  return masks;
}

bool considered(const CoverageInput &input, size_t v) { return input.vertex_mask.empty() || input.vertex_mask[v] != 0; }

// Every vertex's class and colour; the class counts over the considered vertices.
void classify_vertices(const CoverageInput &input, const CoverageSettings &settings, CoverageResult &r) {
  const size_t n = input.mesh.vertex_count;
  r.classes.resize(n);
  r.colors_rgba.resize(4 * n);
  for (size_t v = 0; v < n; ++v) {
    const CoverageClass c = classify_coverage(r.counts[v], settings.min_diffuse, settings.min_specular);
    r.classes[v] = c;
    const auto col = coverage_class_color(c);
    std::copy(col.begin(), col.end(), r.colors_rgba.begin() + std::ptrdiff_t(4 * v));
    if (!considered(input, v)) continue;
    ++r.vertices_considered;
    ++r.class_counts[c];
  }
}

// What each considered vertex still needs (coverage_needs), with the lights of the viewpoint's
// photos that failed a vertex they were predicted to cover (prediction_failures) weighing less.
CoverageNeeds vertex_needs(const CoverageInput &input, const CoverageSettings &settings,
                           const std::vector<LightSource> &sources, CoverageResult &r) {
  const size_t n = input.mesh.vertex_count;
  std::vector<uint16_t> fail_d, fail_s;
  prediction_failures(input.mesh, r.classes, r.viewpoints[r.viewpoint], sources, settings.suggest, fail_d, fail_s);
  for (size_t v = 0; v < n; ++v)
    if (!considered(input, v)) fail_d[v] = fail_s[v] = 0;
  for (size_t v = 0; v < n; ++v) r.failed_diffuse += fail_d[v] > 0, r.failed_specular += fail_s[v] > 0;
  CoverageNeeds needs = coverage_needs(r.counts, input.dq.empty() ? nullptr : input.dq.data(),
                                       input.sq.empty() ? nullptr : input.sq.data(), settings, fail_d.data(),
                                       fail_s.data());
  for (size_t v = 0; v < n; ++v)
    if (!considered(input, v)) {
      if (v < needs.diffuse.size()) needs.diffuse[v] = 0;
      if (v < needs.specular.size()) needs.specular[v] = 0;
    }
  r.poor_diffuse = needs.poor_diffuse, r.poor_specular = needs.poor_specular;
  return needs;
}

// The next diffuse and specular light for the chosen viewpoint, learning from its photos' lights
// and the suggestions followed before; the recommended one promises more and repeats no light
// that failed.
void suggest_lights(const CoverageInput &input, const CoverageSettings &settings, const std::vector<LightSource> &sources,
                    const CoverageNeeds &needs, const std::vector<uint8_t> &visible, CoverageResult &r) {
  const Viewpoint &vp = r.viewpoints[r.viewpoint];
  std::vector<std::array<float, 3>> taken;  // the lights of this viewpoint's photos
  for (size_t i : vp.rasters) taken.push_back(sources[i].direction);  // suggestions are directions (from the object's centre)
  if (settings.write_files && settings.learn_from_previous)
    r.followed = followed_suggestions(suggestion_path(input, settings), input, vp);
  taken.insert(taken.end(), r.followed.begin(), r.followed.end());
  r.diffuse = suggest_light_learning(input.mesh, vp.shot, visible.data(), needs.diffuse.data(), CoverageKind::Diffuse,
                                     settings.suggest, settings.tolerance_deg, taken, settings.failure_cone_deg,
                                     nullptr, &r.diffuse_repeats);
  r.specular = suggest_light_learning(input.mesh, vp.shot, visible.data(), needs.specular.data(),
                                      CoverageKind::Specular, settings.suggest, settings.tolerance_deg, taken,
                                      settings.failure_cone_deg, nullptr, &r.specular_repeats);
  const bool d_ok = r.diffuse.valid && !r.diffuse_repeats, s_ok = r.specular.valid && !r.specular_repeats;
  if (d_ok || s_ok) r.recommended = !s_ok || (d_ok && r.diffuse.covered_weight >= r.specular.covered_weight) ? 0 : 1;
}

// The considered vertices only a new viewpoint can cover (new_view.h), how many of the seen ones
// are seen in mixed pixels only, and a direction for that camera.
void find_new_view_vertices(const CoverageInput &input, const CoverageSettings &settings,
                            const std::vector<std::vector<uint8_t>> &visible, CoverageResult &r) {
  const std::vector<uint8_t> reasons = new_view_reasons(input.mesh, r.classes, visible, r.viewpoints, settings.suggest);
  for (size_t v = 0; v < input.mesh.vertex_count; ++v) {
    if (!reasons[v] || !considered(input, v)) continue;
    r.new_view_vertices.push_back(uint32_t(v)), r.new_view_reasons.push_back(reasons[v]);
    bool clean = reasons[v] == kNewViewUnseen;
    for (size_t i = 0; i < visible.size() && !clean; ++i) clean = visible[i][v] != 0;
    r.new_view_mixed += !clean;
  }
  r.has_view_hint = new_view_hint(input.mesh, r.new_view_vertices, r.view_hint_world, r.view_hint_vertices);
}

} // namespace

CoverageResult run_coverage(const CoverageInput &input, const CoverageSettings &settings_in,
                            VisibilityBackend &visibility, const ProgressFn &progress, const LogFn &log) {
  check_coverage_input(input, settings_in);
  CoverageSettings settings = settings_in;
  settings.suggest.specular_threshold = settings.gather.specular_threshold;
  settings.suggest.diffuse_threshold = settings.gather.diffuse_threshold;

  CoverageResult r;
  r.visibility_backend = visibility.name();
  choose_viewpoint(input, settings, r);
  const std::vector<LightSource> sources = coverage_lights(input, settings, r, log);
  const VisibilityMasks masks = count_coverage(input, settings, sources, visibility, progress, r);
  report_progress(progress, 0.9f, "suggesting lights");

  const auto t = Clock::now();
  classify_vertices(input, settings, r);
  const CoverageNeeds needs = vertex_needs(input, settings, sources, r);
  std::vector<std::vector<uint8_t>> visible;
  for (const Viewpoint &viewpoint : r.viewpoints) visible.push_back(viewpoint_visible(masks, viewpoint));
  suggest_lights(input, settings, sources, needs, visible[r.viewpoint], r);
  find_new_view_vertices(input, settings, visible, r);
  r.seconds_suggest = seconds_since(t);

  std::string kv_text;
  build_coverage_texts(input, settings, r, kv_text);
  if (settings.write_files) write_coverage_files(settings, input, r, kv_text);
  std::istringstream lines(r.report);
  for (std::string line; std::getline(lines, line);) log(line);
  if (!r.suggestion_file.empty()) log("suggestions written to " + r.suggestion_file + " (" + r.suggestion_note + ")");
  report_progress(progress, 1.0f, "done");
  return r;
}

} // namespace vbrdf
