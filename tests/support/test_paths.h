#pragma once
// Paths to the source tree and to ../shared for tests and tools (set by CMake).
#include <string>

namespace vbrdf {
namespace test {
inline std::string source_dir() { return VBRDF_SOURCE_DIR; }
inline std::string shared_dir() { return VBRDF_SHARED_DIR; }
// A fresh scratch folder under the build tree's temp area, unique per call.
std::string scratch_dir(const std::string &name);
} // namespace test
} // namespace vbrdf
