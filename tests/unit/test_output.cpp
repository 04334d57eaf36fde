// Output PLY: header with named per-vertex properties, values, atomic write, NaN refusal.
#include <cmath>
#include <cstring>
#include <fstream>
#include <gtest/gtest.h>
#include <sstream>

#include "base/errors.h"
#include "base/file_util.h"
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
