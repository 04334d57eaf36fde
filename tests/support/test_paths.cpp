#include "test_paths.h"

#include <cstdlib>
#include <string>
#include <unistd.h>

namespace vbrdf {
namespace test {
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
