// Neighbour fill (neighbour_fill.h) and the weak-sample fallback fit (reflectance_fit.h): every seen
// vertex gets a model; unseen ones only on request.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "base/mesh_adjacency.h"
#include "fit/label_spread.h"
#include "fit/neighbour_fill.h"
#include "fit/reflectance_fit.h"
#include "test_scenes.h"
#include "thesis_settings.h"

namespace vbrdf {
namespace {

VertexFit fitted(float r, float g, float b, float ks, float alpha) {
  VertexFit f{};
  f.kd = std::max(r, std::max(g, b));
  f.color[0] = r / f.kd, f.color[1] = g / f.kd, f.color[2] = b / f.kd;
  f.ks = ks, f.shininess = alpha;
  f.status = ks > 0 ? kFitFull : kFitDiffuseOnly;
  return f;
}

// 11 x 11 grid; columns 0..4 fitted with one material, columns 5..10 have no model.
struct Half {
  MeshData mesh = test::make_grid(10, 1.0f, 0.0f);
  std::vector<VertexFit> fits;
  std::vector<uint8_t> seen;
  Half() {
    const size_t n = mesh.positions.size() / 3;
    fits.assign(n, VertexFit{});
    seen.assign(n, 1);
    for (size_t v = 0; v < n; ++v)
      if (column(v) < 5) fits[v] = fitted(0.5f, 0.25f, 0.1f, 0.3f, 40.0f);
  }
  static int column(size_t v) { return int(v % 11); }
};

TEST(NeighbourFill, SeenVerticesTakeTheirNeighboursModel) {
  Half h;
  const NeighbourFillStats s = fill_from_neighbours(h.mesh.view(), h.seen.data(), 0, h.fits.data());
  EXPECT_EQ(s.filled_seen, 6u * 11u);
  EXPECT_EQ(s.filled_unseen, 0u);
  EXPECT_EQ(s.unreachable_seen, 0u);
  EXPECT_EQ(s.rings, 6);  // one ring per pass, columns 5..10
  for (size_t v = 0; v < h.fits.size(); ++v) {
    const VertexFit &f = h.fits[v];
    ASSERT_TRUE(has_model(f)) << v;
    if (Half::column(v) < 5) continue;
    EXPECT_EQ(f.status, kFitFromNeighbours);
    EXPECT_NEAR(f.kd * f.color[0], 0.5f, 1e-5);
    EXPECT_NEAR(f.kd * f.color[1], 0.25f, 1e-5);
    EXPECT_NEAR(f.kd * f.color[2], 0.1f, 1e-5);
    EXPECT_NEAR(f.ks, 0.3f, 1e-5);
    EXPECT_NEAR(f.shininess, 40.0f, 1e-3);
    EXPECT_EQ(f.dq, 0.0f);  // no evidence of its own
    EXPECT_EQ(f.sq, 0.0f);
  }
}

TEST(NeighbourFill, UnseenVerticesOnlyWithinTheRingLimit) {
  Half h;
  for (size_t v = 0; v < h.seen.size(); ++v) h.seen[v] = Half::column(v) < 5;
  std::vector<VertexFit> off = h.fits;
  NeighbourFillStats s = fill_from_neighbours(h.mesh.view(), h.seen.data(), 0, off.data());
  EXPECT_EQ(s.filled_seen + s.filled_unseen, 0u);
  for (size_t v = 0; v < off.size(); ++v) EXPECT_EQ(off[v].status, h.fits[v].status);
  s = fill_from_neighbours(h.mesh.view(), h.seen.data(), 2, h.fits.data());
  EXPECT_EQ(s.filled_unseen, 2u * 11u);  // columns 5 and 6
  for (size_t v = 0; v < h.fits.size(); ++v) EXPECT_EQ(has_model(h.fits[v]), Half::column(v) < 7) << v;
}

TEST(NeighbourFill, MixesNeighboursAndFillsSeparatePiecesFromTheNearest) {
  // Two materials side by side and a separate triangle far away that is seen but has no model.
  Half h;
  for (size_t v = 0; v < h.fits.size(); ++v)
    if (Half::column(v) == 6) h.fits[v] = fitted(0.1f, 0.2f, 0.6f, 0.0f, 0.0f);
  const size_t base = h.mesh.positions.size() / 3;
  h.mesh.positions.insert(h.mesh.positions.end(), {5, 0, 5, 6, 0, 5, 5, 0, 6});
  h.mesh.normals.insert(h.mesh.normals.end(), {0, 1, 0, 0, 1, 0, 0, 1, 0});
  h.mesh.indices.insert(h.mesh.indices.end(), {uint32_t(base), uint32_t(base + 1), uint32_t(base + 2)});
  h.fits.resize(base + 3, VertexFit{});
  h.seen.resize(base + 3, 1);
  const NeighbourFillStats s = fill_from_neighbours(h.mesh.view(), h.seen.data(), 0, h.fits.data());
  EXPECT_EQ(s.unreachable_seen, 0u);
  EXPECT_EQ(s.filled_nearest, 3u);  // the far triangle copies the nearest modelled vertex (corner)
  for (size_t v = 0; v < base; ++v) {
    ASSERT_TRUE(has_model(h.fits[v]));
    const VertexFit &f = h.fits[v];
    for (float c : f.color) EXPECT_TRUE(std::isfinite(c) && c >= 0 && c <= 1);
    if (Half::column(v) == 5) {  // between the two materials: a mix of both
      EXPECT_GT(f.kd * f.color[0], 0.1f + 1e-3f);
      EXPECT_LT(f.kd * f.color[0], 0.5f - 1e-3f);
    }
  }
  const VertexFit &corner = h.fits[10 * 11 + 10];  // grid vertex nearest to (5, 0, 5)
  for (size_t v = base; v < base + 3; ++v) {
    EXPECT_EQ(h.fits[v].status, kFitFromNeighbours);
    EXPECT_EQ(h.fits[v].kd, corner.kd);
  }
  // Nothing modelled anywhere: nothing to copy, every seen vertex stays without a model.
  std::vector<VertexFit> none(h.fits.size(), VertexFit{});
  EXPECT_EQ(fill_from_neighbours(h.mesh.view(), h.seen.data(), 0, none.data()).unreachable_seen, h.fits.size());
}

// Samples of a Lambertian vertex rho = (0.6, 0.4, 0.2).
Sample lambert(float d, uint16_t flags) {
  Sample s{};
  const float rho[3] = {0.6f, 0.4f, 0.2f};
  for (int c = 0; c < 3; ++c) s.rgb[c] = rho[c] * d;
  s.d = d;
  s.lobe_cos = -0.5f;
  s.flags = flags;
  return s;
}

TEST(WeakFit, GrazingOrMixedOnlyVerticesStillGetAModel) {
  std::vector<Sample> grazing;
  for (float d : {0.1f, 0.2f, 0.3f, 0.4f}) grazing.push_back(lambert(d, kGrazing));
  VertexFit strict, weak;
  fit_vertex_cpu(grazing.data(), grazing.size(), vbrdf::test::thesis_fit_options(), strict);
  EXPECT_EQ(strict.status, kFitNone);  // T_d as a wall: no model
  fit_vertex_weak(grazing.data(), grazing.size(), vbrdf::test::thesis_fit_options(), weak);
  ASSERT_EQ(weak.status, kFitFromWeakSamples);
  EXPECT_NEAR(weak.kd * weak.color[0], 0.6f, 0.02f);
  EXPECT_NEAR(weak.kd * weak.color[2], 0.2f, 0.02f);

  std::vector<Sample> mixed;
  for (float d : {0.6f, 0.8f, 1.0f}) mixed.push_back(lambert(d, kMixedPixel));
  fit_vertex_weak(mixed.data(), mixed.size(), vbrdf::test::thesis_fit_options(), weak);
  ASSERT_EQ(weak.status, kFitFromWeakSamples);
  EXPECT_NEAR(weak.kd, 0.6f, 0.02f);

  // Nothing lit or everything clipped: still no model (the neighbour fill takes over).
  std::vector<Sample> dark = {lambert(0.5f, kCastShadow), lambert(0.7f, kSaturated)};
  fit_vertex_weak(dark.data(), dark.size(), vbrdf::test::thesis_fit_options(), weak);
  EXPECT_EQ(weak.status, kFitNone);
  EXPECT_EQ(weak.kd, 0.0f);
}

// The material stage stops spreading labels where no labelled vertex can reach (material_labels.cpp):
// it needs each vertex's connected component.
TEST(MeshAdjacency, ConnectedComponentsNumberedByTheirLowestVertex) {
  MeshData mesh;
  mesh.positions.assign(3 * 8, 0.0f);
  // vertex 0 isolated; 1-2-3 a triangle; 4-5-6 and 5-6-7 two triangles sharing an edge
  mesh.indices = {1, 2, 3, 4, 5, 6, 5, 7, 6};
  uint32_t count = 0;
  const std::vector<uint32_t> comp = connected_components(build_mesh_adjacency(mesh.view()), &count);
  EXPECT_EQ(count, 3u);
  EXPECT_EQ(comp, (std::vector<uint32_t>{0, 1, 1, 1, 2, 2, 2, 2}));
  // and a grid is one component
  const MeshData grid = test::make_grid(4, 1.0f, 0.0f);
  const std::vector<uint32_t> one = connected_components(build_mesh_adjacency(grid.view()), &count);
  EXPECT_EQ(count, 1u);
  EXPECT_TRUE(std::all_of(one.begin(), one.end(), [](uint32_t c) { return c == 0; }));
}

// The material stage's label spreading (label_spread.h). A strip of triangles 0..9 (each vertex
// joined to the next two) and a separate triangle 10-11-12.
TEST(LabelSpread, RingsVoteAndStopOnceTheKeptVerticesAreReached) {
  MeshData mesh;
  mesh.positions.assign(3 * 13, 0.0f);
  for (uint32_t v = 0; v + 2 < 10; ++v) mesh.indices.insert(mesh.indices.end(), {v, v + 1, v + 2});
  mesh.indices.insert(mesh.indices.end(), {10, 11, 12});
  const MeshAdjacency adj = build_mesh_adjacency(mesh.view());
  uint32_t count = 0;
  const std::vector<uint32_t> comp = connected_components(adj, &count);
  ASSERT_EQ(count, 2u);
  // Labels at both ends: the rings meet in the middle, each vertex voting from the ring before it.
  std::vector<int32_t> label(13, 0);
  label[0] = 2, label[9] = 1;
  std::vector<uint8_t> seeded(13, 0), kept(13, 1);
  seeded[0] = seeded[9] = 1;
  SpreadRingCache cache;
  const SpreadRings &rings = cache.rings(adj, seeded, kept, &comp, count);
  EXPECT_EQ(rings.ring_end.size(), 2u);  // {1, 2, 7, 8}, {3, 4, 5, 6}: the unseeded triangle does not hold them up
  EXPECT_EQ(&cache.rings(adj, seeded, kept, &comp, count), &rings);  // the same labelled set: kept, not recomputed
  spread_along_rings(adj, rings, 2, label);
  EXPECT_EQ(label, (std::vector<int32_t>{2, 2, 2, 2, 2, 1, 1, 1, 1, 1, 0, 0, 0}));
  // Only vertices 1 and 2 kept: one ring, the rest of the strip is not walked.
  std::vector<uint8_t> near(13, 0);
  near[1] = near[2] = 1;
  std::vector<uint8_t> one_seed(13, 0);
  one_seed[0] = 1;
  const SpreadRings few = spread_rings(adj, one_seed, near, &comp, count);
  EXPECT_EQ(few.ring_end.size(), 1u);
  EXPECT_EQ(few.vertices, (std::vector<uint32_t>{1, 2}));
}

} // namespace
} // namespace vbrdf
