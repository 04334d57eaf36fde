// Lights (light_source.h): the point-light model, the three light-file forms and their refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "base/errors.h"
#include "inputs/light_source.h"
#include "samples/light_check.h"
#include "samples/samples.h"
#include "test_paths.h"
#include "test_scenes.h"

namespace vbrdf {
namespace {

// Two photos of one camera at (0, 0, 5) looking at the origin, y up; mesh: the cube [-1, 1]^3.
struct Capture {
  std::vector<Raster> rasters;
  LightPlacement placement;
  std::string dir = test::scratch_dir("light_source");
  Capture() {
    const float eye[3] = {0, 0, 5}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    for (const char *name : {"a.png", "b.png"}) {
      Raster r;
      r.label = name;
      r.image_path = dir + "/" + name;
      r.shot = test::make_look_at_shot(eye, target, up, 500, 640, 480);
      rasters.push_back(r);
    }
    const float corners[6] = {-1, -1, -1, 1, 1, 1};
    MeshView cube;
    cube.positions = corners;
    cube.vertex_count = 2;
    placement = light_placement_of(cube, 0, 0);
  }
  std::string write(const std::string &name, const std::string &text) const {
    const std::string path = dir + "/" + name;
    std::ofstream(path) << text;
    return path;
  }
};

float dist3(const std::array<float, 3> &a, const std::array<float, 3> &b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

TEST(LightSource, PointLightDirectionAndInverseSquareFallOff) {
  LightSource l;
  l.positional = true;
  l.position = {{0, 4, 0}};
  l.reference_distance = 4;
  l.intensity = 2;
  const float origin[3] = {0, 0, 0}, side[3] = {3, 0, 0}, far_side[3] = {0, -4, 0};
  float d[3];
  light_direction_at(l, side, d);
  EXPECT_NEAR(d[0], -0.6f, 1e-6f);
  EXPECT_NEAR(d[1], 0.8f, 1e-6f);
  EXPECT_NEAR(light_irradiance_at(l, origin), 2.0f, 1e-6f);        // the reference distance
  EXPECT_NEAR(light_irradiance_at(l, side), 2.0f * 16 / 25, 1e-6f);  // distance 5
  EXPECT_NEAR(light_irradiance_at(l, far_side), 0.5f, 1e-6f);       // twice as far: a quarter
  // At the light itself: finite (distance clamped), the stored direction.
  EXPECT_TRUE(std::isfinite(light_irradiance_at(l, l.position.data())));
  light_direction_at(l, l.position.data(), d);
  EXPECT_TRUE(std::isfinite(d[0]) && std::isfinite(d[1]) && std::isfinite(d[2]));
  // A directional light: the same direction and its intensity everywhere.
  const LightSource dir = LightSource::directional({{0, 0, 2}});
  light_direction_at(dir, side, d);
  EXPECT_FLOAT_EQ(d[2], 1.0f);
  EXPECT_FLOAT_EQ(light_irradiance_at(dir, side), 1.0f);
}

TEST(LightSource, JsonPositionsInTheWorldAndCameraFrames) {
  const Capture s;
  const std::string world = s.write("world.json",
                                    "{\"images\": [\"b.png\", \"a.png\"], \"position_world\": [[0, 0, 6], [4, 0, 3]],"
                                    " \"intensity\": [1.0, 2.0]}");
  const std::vector<LightSource> lights = resolve_lights(s.rasters, world, s.placement);
  ASSERT_EQ(lights.size(), 2u);
  EXPECT_TRUE(lights[0].positional);
  EXPECT_LT(dist3(lights[0].position, {{4, 0, 3}}), 1e-5f);  // matched by name, not by order
  EXPECT_LT(dist3(lights[1].position, {{0, 0, 6}}), 1e-5f);
  EXPECT_FLOAT_EQ(lights[0].intensity, 2.0f);
  EXPECT_NEAR(lights[0].direction[0], 0.8f, 1e-5f);  // from the box centre
  // Reference distance: the median distance from the box centre (5 and 6).
  EXPECT_NEAR(lights[0].reference_distance, 6.0f, 1e-5f);
  // The camera frame: x right, y up, z towards the viewer, origin at the camera centre (0, 0, 5).
  const std::string camera = s.write(
      "camera.json", "{\"images\": [\"a.png\", \"b.png\"], \"position_camera\": [[3, 0, 2], [0, 2, 1]]}");
  const std::vector<LightSource> cam = resolve_lights(s.rasters, camera, s.placement);
  EXPECT_LT(dist3(cam[0].position, {{3, 0, 7}}), 1e-4f);
  EXPECT_LT(dist3(cam[1].position, {{0, 2, 6}}), 1e-4f);
  EXPECT_NE(describe_lights(cam, s.placement).find("2 point lights"), std::string::npos);
}

// What the sphere filter writes for triangulated near lights reads back as the same lights.
TEST(LightSource, WrittenPositionsReadBack) {
  const Capture s;
  const std::string path = s.dir + "/written_positions.json";
  write_light_positions(path, {"a.png", "b.png"}, {{{3, 0, 2.5f}}, {{-1, 4, 2}}}, {0.01f, 0.02f});
  const std::vector<LightSource> lights = resolve_lights(s.rasters, path, s.placement);
  EXPECT_LT(dist3(lights[0].position, {{3, 0, 2.5f}}), 1e-5f);
  EXPECT_LT(dist3(lights[1].position, {{-1, 4, 2}}), 1e-5f);
  EXPECT_THROW(write_light_positions(path, {"a.png"}, {{{0, 0, 1}}, {{0, 0, 2}}}), InputError);
  EXPECT_THROW(write_light_positions(path, {"a.png"}, {{{0, 0, std::nanf("")}}}), InputError);
}

TEST(LightSource, RelightDomeFormsAndDomeRadius) {
  Capture s;
  // Relight's frame: origin on the optical axis at the depth of the box centre (the world origin
  // here), x right, y up, z towards the camera; cm times the unit scale. Photos in name order.
  const std::string lights3d = s.write(
      "a.dome", "{\"lightConfiguration\": \"lights3d\", \"positions3d\": [{\"x\": 30, \"y\": 0, \"z\": 20},"
                " {\"x\": 0, \"y\": -20, \"z\": 30}]}");
  EXPECT_THROW(resolve_lights(s.rasters, lights3d, s.placement), InputError);  // cm without a scale
  s.placement.unit_scale = 0.1f;
  const std::vector<LightSource> l3 = resolve_lights(s.rasters, lights3d, s.placement);
  EXPECT_LT(dist3(l3[0].position, {{3, 0, 2}}), 1e-4f);
  EXPECT_LT(dist3(l3[1].position, {{0, -2, 3}}), 1e-4f);
  const std::string spherical = s.write(
      "s.dome", "{\"lightConfiguration\": \"spherical\", \"domeDiameter\": 80, \"verticalOffset\": 0,"
                " \"directions\": [{\"x\": 0, \"y\": 0, \"z\": 1}, {\"x\": 1, \"y\": 0, \"z\": 1}]}");
  const std::vector<LightSource> sp = resolve_lights(s.rasters, spherical, s.placement);
  EXPECT_LT(dist3(sp[0].position, {{0, 0, 4}}), 1e-4f);
  EXPECT_LT(dist3(sp[1].position, {{4 / std::sqrt(2.0f), 0, 4 / std::sqrt(2.0f)}}), 1e-4f);
  const std::string directional = s.write(
      "d.dome", "{\"lightConfiguration\": \"directional\", \"directions\": [{\"x\": 0, \"y\": 0, \"z\": 1},"
                " {\"x\": 0, \"y\": 1, \"z\": 0}]}");
  const std::vector<LightSource> dl = resolve_lights(s.rasters, directional, s.placement);
  EXPECT_FALSE(dl[1].positional);
  EXPECT_NEAR(dl[1].direction[1], 1.0f, 1e-5f);
  // An .lp's directions on a dome of radius 3 around the box centre.
  const std::string lp = s.write("l.lp", "2\na.png 0 0 1\nb.png 1 0 0\n");
  EXPECT_FALSE(resolve_lights(s.rasters, lp, s.placement)[0].positional);
  s.placement.dome_radius = 3;
  const std::vector<LightSource> dome = resolve_lights(s.rasters, lp, s.placement);
  EXPECT_LT(dist3(dome[0].position, {{0, 0, 3}}), 1e-4f);
  EXPECT_LT(dist3(dome[1].position, {{3, 0, 0}}), 1e-4f);
}

TEST(LightSource, RefusesWhatCannotBePlacedWithAMessage) {
  const Capture s;
  const auto expect_message = [&](const std::string &file, const std::string &words) {
    try {
      resolve_lights(s.rasters, file, s.placement);
      ADD_FAILURE() << file << " was accepted";
    } catch (const InputError &e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  expect_message(s.write("inside.json", "{\"images\": [\"a.png\", \"b.png\"], \"position_world\": [[0, 0, 0.5], [0, 0, 6]]}"),
                 "inside the mesh's bounding box");
  expect_message(s.write("near.json", "{\"images\": [\"a.png\", \"b.png\"], \"position_world\": [[0, 0, 1.5], [0, 0, 6]]}"),
                 "nearer than half its diagonal");
  expect_message(s.write("missing.json", "{\"images\": [\"a.png\"], \"position_world\": [[0, 0, 6]]}"), "'b.png'");
  expect_message(s.write("extra.json", "{\"images\": [\"a.png\", \"b.png\", \"c.png\"], \"position_world\": "
                                       "[[0, 0, 6], [0, 0, 7], [0, 0, 8]]}"),
                 "'c.png' matches no raster");
  expect_message(s.write("both.json", "{\"images\": [\"a.png\", \"b.png\"], \"position_world\": [[0, 0, 6], [0, 0, 7]],"
                                      " \"position_camera\": [[0, 0, 6], [0, 0, 7]]}"),
                 "exactly one of");
  expect_message(s.write("count.json", "{\"images\": [\"a.png\", \"b.png\"], \"position_world\": [[0, 0, 6]]}"),
                 "2 images but 1 entries");
  expect_message(s.write("broken.json", "{\"images\": [\"a.png\", "), "not valid JSON");
  expect_message(s.write("one.dome", "{\"lightConfiguration\": \"directional\", \"directions\": [{\"x\": 0, \"y\": 0, \"z\": 1}]}"),
                 "has 1 lights");
}

// The fit sees samples as under unit light: each colour divided by its light's irradiance at the
// vertex, after colour correction; directional lights leave samples untouched.
TEST(LightSource, SamplesAreDividedByTheFallOff) {
  const float positions[6] = {0, 0, 0, 0, -2, 0};
  const float normals[6] = {0, 1, 0, 0, 1, 0};
  MeshView mesh;
  mesh.positions = positions;
  mesh.normals = normals;
  mesh.vertex_count = 2;
  LightSource point;
  point.positional = true;
  point.position = {{0, 2, 0}};
  point.reference_distance = 2;
  const std::vector<LightSource> lights = {point, LightSource::directional({{0, 1, 0}})};
  SampleChunk chunk;
  chunk.first_vertex = 0;
  chunk.vertex_count = 2;
  chunk.offsets = {0, 2, 3};
  chunk.samples = {Sample{{0.5f, 0.5f, 0.5f}, 1, 0, 0, 0}, Sample{{0.5f, 0.5f, 0.5f}, 1, 0, 1, 0},
                   Sample{{0.5f, 0.5f, 0.5f}, 1, 0, 0, 0}};
  apply_light_falloff(chunk, mesh, lights);
  EXPECT_FLOAT_EQ(chunk.samples[0].rgb[0], 0.5f);  // vertex 0 at the reference distance
  EXPECT_FLOAT_EQ(chunk.samples[1].rgb[0], 0.5f);  // directional
  EXPECT_FLOAT_EQ(chunk.samples[2].rgb[0], 2.0f);  // vertex 1 twice as far: a quarter of the light
}

// A light on the wrong side of the object (its brightest predicted vertices are the dark ones in
// the photo) is refused by name; a right light, and a photo with too few samples to tell, pass.
TEST(LightSource, ALightThatContradictsItsPhotoIsRefused) {
  const Capture s;
  std::vector<float> positions, normals;
  const size_t n = 400;
  for (size_t v = 0; v < n; ++v) {
    const float a = float(v) / float(n) * 6.2831853f;
    positions.insert(positions.end(), {std::cos(a), std::sin(a), 0});
    normals.insert(normals.end(), {std::cos(a), std::sin(a), 0});
  }
  MeshView mesh;
  mesh.positions = positions.data();
  mesh.normals = normals.data();
  mesh.vertex_count = n;
  const std::vector<LightSource> lights = {LightSource::directional({{1, 0, 0}}), LightSource::directional({{-1, 0, 0}})};
  // Both photos are lit from +x (brightness = max(n.x, 0) times a varying albedo); raster 1's
  // light file entry says -x.
  SampleChunk chunk;
  chunk.first_vertex = 0;
  chunk.vertex_count = uint32_t(n);
  chunk.offsets.push_back(0);
  for (size_t v = 0; v < n; ++v) {
    const float albedo = 0.3f + 0.4f * float((v * 7) % 10) / 10.0f;
    const float lit = std::max(0.0f, normals[3 * v]) * albedo;
    for (uint16_t r = 0; r < 2; ++r) {
      const float d = normals[3 * v] * lights[r].direction[0];
      chunk.samples.push_back(Sample{{lit, lit, lit}, d, 0, r, uint16_t(d <= 0 ? kAttachedShadow : 0)});
    }
    chunk.offsets.push_back(uint32_t(chunk.samples.size()));
  }
  LightAgreement agreement(2);
  agreement.add(chunk, mesh, lights);
  EXPECT_GT(agreement.correlation(0), 0.5);
  EXPECT_LT(agreement.correlation(1), -0.3);
  try {
    check_light_agreement(agreement, s.rasters, "lights.lp");
    ADD_FAILURE() << "a contradicting light was accepted";
  } catch (const InputError &e) {
    EXPECT_NE(std::string(e.what()).find("'b.png'"), std::string::npos) << e.what();
  }
  LightAgreement few(2);
  SampleChunk small = chunk;
  small.vertex_count = 40;  // 40 samples per photo: too few to judge
  small.offsets.resize(41);
  few.add(small, mesh, lights);
  EXPECT_NO_THROW(check_light_agreement(few, s.rasters, "lights.lp"));
}

} // namespace
} // namespace vbrdf
