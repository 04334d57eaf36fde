#include "run/coverage_outputs.h"

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "base/errors.h"
#include "base/file_util.h"
#include "base/vec3.h"
#include "io/output_ply.h"

namespace vbrdf {

namespace {

std::string vec3(const float v[3], int digits = 4) {
  return fixed(v[0], digits) + " " + fixed(v[1], digits) + " " + fixed(v[2], digits);
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

} // namespace

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

void build_coverage_texts(const CoverageInput &input, const CoverageSettings &settings, CoverageResult &r,
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
      << (r.vertices_considered < n ? "only on selection: " + std::to_string(r.vertices_considered) + " of " +
                                          std::to_string(n) + " vertices considered (counts below are of these)\n"
                                    : std::string())
      << "legend (vertex colours) and counts:\n";
  static const char *const keys[4] = {"unseen", "seen_not_diffuse", "diffuse_no_specular", "fully_covered"};
  static const char *const colour_names[4] = {"purple", "blue", "yellow", "green"};
  for (int c = 0; c < 4; ++c) {
    const auto col = coverage_class_color(CoverageClass(c));
    rep << "  " << colour_names[c] << " (" << int(col[0]) << "," << int(col[1]) << "," << int(col[2])
        << "): " << coverage_class_name(CoverageClass(c)) << ": " << r.class_counts[c] << " ("
        << percent(r.class_counts[c], r.vertices_considered) << ")\n";
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

void write_coverage_files(const CoverageSettings &settings, const CoverageInput &input, CoverageResult &r,
                          const std::string &kv_text) {
  r.suggestion_file = settings.suggestion_file.empty() ? default_suggestion_path(input.project_path)
                                                       : settings.suggestion_file;
  if (r.suggestion_file == input.project_path || r.suggestion_file == r.light_file)
    throw InputError("The suggestion file '" + r.suggestion_file + "' would overwrite an input file: choose another.");
  r.vertex_list_file = strip_extension(r.suggestion_file) + "_new_view_vertices.txt";
  check_output_path(r.vertex_list_file, settings.overwrite, "Suggestion file");
  r.suggestion_note = check_output_path(r.suggestion_file, settings.overwrite, "Suggestion file");
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

} // namespace vbrdf
