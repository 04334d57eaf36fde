#pragma once
// What a coverage run hands to the user: the report, and the suggestion file ("key: value" lines
// followed by the report as comments) with its list of vertices only a new viewpoint can cover.
#include <array>
#include <string>
#include <vector>

#include "run/coverage_run.h"

namespace vbrdf {

// The default suggestion file: <project folder>/<project name>_next_light.txt
// ("vertex_brdf_next_light.txt" when no project path is known).
std::string default_suggestion_path(const std::string &project_path);

// Keys of the suggestion file ("key: value" lines): read back by tests and scripts.
// Returns the value of `key`, or "" when absent.
std::string suggestion_value(const std::string &suggestion_text, const std::string &key);

// The suggestions followed so far: those listed by the previous suggestion file at `path` for this
// mesh and viewpoint, plus its recommended light when photos were added to the viewpoint since.
// Empty when there is no such file, or it was written for another mesh or viewpoint.
std::vector<std::array<float, 3>> followed_suggestions(const std::string &path, const CoverageInput &input,
                                                       const Viewpoint &vp);

// Fills r.report (human-readable) and `kv_text` (the suggestion file's key: value part) from a
// finished run.
void build_coverage_texts(const CoverageInput &input, const CoverageSettings &settings, CoverageResult &r,
                          std::string &kv_text);

// Writes the suggestion file (settings.suggestion_file, or the default) and the new-view vertex
// list beside it, both atomically; sets r.suggestion_file and r.vertex_list_file. Throws
// InputError when the suggestion file would overwrite the project or the light file.
void write_coverage_files(const CoverageSettings &settings, const CoverageInput &input, CoverageResult &r,
                          const std::string &kv_text);

} // namespace vbrdf
