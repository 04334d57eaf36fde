#pragma once
// Paths to the source tree and to the shared test data (../shared) for tests and tools.
//
// The shared data (Mitsuba scenes, real photographs) is not part of the repository: a plain clone
// has none. Its location is one setting, read here and nowhere else in C++:
//   the environment variable VBRDF_SHARED_DIR when it is set and non-empty, else the folder
//   configured at build time (CMake cache variable VBRDF_SHARED_DIR, whose default is the
//   environment variable at configure time, else <repo>/../shared).
// Script tests registered by CMake resolve it the same way (tests/support/with_shared.sh).
#include <string>

namespace vbrdf {
namespace test {
inline std::string source_dir() { return VBRDF_SOURCE_DIR; }
// The shared data folder (see above). Never empty; the folder may not exist.
std::string shared_dir();
// Empty when <shared_dir()>/<relative> exists (file or folder); else a one-line reason naming the
// missing path and the variable to set, for a skip message.
std::string shared_missing(const std::string &relative);
// A fresh scratch folder under the build tree's temp area, unique per call.
std::string scratch_dir(const std::string &name);
} // namespace test
} // namespace vbrdf

// In a gtest test body: skips the test (GTEST_SKIP, reason printed) when <shared_dir()>/<relative>
// is absent, so that a plain clone reports it as skipped, not failed. With the data present the
// test runs unchanged.
#define VBRDF_REQUIRE_SHARED(relative)                                                 \
  do {                                                                                 \
    const std::string vbrdf_shared_missing_ = ::vbrdf::test::shared_missing(relative); \
    if (!vbrdf_shared_missing_.empty()) GTEST_SKIP() << vbrdf_shared_missing_;         \
  } while (0)
