// Output files, nothing lost (issue 17): overwrite policy, stale temporaries of killed runs, a
// file size limit (as a full disk) and a short temporary become errors with the previous file intact.
#include <csignal>
#include <fstream>
#include <gtest/gtest.h>
#include <sstream>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "base/errors.h"
#include "base/file_util.h"
#include "io/output_file.h"
#include "io/output_ply.h"
#include "test_paths.h"
#include "test_scenes.h"

using namespace vbrdf;

namespace {
std::string read_all(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void write(const std::string &path, const std::string &text) { std::ofstream(path, std::ios::binary) << text; }

template <typename E>
std::string error_of(const std::function<void()> &f) {
  try {
    f();
  } catch (const E &e) {
    return e.what();
  }
  return "";
}

pid_t dead_pid() {  // a process that has exited and been reaped
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  ::waitpid(pid, nullptr, 0);
  return pid;
}
} // namespace

TEST(OutputFile, OverwritePolicyAndFolderChecks) {
  const std::string dir = test::scratch_dir("out_policy");
  const std::string path = dir + "/r.ply";
  EXPECT_EQ(check_output_path(path, OverwritePolicy::Refuse, "Output PLY"), "new file");
  write(path, "previous");
  EXPECT_EQ(check_output_path(path, OverwritePolicy::Replace, "Output PLY"), "replaces the existing file (8 bytes)");
  const std::string refused =
      error_of<InputError>([&] { check_output_path(path, OverwritePolicy::Refuse, "Output PLY"); });
  EXPECT_NE(refused.find("r.ply' already exists"), std::string::npos) << refused;
  EXPECT_NE(refused.find("'Overwrite existing output' is off"), std::string::npos) << refused;
  const std::string missing =
      error_of<InputError>([&] { check_output_path(dir + "/nope/r.ply", OverwritePolicy::Replace, "Output PLY"); });
  EXPECT_NE(missing.find("does not exist"), std::string::npos) << missing;
  EXPECT_NE(missing.find("'Output PLY'"), std::string::npos) << missing;
  EXPECT_NE(error_of<InputError>([&] { check_output_path(dir, OverwritePolicy::Replace, "Output PLY"); }).find("is a folder"),
            std::string::npos);
  EXPECT_EQ(read_all(path), "previous");  // checking never touches the file
}

TEST(OutputFile, StaleTemporariesOfDeadRunsAreRemovedOthersKept) {
  const std::string dir = test::scratch_dir("out_stale");
  const std::string path = dir + "/r.ply";
  const std::string dead = path + ".tmp" + std::to_string(dead_pid());
  const std::string alive = path + ".tmp" + std::to_string(::getppid());  // a running process
  const std::string other = dir + "/other.ply.tmp" + std::to_string(dead_pid());
  for (const std::string &f : {dead, alive, other}) write(f, "partial");
  write(path, "previous");
  EXPECT_EQ(remove_stale_temporaries(path), 1u);
  EXPECT_FALSE(file_exists(dead));
  EXPECT_TRUE(file_exists(alive));   // may be a concurrent run's: left alone
  EXPECT_TRUE(file_exists(other));   // another output's: not ours
  EXPECT_EQ(read_all(path), "previous");
  // Writing the output removes them too, and the result replaces the previous file.
  write(dead, "partial");
  write_text_file_atomically(path, "new");
  EXPECT_FALSE(file_exists(dead));
  EXPECT_EQ(read_all(path), "new");
}

TEST(OutputFile, ShortTemporaryIsNotCommitted) {
  const std::string dir = test::scratch_dir("out_short");
  const std::string path = dir + "/r.txt";
  write(path, "previous");
  std::string tmp;
  const std::string msg = error_of<ProcessingError>([&] {
    AtomicOutput out(path);
    tmp = out.temporary();
    write(out.temporary(), "half");
    out.commit(8);  // 8 bytes expected, 4 written
  });
  EXPECT_NE(msg.find("the previous file is unchanged"), std::string::npos) << msg;
  EXPECT_EQ(read_all(path), "previous");
  EXPECT_FALSE(file_exists(tmp));
  {
    AtomicOutput out(path);  // not committed (an exception elsewhere): the temporary goes
    tmp = out.temporary();
    write(tmp, "abandoned");
  }
  EXPECT_FALSE(file_exists(tmp));
  EXPECT_EQ(read_all(path), "previous");
}

// A file size limit (RLIMIT_FSIZE, `ulimit -f`) stands for a full disk: the write fails with an
// error naming the cause, instead of SIGXFSZ killing the process, and the previous file stays.
// Run in a child process, whose limit does not affect the test runner.
TEST(OutputFile, FileSizeLimitIsAnErrorNotACrash) {
  const std::string dir = test::scratch_dir("out_fsize");
  const std::string text_path = dir + "/report.txt", ply_path = dir + "/r.ply";
  write(text_path, "previous report");
  write(ply_path, "previous ply");
  const MeshData mesh = test::make_grid(40, 1.0f, 0.0f);  // 1681 vertices: ~70 KB with one attribute
  const size_t n = mesh.positions.size() / 3;
  const std::string result_file = dir + "/child_result.txt";
  const pid_t pid = ::fork();
  if (pid == 0) {
    struct rlimit limit = {16384, 16384};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    std::string text_error, ply_error;
    try {
      write_text_file_atomically(text_path, std::string(100000, 'x'));
    } catch (const ProcessingError &e) {
      text_error = e.what();
    }
    try {
      write_result_ply(ply_path, mesh.view(), std::vector<uint8_t>(4 * n, 9), {{"kd", std::vector<float>(n, 0.5f)}});
    } catch (const ProcessingError &e) {
      ply_error = e.what();
    }
    std::ofstream(result_file) << text_error << "\n" << ply_error << "\n";  // small: under the limit
    ::_exit(0);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "the child was killed by signal " << WTERMSIG(status);
  const std::string errors = read_all(result_file);
  std::istringstream lines(errors);
  std::string text_error, ply_error;
  std::getline(lines, text_error);
  std::getline(lines, ply_error);
  for (const std::string &e : {text_error, ply_error}) {
    EXPECT_NE(e.find("file size limit"), std::string::npos) << e;
    EXPECT_NE(e.find("the previous file is unchanged"), std::string::npos) << e;
  }
  EXPECT_EQ(read_all(text_path), "previous report");
  EXPECT_EQ(read_all(ply_path), "previous ply");
  EXPECT_EQ(remove_stale_temporaries(text_path) + remove_stale_temporaries(ply_path), 0u);  // none left
}
