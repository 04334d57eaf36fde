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
#include "coverage/coverage_settings.h"
#include "coverage/new_view.h"
#include "base/output_file.h"
#include "samples/samples.h"
#include "calibration/sphere_lights.h"
#include "inputs/viewpoints.h"
#include "coverage/import_photos.h"
#include "coverage/suggest_learning.h"
#include "visibility/visibility_masks.h"

namespace vbrdf {

// Lenient light lookup for an acquisition in progress: every raster needs an entry in `lp_path`
// (InputError naming the .lp and the raster otherwise); entries for photos not imported yet are
// allowed (their names go to `unused` when given). Directions are returned in world coordinates.
std::vector<std::array<float, 3>> lights_for_rasters(const std::vector<Raster> &rasters, const std::string &lp_path,
                                                     std::vector<std::string> *unused = nullptr);

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
// weighted coverage that does not repeat a failed light. Checks the mesh and rasters as the fit
// does (inputs/input_check.h). Throws InputError when dq/sq do not have one value per vertex, when
// settings.viewpoint_raster is out of range, or when no light file serves (resolve_light_file).
CoverageResult run_coverage(const CoverageInput &input, const CoverageSettings &settings, VisibilityBackend &visibility,
                            const ProgressFn &progress, const LogFn &log);

} // namespace vbrdf
