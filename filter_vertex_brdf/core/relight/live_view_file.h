#pragma once
// A live view (live_relight.h) as a small text file: what the render plugin drew last, written
// when the environment variable VBRDF_RELIGHT_VIEW_LOG names a file, so that the GUI test can
// render the same view and light with the relight renderer and compare it with a screenshot.
//   vbrdf_live_view 1
//   viewport <x> <y> <width> <height>
//   modelview <16 numbers, column-major>
//   projection <16 numbers, column-major>
//   light <4 numbers: GL_LIGHT0 position, eye coordinates>
//   display <LiveDisplay code>
//   exposure <number>
#include <string>

#include "relight/live_relight.h"

namespace vbrdf {

struct LiveViewRecord {
  LiveView view;
  int viewport[4] = {0, 0, 0, 0};
};

// Writes (replaces) `path`; throws ProcessingError naming it when it cannot be written.
void write_live_view(const std::string &path, const LiveViewRecord &record);
// Reads a file of write_live_view; throws InputError naming the file and the first bad line.
LiveViewRecord read_live_view(const std::string &path);

} // namespace vbrdf
