#pragma once
// Acquisition feedback without MeshLab (thesis 4.4.1, 4.5, 4.7): project -> lights -> visibility
// -> samples -> per-vertex coverage counts and classes -> next diffuse and specular light for one
// viewpoint -> colours, report and suggestion file. The coverage filter, the photo import filter
// and the vbrdf_coverage tool all call run_coverage; they differ only in how they get the mesh,
// the rasters and the GL context.
//
// Viewpoints: photos of one viewpoint share one registration, i.e. an identical shot. Rasters are
// grouped by shot; suggestions are for one viewpoint (by default the one of the last raster, the
// photographer's current camera position), since a light is only placeable relative to a camera.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "inputs/camera.h"
#include "coverage/coverage.h"
#include "inputs/light_file.h"
#include "inputs/light_source.h"
#include "base/mesh_view.h"
#include "fit/pipeline.h"
#include "io/output_file.h"
#include "samples/samples.h"
#include "calibration/sphere_lights.h"
#include "inputs/viewpoints.h"
#include "coverage/import_photos.h"
#include "coverage/suggest_learning.h"
#include "visibility/visibility.h"

namespace vbrdf {

// Lenient light lookup for an acquisition in progress: every raster needs an entry in `lp_path`
// (InputError naming the .lp and the raster otherwise); entries for photos not imported yet are
// allowed (their names go to `unused` when given). Directions are returned in world coordinates.
std::vector<std::array<float, 3>> lights_for_rasters(const std::vector<Raster> &rasters, const std::string &lp_path,
                                                     std::vector<std::string> *unused = nullptr);

struct CoverageSettings {
  // Coverage asks for well-lit samples (T_d kCoverageDiffuseThreshold) and counts highlights on R.E
  // (kHighlight): it fits no lobe, so its samples take the R.E cosine and no footprints.
  CoverageSettings() {
    gather.diffuse_threshold = kCoverageDiffuseThreshold;
    gather.lobe = LobeForm::PhongRE;
  }
  GatherSettings gather;            // T_s and T_d classify samples and drive the suggestions
  VisibilitySettings visibility;
  VisibilityChoice visibility_choice = VisibilityChoice::Auto;
  LightSuggestionSettings suggest;  // its thresholds are replaced by gather's
  int min_diffuse = 1;              // diffuse samples a vertex needs to count as diffusely covered
  int min_specular = kDefaultMinSpecularSamples;  // specular samples it needs to count as specularly covered
  int viewpoint_raster = -1;        // suggestions for the viewpoint of this raster; -1: the last raster
  // With a fit (CoverageInput::dq/sq): a covered vertex whose DQ (SQ) is below this still needs
  // diffuse (specular) samples, weighted (poor - q) / poor; uncovered vertices weigh 1.
  float poor_dq = 1.5f;
  float poor_sq = 1.5f;
  float tolerance_deg = 0;          // suggestions robust to this light placement error (0: exact)
  float failure_cone_deg = 20;      // suggest_light_learning: learn from failed predictions (0: off)
  // Learn from the previous suggestion file (same path): when photos were added to the viewpoint
  // since, its recommended light counts as followed, i.e. as a light whose promises are checked
  // (suggest_light_learning), together with the lights followed before. Needs write_files.
  bool learn_from_previous = true;
  std::string light_file;           // "" = find_default_light_file (light_file.h); .json / .dome: light_source.h
  float dome_radius = 0;            // as FitSettings: the .lp's directions as point lights on a dome
  float light_unit_scale = 0;       // as FitSettings: mesh units per unit of the light file's positions
  std::string suggestion_file;      // "" = <project folder>/<project name>_next_light.txt
  // An existing suggestion file (and its vertex list): replaced, the log saying so (the default:
  // each run replaces the last one and learns from it), or the run refused before any work.
  OverwritePolicy overwrite = OverwritePolicy::Replace;
  bool write_files = true;          // false: nothing is written (result only)
};

struct CoverageInput {
  MeshView mesh;
  std::string mesh_name;            // for messages
  std::vector<Raster> rasters;
  std::string project_path;         // the .mlp (default paths; may be empty)
  std::vector<float> dq, sq;        // optional per-vertex fit quality in [0, 2] (empty: no fit)
  std::string quality_source;       // where dq/sq came from (report)
  // "Only on selection": per vertex, 0 = left out: classified and coloured as usual, but it asks
  // for no light, is never listed as needing a new viewpoint and is not counted. Empty: all.
  std::vector<uint8_t> vertex_mask;
};

// Why a vertex can only be covered from a new viewpoint.
enum NewViewReason : uint8_t {
  kNewViewUnseen = 1,    // no photo sees it
  kNewViewDiffuse = 2,   // needs diffuse samples; no placeable light of any viewpoint gives one
  kNewViewSpecular = 4,  // needs specular samples; no placeable light of any viewpoint gives one
};

// Per vertex, the NewViewReason of a vertex only a new viewpoint can cover (0: a registered one
// can): unseen (class kUnseen), or needing diffuse (specular) samples while no viewpoint that sees
// it cleanly (visible[i][v], one mask per viewpoint) has a placeable light that would give one.
std::vector<uint8_t> new_view_reasons(const MeshView &mesh, const std::vector<uint8_t> &classes,
                                      const std::vector<std::vector<uint8_t>> &visible,
                                      const std::vector<Viewpoint> &viewpoints, const LightSuggestionSettings &s);

struct CoverageResult {
  std::vector<CoverageCounts> counts;      // per vertex
  std::vector<uint8_t> classes;            // per vertex, CoverageClass
  std::vector<uint8_t> colors_rgba;        // per vertex, coverage_class_color
  size_t class_counts[4] = {0, 0, 0, 0};   // indexed by CoverageClass (vertices considered only)
  size_t vertices_considered = 0;          // all, or the selected ones (CoverageInput::vertex_mask)
  std::vector<Viewpoint> viewpoints;
  size_t viewpoint = 0;                    // the suggestions' viewpoint (index into viewpoints)
  LightSuggestion diffuse, specular;       // next lights for that viewpoint (valid == false: none)
  bool diffuse_repeats = false, specular_repeats = false;  // repeats a light that failed (see suggest_light_learning)
  int recommended = -1;                    // the one to take next: 0 diffuse, 1 specular, -1 none
  std::vector<std::array<float, 3>> followed;  // earlier suggestions followed by photos (world)
  size_t poor_diffuse = 0, poor_specular = 0;  // see CoverageNeeds
  size_t failed_diffuse = 0, failed_specular = 0;  // uncovered vertices a photo's light should have covered
  std::vector<uint32_t> new_view_vertices; // vertices only a new viewpoint can cover, ascending
  std::vector<uint8_t> new_view_reasons;   // NewViewReason bits, parallel to new_view_vertices
  size_t new_view_mixed = 0;               // of the seen ones: seen only in mixed pixels (silhouettes, borders)
  bool has_view_hint = false;
  float view_hint_world[3] = {0, 0, 0};    // direction from the object towards a good new camera
  size_t view_hint_vertices = 0;           // new-view vertices facing it (N.D >= 0.5)
  std::string light_file;                  // the .lp used
  std::string suggestion_file, vertex_list_file;  // written files ("" when not written)
  std::string suggestion_note;             // "new file" / "replaces the existing file (N bytes)"
  std::string report;                      // human-readable (also in the suggestion file)
  std::string visibility_backend;
  double seconds_visibility = 0, seconds_gather = 0, seconds_suggest = 0;
};

// Runs everything and, when settings.write_files, writes the suggestion file (key: value lines
// plus the report) and beside it the list of vertices only a new viewpoint can cover
// (<suggestion file stem>_new_view_vertices.txt), both atomically. Suggestions learn from the
// viewpoint's photos and, with settings.learn_from_previous, from the previous suggestion file at
// the same path (suggest_light_learning); `recommended` is the valid suggestion promising more
// weighted coverage that does not repeat a failed light. Needs a mesh with normals and at least
// one raster (InputError otherwise, as validate_input). Throws InputError when dq/sq do not have
// one value per vertex, when settings.viewpoint_raster is out of range, or when no .lp has an
// entry for every raster.
CoverageResult run_coverage(const CoverageInput &input, const CoverageSettings &settings, VisibilityBackend &visibility,
                            const ProgressFn &progress, const LogFn &log);

} // namespace vbrdf
