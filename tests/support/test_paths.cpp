#include "test_paths.h"

#include <cstdlib>
#include <string>
#include <sys/stat.h>
#include <unistd.h>

namespace vbrdf {
namespace test {
std::string shared_dir() {
  const char *env = std::getenv("VBRDF_SHARED_DIR");
  if (env && *env) return env;
  return VBRDF_SHARED_DIR_DEFAULT;
}

std::string shared_missing(const std::string &relative) {
  const std::string path = shared_dir() + "/" + relative;
  struct stat st;
  if (::stat(path.c_str(), &st) == 0) return std::string();
  return "shared test data not found: " + path +
         " (not part of the repository; set VBRDF_SHARED_DIR to the folder holding scenes/ and real/)";
}

std::string scratch_dir(const std::string &name) {
  static int counter = 0;
  const char *tmp = std::getenv("TMPDIR");
  std::string dir = std::string(tmp ? tmp : "/tmp") + "/vbrdf_test_" + std::to_string(::getpid()) + "_" +
                    std::to_string(counter++) + "_" + name;
  const std::string cmd = "mkdir -p '" + dir + "'";
  if (std::system(cmd.c_str()) != 0) return "/tmp";
  return dir;
}
} // namespace test
} // namespace vbrdf
