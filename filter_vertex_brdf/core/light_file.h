#pragma once
// RTI light-position files (.lp), as written by RTIBuilder / Relight:
//   first line: N
//   then N lines: image_file lx ly lz
// (lx, ly, lz) is the unit direction towards the light in the camera frame: x right, y up,
// z towards the camera.
#include <string>
#include <vector>

namespace vbrdf {

struct LightEntry {
  std::string image;  // file name as written in the .lp (may contain a relative path)
  float dir_cam[3];   // normalised on read
};

// Reads an .lp file. Throws InputError naming the file and line on: unreadable file, bad count,
// fewer/more lines than the count says, non-numeric values, zero-length direction.
std::vector<LightEntry> read_light_file(const std::string &path);

// Writes an .lp file (RTIBuilder/Relight compatible), atomically. Throws ProcessingError on I/O.
void write_light_file(const std::string &path, const std::vector<LightEntry> &lights);

// Finds the entry whose image file name matches `image_path` (compared by file name without
// directories, case-sensitive first, then case-insensitive). Returns -1 when none matches.
int find_light_for_image(const std::vector<LightEntry> &lights, const std::string &image_path);

// Default .lp search: every *.lp beside the project file, then beside the first image.
// Returns "" when none is found. If several are found the first in sorted order is returned.
std::string find_default_light_file(const std::string &project_path, const std::string &first_image_path);

} // namespace vbrdf
