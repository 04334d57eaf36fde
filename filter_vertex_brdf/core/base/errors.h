#pragma once
// Errors the core reports to its callers. Every message names the file, raster or vertex concerned
// and says what the user can do about it; the plugin shows it in MeshLab's log / error dialog.
#include <stdexcept>
#include <string>

namespace vbrdf {

// Bad or inconsistent input (missing image, .lp mismatch, raster without shot, empty mesh...).
class InputError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// A processing stage failed for a reason that is not the user's input (GL failure, I/O error).
class ProcessingError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

} // namespace vbrdf
