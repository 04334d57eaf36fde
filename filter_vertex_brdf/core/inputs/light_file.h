#pragma once
// RTI light-position files (.lp), as written by RTIBuilder / Relight:
//   first line: N
//   then N lines: image_file lx ly lz
// (lx, ly, lz) is the unit direction towards the light in the camera frame: x right, y up,
// z towards the camera.
#include <string>
#include <vector>

#include "inputs/camera.h"

namespace vbrdf {

struct LightEntry {
  std::string image;  // file name as written in the .lp (may contain a relative path)
  float dir_cam[3];   // normalised on read
};

// Reads an .lp file. Throws InputError naming the file and line on: unreadable file, bad count,
// fewer/more lines than the count says, non-numeric values, zero-length direction, one image
// listed twice with different directions (twice with the same one is accepted). A UTF-8
// byte-order mark and CRLF line ends are accepted.
std::vector<LightEntry> read_light_file(const std::string &path);

// Writes an .lp file (RTIBuilder/Relight compatible), atomically. Throws ProcessingError on I/O.
void write_light_file(const std::string &path, const std::vector<LightEntry> &lights);

// Finds the entry whose image file name matches `image_path` (compared by file name without
// directories, case-sensitive first, then case-insensitive). Returns -1 when none matches.
int find_light_for_image(const std::vector<LightEntry> &lights, const std::string &image_path);

// The default light file of a set of photos: the one rule of every filter and tool (fit,
// coverage, import, relight, vbrdf_fit, vbrdf_eval, ...).
//   Candidates: every *.lp beside `project_path` (may be empty) and beside each raster's photo.
//   A candidate qualifies when it reads as an .lp and has an entry (find_light_for_image) for
//   every raster; entries for other photos are allowed here.
//   Returns the most recently modified qualifying file (equal times: the first in path order),
//   or "" when none qualifies. `checked` (optional) receives "<file>: <why not>" per rejected one.
// Why this rule: the light-estimation steps (sphere filter, import filter) write a new .lp after
// each shot that carries every earlier entry over, so the newest complete file is the current
// one; an older file (e.g. the lights.lp of the first shots) either lacks the new photos or holds
// superseded estimates, and a file that lacks a raster can never serve. Alphabetical order (the
// fit's former rule) means nothing and let the fit pick a stale lights.lp after an import.
std::string find_default_light_file(const std::vector<Raster> &rasters, const std::string &project_path,
                                    std::vector<std::string> *checked = nullptr);

// The light file of a run: `given` (a path the caller resolved) when not empty, else the default
// rule's file (find_default_light_file). Every filter and tool resolves its 'lightFile' here, so
// that a missing file reads the same everywhere: throws InputError "No light file (.lp) found
// beside the project or the photos: ..." when there is no candidate, or "No light file (.lp)
// beside the project or the photos has an entry for every raster: ..." followed by each file
// checked and why it does not serve; both name 'lightFile'. `given` is not read here: reading it
// reports its own errors (read_light_file, light_source.h).
std::string resolve_light_file(const std::string &given, const std::vector<Raster> &rasters,
                               const std::string &project_path);

} // namespace vbrdf
