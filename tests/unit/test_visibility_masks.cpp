// compute_visibility (samples.h): photos taken from the camera of the previous pass share its
// camera pass (an RTI capture: one camera, many lights); each photo still gets its own light pass,
// and the masks are those of a pass per photo.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <vector>

#include "samples/samples.h"
#include "test_scenes.h"
#include "visibility/visibility.h"

namespace vbrdf {
namespace {

// Wraps the CPU ray caster and counts the passes it runs.
class CountingBackend : public VisibilityBackend {
public:
  explicit CountingBackend(const MeshView &mesh) : inner_(make_cpu_visibility(mesh, VisibilitySettings())) {}
  const char *name() const override { return "counting"; }
  void camera_pass(const Shot &shot, uint8_t *out) override {
    ++camera_calls;
    inner_->camera_pass(shot, out);
  }
  void light_pass(const LightSource &light, uint8_t *out, const uint64_t *only) override {
    ++light_calls;
    inner_->light_pass(light, out, only);
  }
  int camera_calls = 0, light_calls = 0;

private:
  std::unique_ptr<VisibilityBackend> inner_;
};

Raster raster_at(const float eye[3]) {
  const float target[3] = {0, 0, 0}, up[3] = {0, 0, -1};
  Raster r;
  r.shot = test::make_look_at_shot(eye, target, up, 300, 320, 240);
  return r;
}

TEST(VisibilityMasks, PhotosOfOneCameraShareItsPass) {
  MeshData m = test::make_grid(30, 1.0f, 0.0f);
  const float c[3] = {0.3f, 0.4f, 0.1f};
  test::append_mesh(m, test::make_sphere(c, 0.25f, 12, 24));  // occludes and shadows the grid
  const float a[3] = {0.2f, 3.0f, 0.4f}, b[3] = {-1.5f, 2.0f, 0.3f};
  // Cameras A A B B A: three camera passes (a pass is shared with the previous photo only).
  const std::vector<Raster> rasters = {raster_at(a), raster_at(a), raster_at(b), raster_at(b), raster_at(a)};
  std::vector<LightSource> lights;
  for (float x : {0.0f, 0.5f, -0.6f, 0.3f, 0.8f}) lights.push_back(LightSource::directional({{x, 1.0f, 0.2f}}));
  CountingBackend shared(m.view());
  const VisibilityMasks masks = compute_visibility(m.view(), rasters, lights, shared);
  EXPECT_EQ(shared.camera_calls, 3);
  EXPECT_EQ(masks.camera_passes, 3u);
  EXPECT_EQ(shared.light_calls, 5);
  // The same masks as one pass per photo (each photo alone).
  const size_t words = masks.words();
  for (size_t r = 0; r < rasters.size(); ++r) {
    CountingBackend single(m.view());
    const VisibilityMasks one = compute_visibility(m.view(), {rasters[r]}, {lights[r]}, single);
    EXPECT_EQ(0, std::memcmp(&masks.seen[r * words], one.seen.data(), words * 8)) << r;
    EXPECT_EQ(0, std::memcmp(&masks.mixed[r * words], one.mixed.data(), words * 8)) << r;
    EXPECT_EQ(0, std::memcmp(&masks.lit[r * words], one.lit.data(), words * 8)) << r;
    EXPECT_EQ(masks.footprints[r], one.footprints[0]) << r;
    EXPECT_EQ(masks.seen_count[r], one.seen_count[0]) << r;
    // Why the others are not seen: counted again or copied with the shared pass's classification.
    EXPECT_EQ(masks.off_image[r], one.off_image[0]) << r;
    EXPECT_EQ(masks.back_facing[r], one.back_facing[0]) << r;
    EXPECT_EQ(masks.occluded[r], one.occluded[0]) << r;
  }
  EXPECT_GT(masks.occluded[0], 0u);  // the sphere hides part of the grid: the codes matter
  EXPECT_GT(masks.seen_count[2], 0u);
}

} // namespace
} // namespace vbrdf
