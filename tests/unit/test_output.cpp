// Output PLY: header with named per-vertex properties, values, atomic write, NaN refusal; output
// files that survive faults (base/output_file.h).
#include <cmath>
#include <csignal>
#include <functional>
#include <cstring>
#include <fstream>
#include <gtest/gtest.h>
#include <sstream>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "base/errors.h"
#include "base/file_util.h"
#include "base/output_file.h"
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
} // namespace

TEST(OutputPly, HeaderAndValuesReadBack) {
  const MeshData mesh = test::make_grid(2, 1.0f, 0.0f);  // 9 vertices
  const size_t n = mesh.positions.size() / 3;
  std::vector<uint8_t> colors(4 * n, 200);
  std::vector<VertexAttribute> attrs = {{"diffuse_r", std::vector<float>(n)}, {"n_visible", std::vector<float>(n)}};
  for (size_t v = 0; v < n; ++v) attrs[0].values[v] = 0.1f * float(v), attrs[1].values[v] = float(v % 3);
  const std::string path = test::scratch_dir("ply") + "/out.ply";
  write_result_ply(path, mesh.view(), colors, attrs);
  const std::string data = read_all(path);
  const size_t header_end = data.find("end_header\n");
  ASSERT_NE(header_end, std::string::npos);
  const std::string header = data.substr(0, header_end);
  EXPECT_NE(header.find("format binary_little_endian 1.0"), std::string::npos);
  EXPECT_NE(header.find("element vertex 9"), std::string::npos);
  EXPECT_NE(header.find("property float diffuse_r"), std::string::npos);
  EXPECT_NE(header.find("property float n_visible"), std::string::npos);
  EXPECT_NE(header.find("property uchar red"), std::string::npos);
  // Vertex record layout: x y z nx ny nz (6 floats), red green blue alpha (4 uchar), then our floats.
  const char *rec = data.data() + header_end + strlen("end_header\n");
  const size_t stride = 6 * 4 + 4 + 2 * 4;
  for (size_t v = 0; v < n; ++v) {
    float value, count;
    std::memcpy(&value, rec + v * stride + 28, 4);
    std::memcpy(&count, rec + v * stride + 32, 4);
    EXPECT_FLOAT_EQ(value, 0.1f * float(v));
    EXPECT_FLOAT_EQ(count, float(v % 3));
    EXPECT_EQ(uint8_t(rec[v * stride + 24]), 200);
  }
}

TEST(OutputPly, RefusesNaNAndLeavesNoFileBehind) {
  const MeshData mesh = test::make_grid(1, 1.0f, 0.0f);
  const size_t n = mesh.positions.size() / 3;
  std::vector<VertexAttribute> attrs = {{"kd", std::vector<float>(n, 0.5f)}};
  attrs[0].values[2] = std::nanf("");
  const std::string dir = test::scratch_dir("ply_nan");
  EXPECT_THROW(write_result_ply(dir + "/out.ply", mesh.view(), std::vector<uint8_t>(4 * n, 0), attrs), ProcessingError);
  EXPECT_FALSE(file_exists(dir + "/out.ply"));
  // Unwritable destination: clear error, no partial file.
  EXPECT_THROW(write_result_ply("/nonexistent_dir/out.ply", mesh.view(), std::vector<uint8_t>(4 * n, 0), {}),
               ProcessingError);
}

TEST(OutputPly, RepeatedExportsInOneProcessStayCorrect) {
  // vcglib's PlyInfo::AddPerVertexFloatAttribute caches the first PlyInfo's vectors in statics:
  // a second export then corrupts memory. Several exports in a row must all read back.
  const MeshData mesh = test::make_grid(2, 1.0f, 0.0f);
  const size_t n = mesh.positions.size() / 3;
  for (int run = 0; run < 4; ++run) {
    std::vector<VertexAttribute> attrs = {{"a" + std::to_string(run), std::vector<float>(n, float(run))},
                                          {"b", std::vector<float>(n, 2.0f * float(run))}};
    const std::string path = test::scratch_dir("ply_repeat") + "/out.ply";
    write_result_ply(path, mesh.view(), std::vector<uint8_t>(4 * n, 1), attrs);
    const std::string data = read_all(path);
    EXPECT_NE(data.find("property float a" + std::to_string(run) + "\n"), std::string::npos) << run;
    EXPECT_NE(data.find("property float b\n"), std::string::npos) << run;
    EXPECT_EQ(data.find("property float a" + std::to_string(run - 1) + "\n"), std::string::npos) << run;
  }
}

namespace {
// Output files, nothing lost: overwrite policy, stale temporaries of killed runs, a
// file size limit (as a full disk) and a short temporary become errors with the previous file intact.
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
