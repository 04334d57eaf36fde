// The photo's footprint weights over the vertices (samples/footprint_weights.h), the albedo
// deconvolution through them (fit/albedo_deconvolution.h) and the relighting evaluation's
// prediction through them (tools/relight.h RelightOptions::diffuse_deconvolved).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "base/errors.h"
#include "fit/albedo_deconvolution.h"
#include "samples/footprint_weights.h"
#include "test_paths.h"
#include "test_scenes.h"
#include "tools/relight.h"
#include "visibility/visibility.h"
#include "thesis_settings.h"

using namespace vbrdf;

namespace {
// A square grid of n x n cells on y = 0 (half-size 1) seen head-on from 4 units above by a camera
// of `focal_px`: the plane spans 2 / 4 * focal_px pixels, a cell that over n.
struct GridView {
  int n;
  MeshData mesh;
  Raster raster;
  VisibilityMasks masks;
  GridView(int cells, float focal_px) : n(cells), mesh(test::make_grid(cells, 1.0f, 0.0f)) {
    const float eye[3] = {0, 4, 0.01f}, target[3] = {0, 0, 0}, up[3] = {0, 0, -1};
    raster.shot = test::make_look_at_shot(eye, target, up, focal_px, 320, 240);
    raster.label = "view";
    auto visibility = make_cpu_visibility(mesh.view(), VisibilitySettings());
    const std::array<float, 3> light{{0, 1, 0}};
    masks = compute_visibility(mesh.view(), {raster}, {LightSource::directional(light)}, *visibility);
  }
  size_t vertex(int i, int j) const { return size_t(i * (n + 1) + j); }
  size_t vertex_count() const { return mesh.positions.size() / 3; }
  FootprintRows rows() const {
    return footprint_rows(mesh.view(), {raster}, masks, {0}, nullptr, 0.002f * 2.83f);
  }
};

// The weight of the row's own vertex (0 when absent).
float own_weight(const FootprintRows &rows, size_t k) {
  for (uint32_t e = rows.offsets[k]; e < rows.offsets[k + 1]; ++e)
    if (rows.entry_vertex[e] == rows.row_vertex[k]) return rows.entry_weight[e];
  return 0.0f;
}

// Per-vertex albedo with a hard edge along the grid's middle column: `left` for j < n / 2, `right`
// from there on (a step defined at the mesh's resolution, as a per-vertex colour is).
std::vector<float> step_albedo(const GridView &g, const float left[3], const float right[3]) {
  std::vector<float> rgb(3 * g.vertex_count());
  for (int i = 0; i <= g.n; ++i)
    for (int j = 0; j <= g.n; ++j)
      for (int c = 0; c < 3; ++c) rgb[3 * g.vertex(i, j) + size_t(c)] = j < g.n / 2 ? left[c] : right[c];
  return rgb;
}
// What one camera's photos show at each vertex of `g` when its per-vertex albedo is `truth`: the
// truth through the vertex's footprint (one camera: row k is vertex row_vertex[k]'s).
std::vector<float> photographed(const FootprintRows &rows, const std::vector<float> &truth) {
  std::vector<float> blurred(3 * rows.rows()), b(truth);
  blur_through_footprints(rows, truth.data(), blurred.data());
  for (size_t k = 0; k < rows.rows(); ++k)
    for (int c = 0; c < 3; ++c) b[3 * rows.row_vertex[k] + size_t(c)] = blurred[3 * k + size_t(c)];
  return b;
}

// The hard edge of step_albedo between two colours.
const float kLeft[3] = {0.7f, 0.5f, 0.2f}, kRight[3] = {0.1f, 0.2f, 0.4f};
} // namespace

// Every row's weights sum to 1 and lie on the vertices near it; a mesh finer than the pixels
// spreads the sample over many vertices, a coarse one keeps most of it on the vertex itself.
TEST(FootprintWeights, RowsSumToOneAndFollowTheMeshResolution) {
  for (const int cells : {160, 12}) {
    const bool fine = cells > 100;
    const GridView g(cells, 300.0f);  // 150 px across: 0.94 px per cell, or 12.5
    const FootprintRows rows = g.rows();
    ASSERT_GT(rows.rows(), g.vertex_count() / 2) << cells;
    EXPECT_EQ(rows.camera_count, 1u);
    std::vector<float> own;
    for (size_t k = 0; k < rows.rows(); ++k) {
      float sum = 0;
      const float *p = &g.mesh.positions[3 * rows.row_vertex[k]];
      for (uint32_t e = rows.offsets[k]; e < rows.offsets[k + 1]; ++e) {
        sum += rows.entry_weight[e];
        const float *q = &g.mesh.positions[3 * rows.entry_vertex[e]];
        // Within the 1.5-pixel reach of the footprint plus one cell (the covering triangle's corners).
        const float reach = 1.5f * 4.0f / 300.0f + 2.0f / float(cells) * 1.5f;
        EXPECT_LE(std::hypot(q[0] - p[0], q[2] - p[2]), reach) << cells;
      }
      EXPECT_NEAR(sum, 1.0f, 1e-4f);
      EXPECT_FLOAT_EQ(rows.row_share[k], 1.0f);  // one camera
      own.push_back(own_weight(rows, k));
    }
    std::sort(own.begin(), own.end());
    const float median = own[own.size() / 2];
    if (fine)
      EXPECT_LT(median, 0.35f);
    else
      EXPECT_GT(median, 0.8f);
  }
}

// A hard edge in a per-vertex albedo, seen through footprints a little larger than a cell (as on
// bunny_two_materials_dir32): the photos' blend is deconvolved back to the two sides at the edge;
// away from it nothing changes; the result reproduces the photos' samples through the footprints.
TEST(AlbedoDeconvolution, RecoversAHardEdgeAtTheMeshResolution) {
  const GridView g(60, 300.0f);  // 2.5 px per cell
  const FootprintRows rows = g.rows();
  const std::vector<float> truth = step_albedo(g, kLeft, kRight);
  const std::vector<float> b = photographed(rows, truth);
  std::vector<float> x(b.size());
  std::vector<uint8_t> flags(g.vertex_count());
  const DeconvolutionStats stats =
      deconvolve_albedo(rows, g.vertex_count(), b.data(), nullptr, DeconvolutionSettings(), x.data(), flags.data());
  ASSERT_TRUE(stats.solved) << stats.note;
  EXPECT_GT(stats.written, size_t(g.n));  // at least the edge's column
  double err_before = 0, err_after = 0;
  size_t edge = 0;
  for (size_t v = 0; v < g.vertex_count(); ++v) {
    if (!flags[v]) {
      for (int c = 0; c < 3; ++c) EXPECT_EQ(x[3 * v + size_t(c)], b[3 * v + size_t(c)]);  // held exactly
      continue;
    }
    ++edge;
    for (int c = 0; c < 3; ++c) {
      err_before += std::fabs(b[3 * v + size_t(c)] - truth[3 * v + size_t(c)]);
      err_after += std::fabs(x[3 * v + size_t(c)] - truth[3 * v + size_t(c)]);
      EXPECT_TRUE(std::isfinite(x[3 * v + size_t(c)]));
    }
  }
  ASSERT_EQ(edge, stats.written);
  EXPECT_LT(err_after, 0.25 * err_before) << err_before << " -> " << err_after;
  EXPECT_LE(stats.reblur_rms, double(DeconvolutionSettings().misfit_tolerance));
}

// Where the photos' samples are not a blend of the vertices' values (a texture finer than the mesh:
// each vertex shows its own colour, sharp, with a neighbour three pixels away of another), no
// solution within the footprints' range reproduces them: the fit's colours stay.
TEST(AlbedoDeconvolution, KeepsTheFitWhereTheFootprintModelDoesNotHold) {
  const GridView g(60, 300.0f);
  const FootprintRows rows = g.rows();
  const std::vector<float> b = step_albedo(g, kLeft, kRight);  // unblurred: the sample is the vertex's own
  std::vector<float> x(b.size());
  std::vector<uint8_t> flags(g.vertex_count());
  const DeconvolutionStats stats =
      deconvolve_albedo(rows, g.vertex_count(), b.data(), nullptr, DeconvolutionSettings(), x.data(), flags.data());
  EXPECT_GT(stats.edge_vertices, size_t(g.n));
  EXPECT_EQ(stats.written, 0u) << stats.note;
  EXPECT_EQ(x, b);
  EXPECT_EQ(std::count(flags.begin(), flags.end(), uint8_t(1)), 0);
}

// Safeguards: no rows, no edge, or a prior that dominates leave the fit's colours; `write` limits
// the solved vertices.
TEST(AlbedoDeconvolution, LeavesTheFitWithoutRowsEdgesOrWithAStrongPrior) {
  const std::vector<float> b = {0.2f, 0.3f, 0.4f, 0.5f, 0.5f, 0.5f};
  std::vector<float> x(b.size());
  const DeconvolutionStats none = deconvolve_albedo(FootprintRows(), 2, b.data(), nullptr, DeconvolutionSettings(), x.data());
  EXPECT_FALSE(none.solved);
  EXPECT_EQ(x, b);

  const GridView g(60, 300.0f);
  const FootprintRows rows = g.rows();
  const float grey[3] = {0.4f, 0.4f, 0.4f};
  const std::vector<float> flat = step_albedo(g, grey, grey);
  std::vector<float> y(flat.size());
  const DeconvolutionStats no_edge = deconvolve_albedo(rows, g.vertex_count(), flat.data(), nullptr, DeconvolutionSettings(), y.data());
  EXPECT_EQ(no_edge.edge_vertices, 0u);
  EXPECT_EQ(y, flat);

  // A blurred edge with a prior of weight 1e6: the result is the fit's colours (to float rounding).
  const std::vector<float> b2 = photographed(rows, step_albedo(g, kLeft, kRight));
  DeconvolutionSettings strong;
  strong.lambda = 1e9f;  // clamped to 1e6
  std::vector<float> z(b2.size());
  deconvolve_albedo(rows, g.vertex_count(), b2.data(), nullptr, strong, z.data());
  for (size_t i = 0; i < z.size(); ++i) EXPECT_NEAR(z[i], b2[i], 1e-4f);

  // write = 0 everywhere: nothing is solved.
  const std::vector<uint8_t> nowhere(g.vertex_count(), 0);
  std::vector<uint8_t> flags(g.vertex_count(), 1);
  const DeconvolutionStats none_written =
      deconvolve_albedo(rows, g.vertex_count(), b2.data(), nowhere.data(), DeconvolutionSettings(), z.data(), flags.data());
  EXPECT_EQ(none_written.written, 0u);
  EXPECT_EQ(z, b2);
  EXPECT_EQ(std::count(flags.begin(), flags.end(), uint8_t(1)), 0);
}

// A deconvolved result is predicted as the camera records it: a per-vertex checkerboard finer than
// the pixels, photographed as its mean, scores near zero through the footprints and far off at the
// vertices alone.
TEST(Relight, DeconvolvedAlbedoIsPredictedThroughTheFootprint) {
  const GridView g(240, 300.0f);  // 0.63 px per cell
  const float mean[3] = {0.5f, 0.4f, 0.3f};
  cv::Mat img(240, 320, CV_16UC3, cv::Scalar(mean[2] * 65535, mean[1] * 65535, mean[0] * 65535));
  Raster raster = g.raster;
  raster.label = "held_out";
  raster.image_path = test::scratch_dir("deconvolution") + "/held_out.png";
  cv::imwrite(raster.image_path, img);
  std::vector<VertexFit> fits(g.vertex_count());
  for (int i = 0; i <= g.n; ++i)
    for (int j = 0; j <= g.n; ++j) {
      VertexFit &f = fits[g.vertex(i, j)];
      const float scale = (i + j) % 2 ? 1.5f : 0.5f;
      f.kd = mean[0] * scale;
      for (int c = 0; c < 3; ++c) f.color[c] = mean[c] / mean[0];
      f.status = kFitDiffuseOnly;
    }
  const std::array<float, 3> light{{0, 1, 0}};
  auto visibility = make_cpu_visibility(g.mesh.view(), VisibilitySettings());
  RelightOptions at_vertex = vbrdf::test::thesis_relight_options();
  const RelightStats plain =
      evaluate_relighting(g.mesh.view(), fits, {raster}, {LightSource::directional(light)}, *visibility, at_vertex);
  const std::vector<uint8_t> deconvolved(g.vertex_count(), 1);
  RelightOptions through = at_vertex;
  through.diffuse_deconvolved = &deconvolved;
  const RelightStats seen =
      evaluate_relighting(g.mesh.view(), fits, {raster}, {LightSource::directional(light)}, *visibility, through);
  ASSERT_GT(seen.samples, 1000u);
  EXPECT_EQ(seen.samples, plain.samples);
  EXPECT_GT(plain.mean_de2000, 10.0);
  EXPECT_LT(seen.clean_modelled.mean, 1.0);
  // A flag vector of the wrong size is refused.
  const std::vector<uint8_t> short_flags(3, 1);
  through.diffuse_deconvolved = &short_flags;
  EXPECT_THROW(evaluate_relighting(g.mesh.view(), fits, {raster}, {LightSource::directional(light)}, *visibility, through),
               InputError);
}
