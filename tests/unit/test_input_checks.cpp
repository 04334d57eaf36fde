// Bad and odd inputs caught before any work: photo contents (black, saturated,
// identical), light files with a byte-order mark, CRLF line ends or a photo listed twice, the mesh
// file's normals, an identity camera.
#include <fstream>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "base/errors.h"
#include "inputs/camera.h"
#include "inputs/light_file.h"
#include "inputs/mesh_file.h"
#include "inputs/photo_content.h"
#include "test_paths.h"

using namespace vbrdf;

namespace {
std::string write_file(const std::string &dir, const std::string &name, const std::string &text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::string input_error(const std::function<void()> &f) {
  try {
    f();
  } catch (const InputError &e) {
    return e.what();
  }
  return "";
}

Photo photo_of(const cv::Mat &bgr, const std::string &name) {
  const std::string path = test::scratch_dir("content") + "/" + name;
  cv::imwrite(path, bgr);
  return load_photo(path, PhotoEncoding::Auto);
}

std::vector<Raster> rasters(size_t n) {
  std::vector<Raster> r(n);
  for (size_t i = 0; i < n; ++i) r[i].label = "photo_" + std::to_string(i), r[i].image_path = "/p/" + r[i].label + ".png";
  return r;
}

cv::Mat gradient(int seed) {
  cv::Mat m(40, 60, CV_8UC3);
  for (int y = 0; y < m.rows; ++y)
    for (int x = 0; x < m.cols; ++x) m.at<cv::Vec3b>(y, x) = cv::Vec3b(uchar(x * 3 + seed), uchar(y * 5), uchar(100 + seed));
  return m;
}
} // namespace

TEST(PhotoContent, DarkSaturatedAndFingerprint) {
  const PhotoContent black = analyse_photo(photo_of(cv::Mat::zeros(40, 60, CV_8UC3), "black.png"));
  EXPECT_DOUBLE_EQ(black.dark_fraction, 1.0);
  EXPECT_DOUBLE_EQ(black.saturated_fraction, 0.0);
  const PhotoContent white = analyse_photo(photo_of(cv::Mat(40, 60, CV_8UC3, cv::Scalar::all(255)), "white.png"));
  EXPECT_DOUBLE_EQ(white.saturated_fraction, 1.0);
  const PhotoContent a = analyse_photo(photo_of(gradient(1), "a.png")), a2 = analyse_photo(photo_of(gradient(1), "a2.png"));
  const PhotoContent b = analyse_photo(photo_of(gradient(2), "b.png"));
  EXPECT_EQ(a.fingerprint, a2.fingerprint);
  EXPECT_NE(a.fingerprint, b.fingerprint);
  EXPECT_LT(a.dark_fraction, 0.01);
  // 16-bit: the same rules on the wider codes.
  const PhotoContent black16 = analyse_photo(photo_of(cv::Mat(40, 60, CV_16UC3, cv::Scalar::all(50)), "black16.png"));
  EXPECT_DOUBLE_EQ(black16.dark_fraction, 1.0);  // 50 / 65535 < 0.2 %
}

TEST(PhotoContent, AllUselessIsRefusedSomeAreWarned) {
  PhotoContent black, white, good1, good2;
  black.dark_fraction = 1, black.fingerprint = 1;
  white.saturated_fraction = 1, white.fingerprint = 2;
  good1.fingerprint = 3, good2.fingerprint = 4;
  const auto r = rasters(3);
  std::string e = input_error([&] { check_photo_contents(r, {black, black, black}); });
  EXPECT_NE(e.find("Every photo is black"), std::string::npos) << e;
  EXPECT_NE(e.find("photo_0"), std::string::npos) << e;
  e = input_error([&] { check_photo_contents(r, {white, white, white}); });
  EXPECT_NE(e.find("Every photo is saturated"), std::string::npos) << e;
  e = input_error([&] { check_photo_contents(r, {good1, good1, good1}); });
  EXPECT_NE(e.find("All 3 photos are identical"), std::string::npos) << e;

  const std::vector<std::string> w = check_photo_contents(r, {good1, black, good2});
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].rfind("WARNING: raster 'photo_1'", 0), 0u) << w[0];
  EXPECT_NE(w[0].find("is black"), std::string::npos);
  const std::vector<std::string> dup = check_photo_contents(r, {good1, good2, good1});
  ASSERT_EQ(dup.size(), 1u);
  EXPECT_NE(dup[0].find("'photo_0', 'photo_2' are identical"), std::string::npos) << dup[0];
  EXPECT_TRUE(check_photo_contents(r, {good1, good2, white}).size() == 1);
  EXPECT_TRUE(check_photo_contents(rasters(1), {good1}).empty());  // one photo: nothing to compare
}

TEST(LightFile, ByteOrderMarkCrlfAndRepeatedEntries) {
  const std::string dir = test::scratch_dir("lp_odd");
  const auto bom = read_light_file(write_file(dir, "bom.lp", "\xEF\xBB\xBF" "2\r\na.png 0 0 1\r\nb.png 0 1 0\r\n"));
  ASSERT_EQ(bom.size(), 2u);
  EXPECT_EQ(bom[1].image, "b.png");  // no '\r' kept in the name
  EXPECT_FLOAT_EQ(bom[1].dir_cam[1], 1.0f);
  // Listed twice with the same direction: accepted; with another: refused, naming both lines.
  EXPECT_EQ(read_light_file(write_file(dir, "same.lp", "2\na.png 0 0 1\na.png 0 0 2\n")).size(), 2u);
  const std::string e = input_error([&] { read_light_file(write_file(dir, "twice.lp", "3\na.png 0 0 1\nb.png 0 1 0\na.png 1 0 0\n")); });
  EXPECT_NE(e.find("line 4"), std::string::npos) << e;
  EXPECT_NE(e.find("'a.png' is listed again (first on line 2)"), std::string::npos) << e;
}

TEST(MeshFile, NormalsStoredOrNot) {
  const std::string dir = test::scratch_dir("mesh_normals");
  const std::string head = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n";
  const auto with = write_file(dir, "with.ply", head + "property float nx\nproperty float ny\nproperty float nz\n"
                                                      "element face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0 1\n");
  const auto without = write_file(dir, "without.ply", head + "element face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n");
  // "nx" of another element does not count.
  const auto other = write_file(dir, "other.ply", head + "element face 0\nproperty float nx\nend_header\n0 0 0\n");
  EXPECT_EQ(normals_in_mesh_file(with), FileNormals::Present);
  EXPECT_EQ(normals_in_mesh_file(without), FileNormals::Absent);
  EXPECT_EQ(normals_in_mesh_file(other), FileNormals::Absent);
  EXPECT_EQ(normals_in_mesh_file(write_file(dir, "m.obj", "v 0 0 0\nvn 0 0 1\n")), FileNormals::Present);
  EXPECT_EQ(normals_in_mesh_file(write_file(dir, "n.obj", "v 0 0 0\n")), FileNormals::Absent);
  EXPECT_EQ(normals_in_mesh_file(dir + "/missing.ply"), FileNormals::Unknown);
  EXPECT_NE(describe_normals_source(without).find("MeshLab computed them when loading it"), std::string::npos);
}

TEST(Shot, IdentityPoseIsNotARegistration) {
  Shot s;
  s.Intrinsics.FocalMm = 50, s.Intrinsics.PixelSizeMm = vcg::Point2f(0.01f, 0.01f);
  s.Intrinsics.ViewportPx = vcg::Point2i(100, 100), s.Intrinsics.CenterPx = vcg::Point2f(50, 50);
  s.Extrinsics.SetIdentity();
  EXPECT_TRUE(shot_is_valid(s));
  EXPECT_TRUE(shot_is_identity(s));
  s.Extrinsics.SetTra(vcg::Point3f(0, 0, 1e-4f));
  EXPECT_FALSE(shot_is_identity(s));
}
