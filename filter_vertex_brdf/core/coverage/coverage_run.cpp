#include "coverage/coverage_run.h"

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <dirent.h>
#include <fstream>
#include <set>
#include <sstream>
#include <sys/stat.h>

#include <opencv2/imgcodecs.hpp>

#include "base/directions.h"
#include "base/errors.h"
#include "base/file_util.h"
#include "inputs/light_file.h"
#include "inputs/photo_prefetch.h"
#include "io/coverage_outputs.h"
#include "base/vec3.h"
#include "coverage/coverage_geometry.h"

namespace vbrdf {

using coverage_geometry::covers_unit;
using coverage_geometry::eye_direction;
using coverage_geometry::unit_normal;

namespace {





// Whether some placeable light gives vertex (n, e) a sample of `kind` from `viewpoint`: the cheap
// sufficient cases first (the normal, the mirror direction), else Algorithm 1/3's search.
bool coverable(CoverageKind kind, const float *n, const float *e, const Shot &viewpoint, const float cam_z[3],
               const LightSuggestionSettings &s) {
  const float zmin = std::sin(radians(s.min_elevation_deg));
  // Largest cosine between `v` and a placeable direction (the cap z >= zmin around cam_z).
  const auto best_cos = [&](const float *v) {
    const float theta = std::acos(std::max(-1.0f, std::min(1.0f, dot3(v, cam_z)))), edge = std::acos(zmin);
    return theta <= edge ? 1.0f : std::cos(theta - edge);
  };
  const float ne = dot3(n, e);
  if (ne <= 0) return false;
  if (kind == CoverageKind::Diffuse) {
    if (dot3(n, cam_z) >= zmin && covers_unit(kind, n, e, n, s)) return true;
    if (best_cos(n) < s.diffuse_threshold) return false;  // N.L >= T_d is out of reach
  } else {
    const float mirror[3] = {2 * ne * n[0] - e[0], 2 * ne * n[1] - e[1], 2 * ne * n[2] - e[2]};
    if (dot3(mirror, cam_z) >= zmin) return true;
    if (best_cos(mirror) <= s.specular_threshold) return false;  // R.E = L.mirror > T_s is out of reach
  }
  float l[3];
  return kind == CoverageKind::Diffuse ? ideal_diffuse_light(n, e, viewpoint, s, l)
                                       : ideal_specular_light(n, e, viewpoint, s, l);
}

void camera_axis_z(const Shot &shot, float out[3]) {
  const float towards_viewer[3] = {0, 0, 1};
  camera_to_world_direction(shot, towards_viewer, out);
}

void report_progress(const ProgressFn &progress, float fraction, const char *stage) {
  if (progress && !progress(fraction, stage)) throw ProcessingError("cancelled by the user");
}

// seen with some own-surface footprint texel (samples.h: kRimFootprint) in the viewpoint's first raster:
// where its photos can give samples.
std::vector<uint8_t> viewpoint_visible(const VisibilityMasks &masks, const Viewpoint &vp) {
  std::vector<uint8_t> visible(masks.vertex_count, 0);
  const size_t r = vp.rasters.front();
  for (size_t v = 0; v < masks.vertex_count; ++v) visible[v] = masks.is_seen(r, v) && masks.own_texels(r, v) != 0;
  return visible;
}

// A direction from the object that faces (N.D >= 0.5) the most new-view vertices: a hint where
// to put the next camera (occlusion is not considered). Normals are binned first, so the cost is
// O(vertices) + O(cells x candidates).
bool new_view_hint(const MeshView &mesh, const std::vector<uint32_t> &vertices, float out[3], size_t &facing) {
  constexpr int kRes = 32, kCandidates = 400;
  std::vector<std::array<double, 4>> cells(size_t(kRes) * kRes, std::array<double, 4>{{0, 0, 0, 0}});
  for (uint32_t v : vertices) {
    const float *n = mesh.normals + 3 * size_t(v);
    auto &c = cells[size_t(octahedral_cell(n, kRes))];
    c[0] += n[0], c[1] += n[1], c[2] += n[2], c[3] += 1;
  }
  std::vector<std::array<float, 4>> groups;  // mean normal, count
  for (const auto &c : cells)
    if (c[3] > 0) {
      const double l = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
      if (l > 0) groups.push_back({{float(c[0] / l), float(c[1] / l), float(c[2] / l), float(c[3])}});
    }
  double best = 0;
  for (int i = 0; i < kCandidates; ++i) {
    float d[3];
    fibonacci_sphere_direction(i, kCandidates, d);
    double score = 0;
    for (const auto &g : groups)
      if (dot3(g.data(), d) >= 0.5f) score += g[3];
    if (score > best) best = score, out[0] = d[0], out[1] = d[1], out[2] = d[2];
  }
  facing = size_t(best + 0.5);
  return best > 0;
}







} // namespace

std::vector<uint8_t> new_view_reasons(const MeshView &mesh, const std::vector<uint8_t> &classes,
                                      const std::vector<std::vector<uint8_t>> &visible,
                                      const std::vector<Viewpoint> &viewpoints, const LightSuggestionSettings &s) {
  const size_t n = mesh.vertex_count;
  std::vector<uint8_t> reasons(n, 0);
  std::vector<std::array<float, 3>> centres(viewpoints.size()), axes(viewpoints.size());
  for (size_t i = 0; i < viewpoints.size(); ++i) {
    camera_centre(viewpoints[i].shot, centres[i].data());
    camera_axis_z(viewpoints[i].shot, axes[i].data());
  }
#pragma omp parallel for schedule(dynamic, 4096)
  for (long long vi = 0; vi < (long long)n; ++vi) {
    const size_t v = size_t(vi);
    const uint8_t c = classes[v];
    if (c == kUnseen) {
      reasons[v] = kNewViewUnseen;
      continue;
    }
    if (c == kFullyCovered) continue;
    const bool diffuse = c == kSeenNotDiffuse;
    bool ok = false;
    for (size_t i = 0; i < viewpoints.size() && !ok; ++i) {
      if (!visible[i][v]) continue;
      float e[3], nrm[3];
      eye_direction(centres[i].data(), mesh.positions + 3 * v, e);
      unit_normal(mesh.normals + 3 * v, nrm);
      ok = coverable(diffuse ? CoverageKind::Diffuse : CoverageKind::Specular, nrm, e, viewpoints[i].shot,
                     axes[i].data(), s);
    }
    if (!ok) reasons[v] = diffuse ? kNewViewDiffuse : kNewViewSpecular;
  }
  return reasons;
}

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



CoverageResult run_coverage(const CoverageInput &input, const CoverageSettings &settings_in,
                            VisibilityBackend &visibility, const ProgressFn &progress, const LogFn &log) {
  FitInput check;
  check.mesh = input.mesh;
  check.mesh_name = input.mesh_name;
  check.rasters = input.rasters;
  validate_input(check);
  if (settings_in.write_files && settings_in.overwrite == OverwritePolicy::Refuse)  // before any work
    check_output_path(settings_in.suggestion_file.empty() ? default_suggestion_path(input.project_path)
                                                          : settings_in.suggestion_file,
                      settings_in.overwrite, "Suggestion file");
  const MeshView &mesh = input.mesh;
  const size_t n = mesh.vertex_count;
  if ((!input.dq.empty() && input.dq.size() != n) || (!input.sq.empty() && input.sq.size() != n) ||
      input.dq.size() != input.sq.size())
    throw InputError("The fit quality (" + (input.quality_source.empty() ? std::string("dq/sq") : input.quality_source) +
                     ") has " + std::to_string(input.dq.size()) + " values but the mesh has " + std::to_string(n) +
                     " vertices: use the result of a fit of this mesh, or none.");
  CoverageSettings settings = settings_in;
  settings.suggest.specular_threshold = settings.gather.specular_threshold;
  settings.suggest.diffuse_threshold = settings.gather.diffuse_threshold;

  CoverageResult r;
  r.visibility_backend = visibility.name();
  r.viewpoints = group_viewpoints(input.rasters);
  const int chosen = settings.viewpoint_raster;
  if (chosen < -1 || chosen >= int(input.rasters.size()))
    throw InputError("Viewpoint raster " + std::to_string(chosen) + " does not exist: the project has " +
                     std::to_string(input.rasters.size()) + " rasters (0 to " + std::to_string(input.rasters.size() - 1) +
                     "; -1 = the last one).");
  r.viewpoint = viewpoint_of_raster(r.viewpoints, chosen < 0 ? input.rasters.size() - 1 : size_t(chosen));

  std::vector<std::string> checked;
  r.light_file = settings.light_file.empty() ? find_default_light_file(input.rasters, input.project_path, &checked)
                                             : settings.light_file;
  if (r.light_file.empty()) {
    std::string why;
    for (const std::string &c : checked) why += "\n  " + c;
    throw InputError("No light file (.lp) beside the project or the photos has an entry for every raster: set "
                     "'lightFile', or add the new photos' lights." + why);
  }
  // An .lp may hold entries for photos not imported yet (an acquisition in progress); light-position
  // files (.json, .dome) and a dome radius go through the fit's resolve_lights.
  std::vector<std::string> unused;
  const LightPlacement placement =
      light_placement_of(mesh, settings.dome_radius, settings.light_unit_scale);
  const bool plain_lp = placement.dome_radius <= 0 && extension_of(r.light_file) == "lp";
  const std::vector<LightSource> sources =
      plain_lp ? directional_lights(lights_for_rasters(input.rasters, r.light_file, &unused))
               : resolve_lights(input.rasters, r.light_file, placement);
  log("Lights: " + describe_lights(sources, placement) + " from '" + r.light_file + "'" +
      (unused.empty() ? std::string(".") : " (" + std::to_string(unused.size()) + " entries for photos not imported yet)."));

  PhotoCache photos(settings.gather.encoding, settings.gather.saturation_level, settings.gather.photo_cache_bytes,
                    settings.gather.host_photos);
  const std::unique_ptr<PhotoPrefetch> prefetch = start_photo_prefetch(photos, input.rasters);  // as the fit

  auto t = Clock::now();
  const VisibilityMasks masks = compute_visibility(mesh, input.rasters, sources, visibility,
                                                   [&](float f, const char *s) { return !progress || progress(0.45f * f, s); });
  r.seconds_visibility = seconds_since(t);
  prefetch->finish();

  t = Clock::now();
  r.counts.assign(n, CoverageCounts());
  gather_samples(mesh, input.rasters, sources, masks, settings.gather, photos,
                 [&](const SampleChunk &chunk) { count_coverage_chunk(chunk, &r.counts[chunk.first_vertex]); },
                 [&](float f, const char *s) { return !progress || progress(0.45f + 0.45f * f, s); });
  r.seconds_gather = seconds_since(t);
  report_progress(progress, 0.9f, "suggesting lights");

  t = Clock::now();
  r.classes.resize(n);
  r.colors_rgba.resize(4 * n);
  const auto considered = [&input](size_t v) { return input.vertex_mask.empty() || input.vertex_mask[v] != 0; };
  for (size_t v = 0; v < n; ++v) {
    const CoverageClass c = classify_coverage(r.counts[v], settings.min_diffuse, settings.min_specular);
    r.classes[v] = c;
    const auto col = coverage_class_color(c);
    std::copy(col.begin(), col.end(), r.colors_rgba.begin() + std::ptrdiff_t(4 * v));
    if (!considered(v)) continue;
    ++r.vertices_considered;
    ++r.class_counts[c];
  }
  const Viewpoint &vp = r.viewpoints[r.viewpoint];
  std::vector<uint16_t> fail_d, fail_s;
  prediction_failures(mesh, r.classes, vp, sources, settings.suggest, fail_d, fail_s);
  for (size_t v = 0; v < n; ++v)
    if (!considered(v)) fail_d[v] = fail_s[v] = 0;
  for (size_t v = 0; v < n; ++v) r.failed_diffuse += fail_d[v] > 0, r.failed_specular += fail_s[v] > 0;
  CoverageNeeds needs = coverage_needs(r.counts, input.dq.empty() ? nullptr : input.dq.data(),
                                       input.sq.empty() ? nullptr : input.sq.data(), settings, fail_d.data(),
                                       fail_s.data());
  for (size_t v = 0; v < n; ++v)
    if (!considered(v)) {
      if (v < needs.diffuse.size()) needs.diffuse[v] = 0;
      if (v < needs.specular.size()) needs.specular[v] = 0;
    }
  r.poor_diffuse = needs.poor_diffuse, r.poor_specular = needs.poor_specular;
  std::vector<std::vector<uint8_t>> visible;
  for (const Viewpoint &viewpoint : r.viewpoints) visible.push_back(viewpoint_visible(masks, viewpoint));
  std::vector<std::array<float, 3>> taken;  // the lights of this viewpoint's photos
  for (size_t i : vp.rasters) taken.push_back(sources[i].direction);  // suggestions are directions (from the object's centre)
  if (settings.write_files && settings.learn_from_previous)
    r.followed = followed_suggestions(settings.suggestion_file.empty() ? default_suggestion_path(input.project_path)
                                                                       : settings.suggestion_file,
                                      input, vp);
  taken.insert(taken.end(), r.followed.begin(), r.followed.end());
  r.diffuse = suggest_light_learning(mesh, vp.shot, visible[r.viewpoint].data(), needs.diffuse.data(),
                                     CoverageKind::Diffuse, settings.suggest, settings.tolerance_deg, taken,
                                     settings.failure_cone_deg, nullptr, &r.diffuse_repeats);
  r.specular = suggest_light_learning(mesh, vp.shot, visible[r.viewpoint].data(), needs.specular.data(),
                                      CoverageKind::Specular, settings.suggest, settings.tolerance_deg, taken,
                                      settings.failure_cone_deg, nullptr, &r.specular_repeats);
  // Recommend the light that promises more, never one that failed before.
  const bool d_ok = r.diffuse.valid && !r.diffuse_repeats, s_ok = r.specular.valid && !r.specular_repeats;
  if (d_ok || s_ok) r.recommended = !s_ok || (d_ok && r.diffuse.covered_weight >= r.specular.covered_weight) ? 0 : 1;
  const std::vector<uint8_t> reasons = new_view_reasons(mesh, r.classes, visible, r.viewpoints, settings.suggest);
  for (size_t v = 0; v < n; ++v) {
    if (!reasons[v] || !considered(v)) continue;
    r.new_view_vertices.push_back(uint32_t(v)), r.new_view_reasons.push_back(reasons[v]);
    bool clean = reasons[v] == kNewViewUnseen;
    for (size_t i = 0; i < visible.size() && !clean; ++i) clean = visible[i][v] != 0;
    r.new_view_mixed += !clean;
  }
  r.has_view_hint = new_view_hint(mesh, r.new_view_vertices, r.view_hint_world, r.view_hint_vertices);
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
