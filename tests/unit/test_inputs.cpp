// Inputs: .lp light files, .mlp projects, shot projection conventions.
#include <fstream>
#include <gtest/gtest.h>

#include "tool_errors.h"
#include "inputs/camera.h"
#include "base/errors.h"
#include "base/file_util.h"
#include "inputs/light_file.h"
#include "run/fit_run.h"
#include "inputs/project.h"
#include "test_paths.h"
#include "test_scenes.h"

using namespace vbrdf;

namespace {
std::string write_file(const std::string &dir, const std::string &name, const std::string &text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

using test::error_of;
} // namespace

TEST(LightFile, ParsesNamesWithSpacesAndNormalises) {
  const std::string dir = test::scratch_dir("lp");
  const auto path = write_file(dir, "a.lp", "2\nimages/photo 1.jpg 0 0 2\n\nimg2.png 0.6 0 0.8\n");
  const auto lights = read_light_file(path);
  ASSERT_EQ(lights.size(), 2u);
  EXPECT_EQ(lights[0].image, "images/photo 1.jpg");
  EXPECT_FLOAT_EQ(lights[0].dir_cam[2], 1.0f);
  EXPECT_EQ(lights[1].image, "img2.png");
  EXPECT_NEAR(lights[1].dir_cam[0], 0.6f, 1e-6f);
}

TEST(LightFile, CountMismatchAndBadValuesNameFileAndLine) {
  const std::string dir = test::scratch_dir("lp_bad");
  const auto fewer = write_file(dir, "fewer.lp", "3\na.png 0 0 1\nb.png 0 1 0\n");
  EXPECT_NE(error_of([&] { read_light_file(fewer); }).find("says 3 lights but 2"), std::string::npos);
  const auto more = write_file(dir, "more.lp", "1\na.png 0 0 1\nb.png 0 1 0\n");
  EXPECT_NE(error_of([&] { read_light_file(more); }).find("line 3"), std::string::npos);
  const auto nan = write_file(dir, "nan.lp", "1\na.png 0 x 1\n");
  const std::string msg = error_of([&] { read_light_file(nan); });
  EXPECT_NE(msg.find("nan.lp"), std::string::npos);
  EXPECT_NE(msg.find("'x' is not a number"), std::string::npos);
  const auto zero = write_file(dir, "zero.lp", "1\na.png 0 0 0\n");
  EXPECT_NE(error_of([&] { read_light_file(zero); }).find("zero length"), std::string::npos);
  EXPECT_NE(error_of([&] { read_light_file(dir + "/missing.lp"); }).find("Cannot open"), std::string::npos);
}

TEST(LightFile, RoundTripAndMatchingByFileName) {
  const std::string dir = test::scratch_dir("lp_rt");
  std::vector<LightEntry> lights = {{"images/L_000.png", {0.1f, 0.2f, 0.9746794f}}, {"images/L_001.png", {0, 1, 0}}};
  write_light_file(dir + "/out.lp", lights);
  const auto back = read_light_file(dir + "/out.lp");
  ASSERT_EQ(back.size(), 2u);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(back[0].dir_cam[k], lights[0].dir_cam[k], 1e-6f);
  EXPECT_EQ(find_light_for_image(back, "/abs/path/to/L_001.png"), 1);
  EXPECT_EQ(find_light_for_image(back, "/x/l_000.PNG"), 0);  // case-insensitive fallback
  EXPECT_EQ(find_light_for_image(back, "/x/other.png"), -1);
  Raster a, b;
  a.label = "a", a.image_path = "/elsewhere/images/L_000.png";
  b.label = "b", b.image_path = "/elsewhere/images/L_001.png";
  EXPECT_EQ(find_default_light_file({a, b}, dir + "/project.mlp"), dir + "/out.lp");
  b.image_path = "/elsewhere/images/L_002.png";  // no entry for it: the file does not qualify
  EXPECT_EQ(find_default_light_file({a, b}, dir + "/project.mlp"), "");
}

TEST(Shot, PixelOriginIsTopLeftWithYDown) {
  // Camera on +z looking at the origin, y up. A point above the axis must land in the upper
  // half of the image (smaller image y); a point to the right at larger x.
  const float c[3] = {0, 0, 10}, t[3] = {0, 0, 0}, up[3] = {0, 1, 0};
  const Shot shot = test::make_look_at_shot(c, t, up, 500, 640, 480);
  const float centre[3] = {0, 0, 0}, above[3] = {0, 1, 0}, right[3] = {1, 0, 0}, behind[3] = {0, 0, 20};
  ImagePoint p = project_to_image(shot, centre);
  EXPECT_NEAR(p.x, 320, 1e-3);
  EXPECT_NEAR(p.y, 240, 1e-3);
  EXPECT_TRUE(p.in_front);
  p = project_to_image(shot, above);
  EXPECT_NEAR(p.x, 320, 1e-3);
  EXPECT_NEAR(p.y, 240 - 50, 1e-3);  // focal 500 px, 1 unit at distance 10
  p = project_to_image(shot, right);
  EXPECT_NEAR(p.x, 320 + 50, 1e-3);
  EXPECT_FALSE(project_to_image(shot, behind).in_front);
  EXPECT_NEAR(view_depth(shot, above), 10, 1e-4);
}

TEST(Shot, GlMatricesReproduceShotProjection) {
  const float c[3] = {3, 2, 7}, t[3] = {0.2f, -0.1f, 0}, up[3] = {0, 1, 0};
  const Shot shot = test::make_look_at_shot(c, t, up, 800, 1024, 768, 530.5f, 370.25f);
  float view[16], proj[16];
  gl_view_matrix(shot, view);
  gl_projection_matrix(shot, 1.0f, 20.0f, proj);
  const float pts[3][3] = {{0, 0, 0}, {0.5f, 0.3f, -0.4f}, {-0.7f, 0.1f, 0.9f}};
  for (const auto &p : pts) {
    float eye[4] = {0, 0, 0, 0}, clip[4] = {0, 0, 0, 0};
    const float hp[4] = {p[0], p[1], p[2], 1};
    for (int r = 0; r < 4; ++r)
      for (int k = 0; k < 4; ++k) eye[r] += view[k * 4 + r] * hp[k];
    for (int r = 0; r < 4; ++r)
      for (int k = 0; k < 4; ++k) clip[r] += proj[k * 4 + r] * eye[k];
    // Window coordinates (GL: origin bottom-left) -> image pixels (top-left, y down).
    const float wx = (clip[0] / clip[3] * 0.5f + 0.5f) * 1024, wy = (clip[1] / clip[3] * 0.5f + 0.5f) * 768;
    const ImagePoint ip = project_to_image(shot, p);
    EXPECT_NEAR(wx, ip.x, 1e-2);
    EXPECT_NEAR(768 - wy, ip.y, 1e-2);
    EXPECT_NEAR(-eye[2], view_depth(shot, p), 1e-4);
  }
}

TEST(Shot, CameraFrameDirectionsFollowRtiConvention) {
  const float c[3] = {0, 0, 10}, t[3] = {0, 0, 0}, up[3] = {0, 1, 0};
  const Shot shot = test::make_look_at_shot(c, t, up, 500, 640, 480);
  const float towards_camera[3] = {0, 0, 1}, right[3] = {1, 0, 0};
  float w[3];
  camera_to_world_direction(shot, towards_camera, w);
  EXPECT_NEAR(w[2], 1, 1e-6);  // camera sits on +z
  camera_to_world_direction(shot, right, w);
  EXPECT_NEAR(w[0], 1, 1e-6);
  float back[3];
  world_to_camera_direction(shot, w, back);
  EXPECT_NEAR(back[0], 1, 1e-6);
}

TEST(Project, ReadsSharedSceneLikeMeshLab) {
  VBRDF_REQUIRE_SHARED("scenes/spot_dir24/project.mlp");
  const std::string mlp = test::shared_dir() + "/scenes/spot_dir24/project.mlp";
  const Project p = read_project(mlp);
  EXPECT_TRUE(file_exists(p.mesh_path));
  ASSERT_EQ(p.rasters.size(), 24u);
  for (const Raster &r : p.rasters) {
    EXPECT_TRUE(shot_is_valid(r.shot)) << r.label;
    EXPECT_TRUE(file_exists(r.image_path)) << r.image_path;
    EXPECT_EQ(r.width(), 640);
    EXPECT_EQ(r.height(), 480);
  }
  // Every raster's light from the scene's own .lp resolves, in world coordinates.
  const auto dirs = resolve_lights(p.rasters, test::shared_dir() + "/scenes/spot_dir24/lights.lp", LightPlacement());
  ASSERT_EQ(dirs.size(), 24u);
}

TEST(Project, RasterWithoutCameraIsRejectedByName) {
  const std::string dir = test::scratch_dir("mlp");
  const auto path = write_file(dir, "p.mlp",
                               "<!DOCTYPE MeshLabDocument>\n<MeshLabProject><MeshGroup><MLMesh label=\"m\" filename=\"m.ply\"/>"
                               "</MeshGroup><RasterGroup><MLRaster label=\"photo_07\"><Plane semantic=\"1\" fileName=\"a.png\"/>"
                               "<VCGCamera FocalMm=\"10\"/></MLRaster></RasterGroup></MeshLabProject>\n");
  const std::string msg = error_of([&] { read_project(path); });
  EXPECT_NE(msg.find("photo_07"), std::string::npos) << msg;
  EXPECT_NE(msg.find("first child"), std::string::npos) << msg;
}
