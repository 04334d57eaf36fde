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

#include "base/errors.h"
#include "base/file_util.h"
#include "inputs/light_file.h"
#include "io/output_ply.h"
#include "base/vec3.h"

namespace vbrdf {

namespace {



std::string vec3(const float v[3], int digits = 4) {
  return fixed(v[0], digits) + " " + fixed(v[1], digits) + " " + fixed(v[2], digits);
}


// A mesh normal, normalised (file normals need not be unit length).
void unit_normal(const float *n, float out[3]) {
  const float l = std::sqrt(dot3(n, n));
  for (int k = 0; k < 3; ++k) out[k] = l > 0 ? n[k] / l : 0.0f;
}

void eye_direction(const float centre[3], const float *p, float e[3]) {
  for (int k = 0; k < 3; ++k) e[k] = centre[k] - p[k];
  const float l = std::sqrt(dot3(e, e));
  for (int k = 0; k < 3; ++k) e[k] = l > 0 ? e[k] / l : 0.0f;
}

// light_covers_diffuse / light_covers_specular (coverage.h) for unit vectors, without their
// renormalisation: this runs per vertex and photo.
inline bool covers_unit(CoverageKind kind, const float *n, const float *e, const float *l, const LightSuggestionSettings &s) {
  const float d = dot3(n, l);
  if (d <= 0) return false;
  const float spec = 2 * d * dot3(n, e) - dot3(l, e);  // R.E with R = 2 (N.L) N - L
  return kind == CoverageKind::Specular ? spec > s.specular_threshold
                                        : d >= s.diffuse_threshold && spec <= s.specular_threshold;
}

// Whether some placeable light gives vertex (n, e) a sample of `kind` from `viewpoint`: the cheap
// sufficient cases first (the normal, the mirror direction), else Algorithm 1/3's search.
bool coverable(CoverageKind kind, const float *n, const float *e, const Shot &viewpoint, const float cam_z[3],
               const LightSuggestionSettings &s) {
  const float zmin = std::sin(s.min_elevation_deg * kPi / 180);
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

// Octahedral cell of a unit vector on a res x res grid.
int octa_cell(const float n[3], int res) {
  const float a = std::fabs(n[0]) + std::fabs(n[1]) + std::fabs(n[2]);
  if (!(a > 0)) return 0;
  float u = n[0] / a, v = n[1] / a;
  if (n[2] < 0) {
    const float nu = (1 - std::fabs(v)) * (u >= 0 ? 1 : -1), nv = (1 - std::fabs(u)) * (v >= 0 ? 1 : -1);
    u = nu, v = nv;
  }
  const int i = std::min(res - 1, std::max(0, int((u * 0.5f + 0.5f) * float(res))));
  const int j = std::min(res - 1, std::max(0, int((v * 0.5f + 0.5f) * float(res))));
  return j * res + i;
}

// A direction from the object that faces (N.D >= 0.5) the most new-view vertices: a hint where
// to put the next camera (occlusion is not considered). Normals are binned first, so the cost is
// O(vertices) + O(cells x candidates).
bool new_view_hint(const MeshView &mesh, const std::vector<uint32_t> &vertices, float out[3], size_t &facing) {
  constexpr int kRes = 32, kCandidates = 400;
  std::vector<std::array<double, 4>> cells(size_t(kRes) * kRes, std::array<double, 4>{{0, 0, 0, 0}});
  for (uint32_t v : vertices) {
    const float *n = mesh.normals + 3 * size_t(v);
    auto &c = cells[size_t(octa_cell(n, kRes))];
    c[0] += n[0], c[1] += n[1], c[2] += n[2], c[3] += 1;
  }
  std::vector<std::array<float, 4>> groups;  // mean normal, count
  for (const auto &c : cells)
    if (c[3] > 0) {
      const double l = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
      if (l > 0) groups.push_back({{float(c[0] / l), float(c[1] / l), float(c[2] / l), float(c[3])}});
    }
  double best = 0;
  for (int i = 0; i < kCandidates; ++i) {  // Fibonacci sphere
    const float z = 1 - (2 * float(i) + 1) / float(kCandidates), r = std::sqrt(std::max(0.0f, 1 - z * z));
    const float phi = float(i) * kPi * (3 - std::sqrt(5.0f));
    const float d[3] = {r * std::cos(phi), r * std::sin(phi), z};
    double score = 0;
    for (const auto &g : groups)
      if (dot3(g.data(), d) >= 0.5f) score += g[3];
    if (score > best) best = score, out[0] = d[0], out[1] = d[1], out[2] = d[2];
  }
  facing = size_t(best + 0.5);
  return best > 0;
}

// Clock position of a camera-frame azimuth as the photographer sees the object: up = 12, right = 3.
int clock_hour(float azimuth_deg) {
  const int h = ((int(std::lround(3.0 - double(azimuth_deg) / 30.0)) % 12) + 12) % 12;
  return h == 0 ? 12 : h;
}

void describe_suggestion(std::ostringstream &kv, std::ostringstream &rep, const char *kind,
                         const LightSuggestion &s) {
  kv << kind << "_valid: " << (s.valid ? 1 : 0) << "\n"
     << kind << "_needing: " << s.needing_vertices << "\n"
     << kind << "_unplaceable: " << s.uncoverable_vertices << "\n";
  if (s.valid) {
    kv << kind << "_azimuth_deg: " << fixed(s.azimuth_deg, 1) << "\n"
       << kind << "_elevation_deg: " << fixed(s.elevation_deg, 1) << "\n"
       << kind << "_clock: " << clock_hour(s.azimuth_deg) << "\n"
       << kind << "_camera: " << vec3(s.dir_cam) << "\n"
       << kind << "_world: " << vec3(s.dir_world) << "\n"
       << kind << "_covers: " << s.covered_vertices << "\n";
    rep << "next " << kind << " light: azimuth " << fixed(s.azimuth_deg, 1) << " deg, elevation "
        << fixed(s.elevation_deg, 1) << " deg (about " << clock_hour(s.azimuth_deg)
        << " o'clock seen from the camera); unit vector camera (" << vec3(s.dir_cam, 3) << "), world ("
        << vec3(s.dir_world, 3) << "); covers " << s.covered_vertices << " of the " << s.needing_vertices
        << " vertices this viewpoint sees that need " << kind << " samples\n";
  } else if (s.needing_vertices == 0) {
    rep << "next " << kind << " light: none needed (every vertex this viewpoint sees is covered)\n";
  } else {
    rep << "next " << kind << " light: none; no placeable light covers the " << s.needing_vertices
        << " vertices this viewpoint sees that still need " << kind << " samples (take another viewpoint)\n";
  }
  if (s.uncoverable_vertices > 0)
    rep << "  " << s.uncoverable_vertices << " of them need a light behind the object or below the "
        << "camera-facing horizon: only another viewpoint covers them\n";
}

std::vector<std::array<float, 3>> parse_directions(const std::string &text) {
  std::vector<std::array<float, 3>> out;
  std::istringstream items(text);
  for (std::string item; std::getline(items, item, ';');) {
    std::istringstream xyz(item);
    std::array<float, 3> d;
    if (xyz >> d[0] >> d[1] >> d[2]) out.push_back(d);
  }
  return out;
}

std::string format_directions(const std::vector<std::array<float, 3>> &dirs) {
  std::string out;
  for (const auto &d : dirs) out += (out.empty() ? "" : "; ") + vec3(d.data());
  return out;
}

// The suggestions followed so far: those listed by the previous suggestion file of this project
// and viewpoint, plus its recommended light when photos were added to the viewpoint since.
std::vector<std::array<float, 3>> followed_suggestions(const std::string &path, const CoverageInput &input,
                                                       const Viewpoint &vp) {
  if (!file_exists(path)) return {};
  std::ifstream f(path);
  std::stringstream buffer;
  buffer << f.rdbuf();
  const std::string text = buffer.str();
  if (suggestion_value(text, "vertices") != std::to_string(input.mesh.vertex_count) ||
      suggestion_value(text, "viewpoint_first_raster") != input.rasters[vp.rasters.front()].label)
    return {};  // another mesh or viewpoint
  std::vector<std::array<float, 3>> out = parse_directions(suggestion_value(text, "followed_world"));
  const std::string kind = suggestion_value(text, "recommended");
  const std::string before = suggestion_value(text, "viewpoint_photos");
  if ((kind == "diffuse" || kind == "specular") && vp.rasters.size() > std::strtoul(before.c_str(), nullptr, 10)) {
    const auto last = parse_directions(suggestion_value(text, kind + "_world"));
    out.insert(out.end(), last.begin(), last.end());
  }
  return out;
}

void build_texts(const CoverageInput &input, const CoverageSettings &settings, CoverageResult &r,
                 std::string &kv_text) {
  const size_t n = input.mesh.vertex_count;
  const Viewpoint &vp = r.viewpoints[r.viewpoint];
  std::ostringstream kv, rep;
  rep << "Vertex BRDF coverage: " << input.mesh_name << " (" << n << " vertices), " << input.rasters.size()
      << " photo(s) in " << r.viewpoints.size() << " viewpoint(s), lights from " << r.light_file << "\n"
      << "thresholds: T_s (R.E) = " << settings.gather.specular_threshold << ", T_d (N.L) = "
      << settings.gather.diffuse_threshold << "; covered = at least " << settings.min_diffuse << " diffuse / "
      << settings.min_specular << " specular sample(s); lights at least " << settings.suggest.min_elevation_deg
      << " deg above the image plane\n"
      << "legend (vertex colours) and counts:\n";
  static const char *const keys[4] = {"unseen", "seen_not_diffuse", "diffuse_no_specular", "fully_covered"};
  static const char *const colour_names[4] = {"purple", "red", "yellow", "green"};
  for (int c = 0; c < 4; ++c) {
    const auto col = coverage_class_color(CoverageClass(c));
    rep << "  " << colour_names[c] << " (" << int(col[0]) << "," << int(col[1]) << "," << int(col[2])
        << "): " << coverage_class_name(CoverageClass(c)) << ": " << r.class_counts[c] << " ("
        << percent(r.class_counts[c], n) << ")\n";
  }
  if (!input.dq.empty())
    rep << "fit quality (" << (input.quality_source.empty() ? "per-vertex dq/sq" : input.quality_source)
        << "): " << r.poor_diffuse << " covered vertices with DQ < " << settings.poor_dq << " and "
        << r.poor_specular << " with SQ < " << settings.poor_sq << " also ask for samples (poorer fits weigh more)\n";
  if (r.failed_diffuse + r.failed_specular > 0)
    rep << "uncovered although a photo's light should have covered them (cast shadow or clipped pixel; they weigh "
        << "less now so that the suggestions move on): " << r.failed_diffuse << " for diffuse, " << r.failed_specular
        << " for specular samples\n";
  rep << "suggestions for viewpoint " << r.viewpoint << " (" << vp.rasters.size() << " photo(s), first raster '"
      << input.rasters[vp.rasters.front()].label << "'); directions in its camera frame: azimuth 0 = right, "
      << "90 = up; elevation 90 = at the camera, 0 = in the image plane\n";

  kv << "# Vertex BRDF: coverage and next light (key: value; see the report below)\n"
     << "project: " << input.project_path << "\n"
     << "mesh: " << input.mesh_name << "\n"
     << "vertices: " << n << "\n"
     << "photos: " << input.rasters.size() << "\n"
     << "viewpoints: " << r.viewpoints.size() << "\n"
     << "viewpoint: " << r.viewpoint << "\n"
     << "viewpoint_photos: " << vp.rasters.size() << "\n"
     << "viewpoint_first_raster: " << input.rasters[vp.rasters.front()].label << "\n"
     << "light_file: " << r.light_file << "\n";
  for (int c = 0; c < 4; ++c) kv << keys[c] << ": " << r.class_counts[c] << "\n";
  kv << "poor_diffuse_fits: " << r.poor_diffuse << "\npoor_specular_fits: " << r.poor_specular << "\n"
     << "failed_diffuse: " << r.failed_diffuse << "\nfailed_specular: " << r.failed_specular << "\n";
  describe_suggestion(kv, rep, "diffuse", r.diffuse);
  describe_suggestion(kv, rep, "specular", r.specular);
  static const char *const kinds[2] = {"diffuse", "specular"};
  kv << "diffuse_repeats_failed: " << (r.diffuse_repeats ? 1 : 0) << "\nspecular_repeats_failed: "
     << (r.specular_repeats ? 1 : 0) << "\n";
  for (int k = 0; k < 2; ++k)
    if (k == 0 ? r.diffuse_repeats : r.specular_repeats)
      rep << "  the " << kinds[k] << " light repeats one that was tried without success (a cast shadow, or the "
          << "light could not be placed there): the vertices it aims at probably need another viewpoint\n";
  kv << "recommended: " << (r.recommended < 0 ? "none" : kinds[r.recommended]) << "\n"
     << "followed_world: " << format_directions(r.followed) << "\n";
  if (r.recommended >= 0)
    rep << "take next: the " << kinds[r.recommended] << " light (it promises more coverage)\n";

  size_t by_reason[3] = {0, 0, 0};
  for (uint8_t why : r.new_view_reasons) by_reason[why == kNewViewUnseen ? 0 : why == kNewViewDiffuse ? 1 : 2]++;
  kv << "new_view_vertices: " << r.new_view_vertices.size() << "\n"
     << "new_view_unseen: " << by_reason[0] << "\nnew_view_diffuse: " << by_reason[1]
     << "\nnew_view_specular: " << by_reason[2] << "\nnew_view_mixed_only: " << r.new_view_mixed << "\n";
  rep << "vertices only a new viewpoint can cover: " << r.new_view_vertices.size() << " (" << by_reason[0]
      << " seen by no photo, " << by_reason[1] << " without a placeable diffuse light, " << by_reason[2]
      << " without a placeable specular light from any registered viewpoint; " << r.new_view_mixed
      << " of the seen ones appear only in mixed pixels at silhouettes or borders)\n";
  if (r.has_view_hint) {
    kv << "new_view_hint_world: " << vec3(r.view_hint_world) << "\nnew_view_hint_vertices: " << r.view_hint_vertices
       << "\n";
    rep << "  a camera placed from the object towards world (" << vec3(r.view_hint_world, 3) << ") faces "
        << r.view_hint_vertices << " of them (occlusion not considered)\n";
  }
  const bool done = r.recommended < 0;
  kv << "viewpoint_done: " << (done ? 1 : 0) << "\n";
  if (done)
    rep << "this viewpoint is done: no placeable light that has not failed before adds coverage; take another "
        << "viewpoint for the rest\n";
  rep << "time: visibility " << fixed(r.seconds_visibility, 2) << " s, samples " << fixed(r.seconds_gather, 2)
      << " s, suggestions " << fixed(r.seconds_suggest, 3) << " s (visibility: " << r.visibility_backend << ")\n";
  r.report = rep.str();
  kv_text = kv.str();
}

void write_files(const CoverageSettings &settings, const CoverageInput &input, CoverageResult &r,
                 const std::string &kv_text) {
  r.suggestion_file = settings.suggestion_file.empty() ? default_suggestion_path(input.project_path)
                                                       : settings.suggestion_file;
  if (r.suggestion_file == input.project_path || r.suggestion_file == r.light_file)
    throw InputError("The suggestion file '" + r.suggestion_file + "' would overwrite an input file: choose another.");
  r.vertex_list_file = strip_extension(r.suggestion_file) + "_new_view_vertices.txt";
  std::ostringstream list;
  list << "# Vertices (0-based, mesh order) only a new viewpoint can cover: index reason\n"
       << "# reason: unseen = no photo sees it; diffuse / specular = no placeable light of a registered "
          "viewpoint gives such a sample\n";
  for (size_t i = 0; i < r.new_view_vertices.size(); ++i) {
    const uint8_t why = r.new_view_reasons[i];
    list << r.new_view_vertices[i] << " "
         << (why == kNewViewUnseen ? "unseen" : why == kNewViewDiffuse ? "diffuse" : "specular") << "\n";
  }
  std::ostringstream text;
  text << kv_text << "new_view_list: " << r.vertex_list_file << "\n#\n";
  std::istringstream lines(r.report);
  for (std::string line; std::getline(lines, line);) text << "# " << line << "\n";
  write_text_file_atomically(r.vertex_list_file, list.str());
  write_text_file_atomically(r.suggestion_file, text.str());
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

LightSuggestion suggest_light_with_tolerance(const MeshView &mesh, const Shot &viewpoint, const uint8_t *visible,
                                             const float *needs, CoverageKind kind, const LightSuggestionSettings &s,
                                             float tolerance_deg, size_t *robust_covered, bool brute_force) {
  if (robust_covered) *robust_covered = 0;
  const auto suggest = brute_force ? suggest_next_light_brute_force : suggest_next_light;
  if (tolerance_deg > 0) {
    const float tol = tolerance_deg * kPi / 180, ts = std::acos(s.specular_threshold), td = std::acos(s.diffuse_threshold);
    LightSuggestionSettings tight = s;
    if (kind == CoverageKind::Specular) {
      tight.specular_threshold = std::cos(std::max(0.0f, ts - tol));
    } else {
      tight.diffuse_threshold = std::cos(std::max(0.0f, td - tol));
      tight.specular_threshold = std::cos(std::min(float(kPi / 2), ts + tol));
    }
    LightSuggestion robust = suggest(mesh, viewpoint, visible, needs, kind, tight);
    if (robust.valid) {
      if (robust_covered) *robust_covered = robust.covered_vertices;
      const LightSuggestion exact = suggest(mesh, viewpoint, visible, needs, kind, s);
      robust.needing_vertices = exact.needing_vertices, robust.uncoverable_vertices = exact.uncoverable_vertices;
      robust.covered_vertices = count_covered(mesh, viewpoint, visible, needs, kind, robust.dir_world, s);
      return robust;
    }
  }
  return suggest(mesh, viewpoint, visible, needs, kind, s);
}

namespace {
// The vertices that need samples (visible, weight > 0) with, as a bitmask over the taken lights,
// those that were predicted to give them one: each such light failed them (they still need it).
struct NeedingSet {
  std::vector<uint32_t> vertex;
  std::vector<float> n, e, w;     // unit normal and eye direction (3 floats each), weight
  size_t words = 0;               // 64-bit words per vertex in `failed`
  std::vector<uint64_t> failed;   // vertex-major: failed[i * words + t / 64] bit t % 64
  std::vector<uint8_t> any_failed;
  size_t size() const { return vertex.size(); }
};

NeedingSet needing_set(const MeshView &mesh, const Shot &viewpoint, const uint8_t *visible, const float *needs,
                       CoverageKind kind, const LightSuggestionSettings &s,
                       const std::vector<std::array<float, 3>> &taken) {
  NeedingSet out;
  for (size_t v = 0; v < mesh.vertex_count; ++v)
    if (needs[v] > 0 && visible[v]) out.vertex.push_back(uint32_t(v));
  const size_t m = out.size();
  out.words = (taken.size() + 63) / 64;
  out.n.resize(3 * m), out.e.resize(3 * m), out.w.resize(m), out.any_failed.assign(m, 0);
  out.failed.assign(m * out.words, 0);
  float centre[3];
  camera_centre(viewpoint, centre);
#pragma omp parallel for schedule(static)
  for (long long ii = 0; ii < (long long)m; ++ii) {
    const size_t i = size_t(ii), v = out.vertex[i];
    float *n = &out.n[3 * i], *e = &out.e[3 * i];
    unit_normal(mesh.normals + 3 * v, n);
    eye_direction(centre, mesh.positions + 3 * v, e);
    out.w[i] = needs[v];
    for (size_t t = 0; t < taken.size(); ++t)
      if (covers_unit(kind, n, e, taken[t].data(), s)) {
        out.failed[i * out.words + t / 64] |= uint64_t(1) << (t % 64);
        out.any_failed[i] = 1;
      }
  }
  return out;
}

// Bitmask of the taken lights within the cone around `l`.
std::vector<uint64_t> near_mask(const float *l, const std::vector<std::array<float, 3>> &taken, float cone_cos,
                                size_t words) {
  std::vector<uint64_t> mask(words, 0);
  for (size_t t = 0; t < taken.size(); ++t)
    if (dot3(taken[t].data(), l) >= cone_cos) mask[t / 64] |= uint64_t(1) << (t % 64);
  return mask;
}

// Whether light `l` (with its near_mask) is expected to give needing vertex i a sample: predicted,
// and no light that failed it lies within the cone.
bool counts_for(const NeedingSet &x, size_t i, const float *l, const std::vector<uint64_t> &near, CoverageKind kind,
                const LightSuggestionSettings &s) {
  if (!covers_unit(kind, &x.n[3 * i], &x.e[3 * i], l, s)) return false;
  if (!x.any_failed[i]) return true;
  for (size_t w = 0; w < x.words; ++w)
    if (x.failed[i * x.words + w] & near[w]) return false;
  return true;
}

// Leaves out, before the first search, the failed vertices whose own best light (the normal for
// diffuse, the mirror direction for specular) lies near a light that failed them: their ideal
// light (Algorithms 1 and 3) would point there again.
void drop_failed_ideals(const NeedingSet &x, CoverageKind kind, const std::vector<std::array<float, 3>> &taken,
                        float cone_cos, std::vector<float> &work) {
#pragma omp parallel for schedule(static)
  for (long long ii = 0; ii < (long long)x.size(); ++ii) {
    const size_t i = size_t(ii);
    if (!x.any_failed[i]) continue;
    const float *n = &x.n[3 * i], *e = &x.e[3 * i];
    const float ne = dot3(n, e);
    const float mirror[3] = {2 * ne * n[0] - e[0], 2 * ne * n[1] - e[1], 2 * ne * n[2] - e[2]};
    const float *ideal = kind == CoverageKind::Diffuse ? n : mirror;
    for (size_t t = 0; t < taken.size(); ++t)
      if (((x.failed[i * x.words + t / 64] >> (t % 64)) & 1u) && dot3(taken[t].data(), ideal) >= cone_cos) {
        work[x.vertex[i]] = 0;
        break;
      }
  }
}

// Best direction of a uniform set over the placeable hemisphere, scored with counts_for (the ideal
// lights of the vertices left all failed before: look elsewhere). Invalid when nothing counts.
LightSuggestion explore_directions(const NeedingSet &x, const Shot &viewpoint, CoverageKind kind,
                                   const LightSuggestionSettings &s, const std::vector<std::array<float, 3>> &taken,
                                   float cone_cos) {
  constexpr int kDirections = 600;
  constexpr size_t kMaxScored = 8000;  // larger sets are subsampled for the score
  const size_t stride = std::max<size_t>(1, (x.size() + kMaxScored - 1) / kMaxScored);
  const float zmin = std::sin(s.min_elevation_deg * kPi / 180);
  std::vector<double> score(kDirections, 0);
  std::vector<std::array<float, 3>> dirs(kDirections), cams(kDirections);
  for (int d = 0; d < kDirections; ++d) {
    const float z = zmin + (1 - zmin) * (float(d) + 0.5f) / float(kDirections), r = std::sqrt(std::max(0.0f, 1 - z * z));
    const float phi = float(d) * kPi * (3 - std::sqrt(5.0f));
    cams[size_t(d)] = {{r * std::cos(phi), r * std::sin(phi), z}};
    camera_to_world_direction(viewpoint, cams[size_t(d)].data(), dirs[size_t(d)].data());
  }
#pragma omp parallel for schedule(dynamic, 8)
  for (int d = 0; d < kDirections; ++d) {
    const std::vector<uint64_t> near = near_mask(dirs[size_t(d)].data(), taken, cone_cos, x.words);
    for (size_t i = 0; i < x.size(); i += stride)
      if (counts_for(x, i, dirs[size_t(d)].data(), near, kind, s)) score[size_t(d)] += x.w[i];
  }
  const size_t best = size_t(std::max_element(score.begin(), score.end()) - score.begin());
  LightSuggestion out;
  if (!(score[best] > 0)) return out;
  out.valid = true;
  std::copy(dirs[best].begin(), dirs[best].end(), out.dir_world);
  std::copy(cams[best].begin(), cams[best].end(), out.dir_cam);
  out.azimuth_deg = std::atan2(out.dir_cam[1], out.dir_cam[0]) * 180 / kPi;
  out.elevation_deg = std::asin(std::min(1.0f, out.dir_cam[2])) * 180 / kPi;
  const std::vector<uint64_t> near = near_mask(out.dir_world, taken, cone_cos, x.words);
  for (size_t i = 0; i < x.size(); ++i)
    if (counts_for(x, i, out.dir_world, near, kind, s)) ++out.covered_vertices, out.covered_weight += x.w[i];
  return out;
}
} // namespace

LightSuggestion suggest_light_learning(const MeshView &mesh, const Shot &viewpoint, const uint8_t *visible,
                                       const float *needs, CoverageKind kind, const LightSuggestionSettings &s,
                                       float tolerance_deg, const std::vector<std::array<float, 3>> &taken_lights,
                                       float failure_cone_deg, size_t *robust_covered, bool *repeats_failed,
                                       bool brute_force) {
  if (repeats_failed) *repeats_failed = false;
  const auto suggest = [&](const float *weights) {
    return suggest_light_with_tolerance(mesh, viewpoint, visible, weights, kind, s, tolerance_deg, robust_covered,
                                        brute_force);
  };
  const LightSuggestion plain = suggest(needs);
  if (taken_lights.empty() || failure_cone_deg <= 0 || plain.needing_vertices == 0) return plain;
  const float cone_cos = std::cos(failure_cone_deg * kPi / 180);
  const NeedingSet x = needing_set(mesh, viewpoint, visible, needs, kind, s, taken_lights);
  if (std::find(x.any_failed.begin(), x.any_failed.end(), 1) == x.any_failed.end()) return plain;  // nothing to learn
  std::vector<float> work(needs, needs + mesh.vertex_count);
  drop_failed_ideals(x, kind, taken_lights, cone_cos, work);
  LightSuggestion sg = suggest(work.data());
  constexpr int kRounds = 4;
  for (int round = 0; sg.valid; ++round) {
    // Vertices this light would not cover after all (a photo near it failed them).
    const std::vector<uint64_t> near = near_mask(sg.dir_world, taken_lights, cone_cos, x.words);
    size_t removed = 0;
#pragma omp parallel for reduction(+ : removed) schedule(static)
    for (long long ii = 0; ii < (long long)x.size(); ++ii) {
      const size_t i = size_t(ii), v = x.vertex[i];
      if (work[v] > 0 && x.any_failed[i] && covers_unit(kind, &x.n[3 * i], &x.e[3 * i], sg.dir_world, s) &&
          !counts_for(x, i, sg.dir_world, near, kind, s))
        work[v] = 0, ++removed;
    }
    // A few broken promises do not change the best light; many do: recompute without them.
    if (removed * 10 <= sg.covered_vertices) break;
    if (round + 1 == kRounds) {
      sg = LightSuggestion();  // still mostly broken promises: look elsewhere
      break;
    }
    sg = suggest(work.data());
  }
  if (!sg.valid) {
    sg = explore_directions(x, viewpoint, kind, s, taken_lights, cone_cos);
    if (robust_covered) *robust_covered = 0;
    if (!sg.valid) {  // every light that could help failed before: the best of them again
      if (repeats_failed) *repeats_failed = plain.valid;
      return plain;
    }
  }
  sg.needing_vertices = plain.needing_vertices, sg.uncoverable_vertices = plain.uncoverable_vertices;
  return sg;
}

float prediction_failure_weight(int failures) { return failures <= 0 ? 1.0f : std::pow(0.2f, float(failures)); }

CoverageNeeds coverage_needs(const std::vector<CoverageCounts> &counts, const float *dq, const float *sq,
                             const CoverageSettings &s, const uint16_t *diffuse_failures,
                             const uint16_t *specular_failures) {
  CoverageNeeds needs;
  const size_t n = counts.size();
  needs.diffuse.assign(n, 0.0f);
  needs.specular.assign(n, 0.0f);
  for (size_t v = 0; v < n; ++v) {
    const CoverageClass c = classify_coverage(counts[v], s.min_diffuse, s.min_specular);
    if (c == kUnseen) continue;  // no light of a registered viewpoint helps
    if (c == kSeenNotDiffuse) {
      needs.diffuse[v] = diffuse_failures ? prediction_failure_weight(diffuse_failures[v]) : 1.0f;
      continue;
    }
    if (dq && dq[v] < s.poor_dq && s.poor_dq > 0) {
      needs.diffuse[v] = std::min(1.0f, std::max(0.05f, (s.poor_dq - dq[v]) / s.poor_dq));
      ++needs.poor_diffuse;
    }
    if (c == kDiffuseNoSpecular) {
      needs.specular[v] = specular_failures ? prediction_failure_weight(specular_failures[v]) : 1.0f;
    } else if (sq && sq[v] < s.poor_sq && s.poor_sq > 0) {
      needs.specular[v] = std::min(1.0f, std::max(0.05f, (s.poor_sq - sq[v]) / s.poor_sq));
      ++needs.poor_specular;
    }
  }
  return needs;
}

void prediction_failures(const MeshView &mesh, const std::vector<uint8_t> &classes, const Viewpoint &viewpoint,
                         const std::vector<LightSource> &lights, const LightSuggestionSettings &s,
                         std::vector<uint16_t> &diffuse, std::vector<uint16_t> &specular) {
  const size_t n = mesh.vertex_count;
  diffuse.assign(n, 0);
  specular.assign(n, 0);
  float centre[3];
  camera_centre(viewpoint.shot, centre);
#pragma omp parallel for schedule(dynamic, 4096)
  for (long long vi = 0; vi < (long long)n; ++vi) {
    const size_t v = size_t(vi);
    const bool need_d = classes[v] == kSeenNotDiffuse, need_s = classes[v] == kDiffuseNoSpecular;
    if (!need_d && !need_s) continue;
    float e[3], nrm[3];
    eye_direction(centre, mesh.positions + 3 * v, e);
    unit_normal(mesh.normals + 3 * v, nrm);
    int fails = 0;
    for (size_t r : viewpoint.rasters) {
      float l[3];
      light_direction_at(lights[r], mesh.positions + 3 * v, l);  // a point light's direction at the vertex
      fails += covers_unit(need_d ? CoverageKind::Diffuse : CoverageKind::Specular, nrm, e, l, s);
    }
    (need_d ? diffuse : specular)[v] = uint16_t(std::min(fails, 65535));
  }
}

std::unique_ptr<VisibilityBackend> make_coverage_visibility(const MeshView &mesh, const CoverageSettings &settings,
                                                            const std::function<void *(const char *)> &get_proc,
                                                            const LogFn &log) {
  FitSettings fit;
  fit.visibility = settings.visibility;
  fit.visibility_choice = settings.visibility_choice;
  return make_visibility_backend(mesh, fit, get_proc, log);
}

std::string default_suggestion_path(const std::string &project_path) {
  if (project_path.empty()) return "vertex_brdf_next_light.txt";
  return strip_extension(project_path) + "_next_light.txt";
}

std::string suggestion_value(const std::string &text, const std::string &key) {
  std::istringstream lines(text);
  const std::string prefix = key + ": ";
  for (std::string line; std::getline(lines, line);)
    if (line.compare(0, prefix.size(), prefix) == 0) return line.substr(prefix.size());
  return "";
}

CoverageResult run_coverage(const CoverageInput &input, const CoverageSettings &settings_in,
                            VisibilityBackend &visibility, const ProgressFn &progress, const LogFn &log) {
  FitInput check;
  check.mesh = input.mesh;
  check.mesh_name = input.mesh_name;
  check.rasters = input.rasters;
  validate_input(check);
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
      light_placement_of(mesh.positions, mesh.vertex_count, settings.dome_radius, settings.light_unit_scale);
  const bool plain_lp = placement.dome_radius <= 0 && extension_of(r.light_file) == "lp";
  const std::vector<LightSource> sources =
      plain_lp ? directional_lights(lights_for_rasters(input.rasters, r.light_file, &unused))
               : resolve_lights(input.rasters, r.light_file, placement);
  log("Lights: " + describe_lights(sources, placement) + " from '" + r.light_file + "'" +
      (unused.empty() ? std::string(".") : " (" + std::to_string(unused.size()) + " entries for photos not imported yet)."));

  PhotoCache photos(settings.gather.encoding, settings.gather.saturation_level, settings.gather.photo_cache_bytes);
  for (const Raster &raster : input.rasters) photos.get(raster.image_path, raster.width(), raster.height());

  auto t = Clock::now();
  const VisibilityMasks masks = compute_visibility(mesh, input.rasters, sources, visibility,
                                                   [&](float f, const char *s) { return !progress || progress(0.45f * f, s); });
  r.seconds_visibility = seconds_since(t);

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
  for (size_t v = 0; v < n; ++v) {
    const CoverageClass c = classify_coverage(r.counts[v], settings.min_diffuse, settings.min_specular);
    r.classes[v] = c;
    ++r.class_counts[c];
    const auto col = coverage_class_color(c);
    std::copy(col.begin(), col.end(), r.colors_rgba.begin() + std::ptrdiff_t(4 * v));
  }
  const Viewpoint &vp = r.viewpoints[r.viewpoint];
  std::vector<uint16_t> fail_d, fail_s;
  prediction_failures(mesh, r.classes, vp, sources, settings.suggest, fail_d, fail_s);
  for (size_t v = 0; v < n; ++v) r.failed_diffuse += fail_d[v] > 0, r.failed_specular += fail_s[v] > 0;
  const CoverageNeeds needs = coverage_needs(r.counts, input.dq.empty() ? nullptr : input.dq.data(),
                                             input.sq.empty() ? nullptr : input.sq.data(), settings, fail_d.data(),
                                             fail_s.data());
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
    if (!reasons[v]) continue;
    r.new_view_vertices.push_back(uint32_t(v)), r.new_view_reasons.push_back(reasons[v]);
    bool clean = reasons[v] == kNewViewUnseen;
    for (size_t i = 0; i < visible.size() && !clean; ++i) clean = visible[i][v] != 0;
    r.new_view_mixed += !clean;
  }
  r.has_view_hint = new_view_hint(mesh, r.new_view_vertices, r.view_hint_world, r.view_hint_vertices);
  r.seconds_suggest = seconds_since(t);

  std::string kv_text;
  build_texts(input, settings, r, kv_text);
  if (settings.write_files) write_files(settings, input, r, kv_text);
  std::istringstream lines(r.report);
  for (std::string line; std::getline(lines, line);) log(line);
  if (!r.suggestion_file.empty()) log("suggestions written to " + r.suggestion_file);
  report_progress(progress, 1.0f, "done");
  return r;
}

namespace {
bool is_image_name(const std::string &name) {
  const std::string lower = to_lower(name);
  for (const char *ext : {".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp"}) {
    const std::string e = ext;
    if (lower.size() > e.size() && lower.compare(lower.size() - e.size(), e.size(), e) == 0) return true;
  }
  return false;
}

std::string canonical(const std::string &path) {
  char buffer[PATH_MAX];
  return ::realpath(path.c_str(), buffer) ? std::string(buffer) : path;
}

std::string relative_to(const std::string &path, const std::string &folder) {
  const std::string a = canonical(path), dir = canonical(folder) + "/";
  return a.compare(0, dir.size(), dir) == 0 ? a.substr(dir.size()) : a;
}
} // namespace

std::vector<std::string> new_photos_in_folder(const std::string &folder, const std::vector<Raster> &rasters) {
  std::set<std::string> taken;
  for (const Raster &r : rasters) taken.insert(canonical(r.image_path));
  DIR *d = ::opendir(folder.c_str());
  if (!d) throw InputError("Photo folder '" + folder + "' cannot be read: check the path.");
  std::vector<std::string> found;
  while (dirent *e = ::readdir(d)) {
    const std::string name = e->d_name;
    const std::string path = join_path(folder, name);
    if (is_image_name(name) && file_exists(path) && !taken.count(canonical(path))) found.push_back(path);
  }
  ::closedir(d);
  std::sort(found.begin(), found.end());
  return found;
}

std::vector<LightEntry> sphere_light_entries(const std::vector<std::string> &photos, const std::vector<size_t> &wanted,
                                             const Shot &shot, const SphereCircle &manual,
                                             const std::string &lp_folder, const LogFn &log) {
  LightSettings settings;
  if (manual.r > 0) settings.manual_spheres.push_back(manual);
  std::vector<std::string> names;
  for (const std::string &p : photos) names.push_back(file_name_of(p));
  const GrayLoader load = [&photos](size_t i) {
    const cv::Mat image = cv::imread(photos[i], cv::IMREAD_UNCHANGED);
    if (image.empty()) throw InputError("Photo '" + photos[i] + "' cannot be read: check the file.");
    return gray_image(image, true);
  };
  const LightCalibration cal = calibrate_lights(photos.size(), load, camera_from_shot(shot), settings, names);
  for (const std::string &line : cal.log) log("Sphere: " + line);
  std::vector<LightEntry> out;
  for (size_t i : wanted) {
    const PhotoLight &p = cal.photos.at(i);
    if (!p.valid)
      throw InputError("Photo '" + photos[i] + "': no light from the sphere (" +
                       (p.warning.empty() ? std::string("no highlight found") : p.warning) +
                       "). Check that the sphere and its highlight are in the picture, give the sphere's centre "
                       "and radius, or take the light from an .lp.");
    LightEntry e;
    e.image = relative_to(photos[i], lp_folder);
    for (int k = 0; k < 3; ++k) e.dir_cam[k] = float(p.dir[k]);
    out.push_back(e);
  }
  return out;
}

std::vector<LightEntry> merge_light_entries(const std::vector<LightEntry> &existing, const std::vector<LightEntry> &added) {
  std::vector<LightEntry> out;
  for (const LightEntry &e : existing)
    if (find_light_for_image(added, e.image) < 0) out.push_back(e);
  out.insert(out.end(), added.begin(), added.end());
  return out;
}

} // namespace vbrdf
