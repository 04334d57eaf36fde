// MeshLab's conventions in the core: only on selection (fit's visibility masks, the
// coverage's vertex mask), vertex quality of unmodelled vertices, attaching a saved result to its
// mesh, and the sphere checks behind vbrdf-lights (a given circle, several highlights).
#include <cmath>
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "tool_errors.h"
#include "base/errors.h"
#include "calibration/sphere_lights.h"
#include "run/coverage_run.h"
#include "run/fit_run.h"
#include "inputs/project.h"
#include "run/fit_outputs.h"
#include "io/result_attach.h"
#include "samples/samples.h"
#include "test_paths.h"
#include "tools/mesh_io.h"

using namespace vbrdf;

namespace {

using test::error_of;

// --- Only on selection ---------------------------------------------------------------------------

TEST(OnlyOnSelection, MaskedVerticesAreNeitherSeenNorLitAndCountsFollow) {
  VisibilityMasks m;
  m.vertex_count = 130;
  m.raster_count = 2;
  m.seen.assign(m.raster_count * m.words(), ~uint64_t(0));
  m.lit = m.seen;
  m.mixed = m.seen;
  m.seen_count = {130, 130};
  std::vector<uint8_t> mask(130, 0);
  for (size_t v = 0; v < 130; v += 3) mask[v] = 1;  // 44 vertices
  restrict_to_vertices(m, mask);
  for (size_t r = 0; r < 2; ++r) {
    EXPECT_EQ(m.seen_count[r], 44u);
    for (size_t v = 0; v < 130; ++v) {
      EXPECT_EQ(m.is_seen(r, v), mask[v] != 0) << v;
      EXPECT_EQ(m.is_lit(r, v), mask[v] != 0) << v;
      EXPECT_EQ(m.is_mixed(r, v), mask[v] != 0) << v;
    }
  }
  EXPECT_NE(error_of([&] { restrict_to_vertices(m, std::vector<uint8_t>(7, 1)); }), "");
  VisibilityMasks untouched = m;
  restrict_to_vertices(untouched, {});  // empty: every vertex stays
  EXPECT_EQ(untouched.seen, m.seen);
}

TEST(OnlyOnSelection, CoverageAsksNothingForVerticesLeftOut) {
  const Project project = read_project(test::source_dir() + "/sample_projects/synth_basic/project.mlp");
  const MeshData mesh = load_mesh_ply(project.mesh_path);
  CoverageInput input;
  input.mesh = mesh.view();
  input.mesh_name = "synth_basic";
  input.rasters = project.rasters;
  input.project_path = project.project_path;
  CoverageSettings s;
  s.write_files = false;
  auto vis = make_cpu_visibility(input.mesh, s.visibility);
  const CoverageResult all = run_coverage(input, s, *vis, {}, [](const std::string &) {});
  const size_t n = mesh.positions.size() / 3;
  input.vertex_mask.assign(n, 0);
  for (size_t v = 0; v < n / 2; ++v) input.vertex_mask[v] = 1;
  const CoverageResult half = run_coverage(input, s, *vis, {}, [](const std::string &) {});
  EXPECT_EQ(all.vertices_considered, n);
  EXPECT_EQ(half.vertices_considered, n / 2);
  size_t counted = 0;
  for (size_t c : half.class_counts) counted += c;
  EXPECT_EQ(counted, n / 2);
  for (uint32_t v : half.new_view_vertices) EXPECT_LT(v, n / 2);  // never a vertex left out
  EXPECT_EQ(half.classes, all.classes);  // classes themselves are the same
  EXPECT_NE(half.report.find("only on selection"), std::string::npos);
}

// --- Quality of unmodelled vertices ------------------------------------------------------------

TEST(Quality, UnmodelledVerticesGetTheMedianNotTheWorst) {
  std::vector<VertexFit> fits(6);
  std::vector<float> q = {1.8f, 0.0f, 1.2f, 0.0f, 1.5f, NAN};
  const uint8_t status[6] = {kFitFull, kFitNone, kFitDiffuseOnly, kFitNone, kFitFull, kFitFull};
  for (size_t v = 0; v < 6; ++v) fits[v].status = status[v];
  neutral_quality_for_unmodelled(fits, q);
  EXPECT_FLOAT_EQ(q[1], 1.5f);  // median of 1.8, 1.2, 1.5
  EXPECT_FLOAT_EQ(q[3], 1.5f);
  EXPECT_FLOAT_EQ(q[5], 1.5f);  // never NaN
  EXPECT_FLOAT_EQ(q[0], 1.8f);  // modelled vertices keep theirs
  std::vector<float> none = {0, 0};
  std::vector<VertexFit> unfitted(2);
  for (VertexFit &f : unfitted) f.status = kFitNone;
  neutral_quality_for_unmodelled(unfitted, none);
  EXPECT_EQ(none, (std::vector<float>{0, 0}));
}

// --- Attaching a result to its mesh ----------------------------------------------------------------

ResultPly result_for(const MeshData &mesh) {
  ResultPly r;
  r.mesh = mesh;
  const size_t n = mesh.positions.size() / 3;
  r.mesh.colors.assign(4 * n, 200);
  for (const char *name : {"kd", "ks", "shininess", "color_r", "color_g", "color_b", "fit_status", "dq", "sq"})
    r.vertex_properties[name] = std::vector<float>(n, 0.0f);
  for (size_t v = 0; v < n; ++v) {
    r.vertex_properties["kd"][v] = 0.1f * float(v);
    r.vertex_properties["fit_status"][v] = v == 0 ? 0.0f : 2.0f;
    r.vertex_properties["dq"][v] = v == 0 ? 0.0f : 1.0f + 0.1f * float(v);
  }
  r.vertex_properties["not_in_schema"] = std::vector<float>(n, 7.0f);
  return r;
}

TEST(AttachResult, AttributesByNameAfterTheVerticesMatch) {
  MeshData mesh;
  mesh.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  mesh.normals.assign(12, 0.0f);
  mesh.indices = {0, 1, 2, 1, 3, 2};
  const ResultPly r = result_for(mesh);
  const AttachedResult a = attach_result(r, mesh.view(), "m", "r.ply", QualityOutput::DQ);
  std::map<std::string, std::vector<float>> got;
  for (const VertexAttribute &attr : a.attributes) got[attr.name] = attr.values;
  EXPECT_EQ(got.count("not_in_schema"), 0u);
  EXPECT_EQ(got["kd"], r.vertex_properties.at("kd"));
  EXPECT_EQ(got["fit_status"], r.vertex_properties.at("fit_status"));
  EXPECT_EQ(a.colors_rgba.size(), 16u);
  ASSERT_EQ(a.quality.size(), 4u);
  EXPECT_FLOAT_EQ(a.quality[0], 1.2f);  // unmodelled: median of 1.1, 1.2, 1.3
  EXPECT_FLOAT_EQ(a.quality[3], 1.3f);
  EXPECT_EQ(a.modelled, 3u);
}

TEST(AttachResult, AnotherMeshIsRefusedNamingFileAndVertex) {
  MeshData mesh;
  mesh.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  mesh.normals.assign(12, 0.0f);
  ResultPly r = result_for(mesh);
  MeshData fewer = mesh;
  fewer.positions.resize(9);
  std::string e = error_of([&] { attach_result(r, fewer.view(), "scan", "fit.ply", QualityOutput::DQ); });
  EXPECT_NE(e.find("fit.ply"), std::string::npos) << e;
  EXPECT_NE(e.find("4 vertices"), std::string::npos) << e;
  EXPECT_NE(e.find("'scan' has 3"), std::string::npos) << e;
  MeshData moved = mesh;
  moved.positions[7] += 0.01f;  // vertex 2, 1 % of the diagonal
  e = error_of([&] { attach_result(r, moved.view(), "scan", "fit.ply", QualityOutput::DQ); });
  EXPECT_NE(e.find("vertex 2"), std::string::npos) << e;
  moved.positions[7] = mesh.positions[7] + 1e-6f;  // float rounding passes
  EXPECT_EQ(error_of([&] { attach_result(r, moved.view(), "scan", "fit.ply", QualityOutput::DQ); }), "");
}

// --- Sphere checks (vbrdf-lights) --------------------------------------------------------------

// A grey sphere (radius r at (cx, cy)) on a dark ground with highlights at the given points.
cv::Mat sphere_photo(double cx, double cy, double r, const std::vector<cv::Point2d> &highlights) {
  cv::Mat img(240, 320, CV_32F, cv::Scalar(0.03));
  cv::circle(img, cv::Point(int(cx), int(cy)), int(r), cv::Scalar(0.25), cv::FILLED, cv::LINE_AA);
  for (const cv::Point2d &h : highlights) cv::circle(img, h, 3, cv::Scalar(1.0), cv::FILLED, cv::LINE_AA);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 0.8);
  return img;
}

TEST(SphereChecks, SeveralHighlightsAreCountedStaticReflectionsAreNot) {
  const SphereCircle c{160, 120, 60};
  EXPECT_EQ(highlight_blobs(sphere_photo(160, 120, 60, {{150, 110}}), c).size(), 1u);
  EXPECT_EQ(highlight_blobs(sphere_photo(160, 120, 60, {{140, 100}, {185, 140}}), c).size(), 2u);
  EXPECT_EQ(highlight_blobs(sphere_photo(160, 120, 60, {}), c).size(), 0u);
  // Six photos: the light's highlight moves, a lamp's reflection stays at (190, 100) in all of
  // them; photo 4 has a second light on.
  std::vector<std::vector<HighlightBlob>> blobs;
  for (int i = 0; i < 6; ++i) {
    std::vector<cv::Point2d> h = {{140 + 6.0 * i, 130 - 4.0 * i}, {190, 100}};
    if (i == 4) h.push_back({150, 150});
    blobs.push_back(highlight_blobs(sphere_photo(160, 120, 60, h), c));
  }
  EXPECT_EQ(moving_highlight_counts(blobs, c.r), (std::vector<int>{1, 1, 1, 1, 2, 1}));
}

TEST(SphereChecks, AGivenCircleMustFitThePhotos) {
  std::vector<cv::Mat> photos;
  for (int i = 0; i < 8; ++i) {
    const double a = 0.8 * i;
    photos.push_back(sphere_photo(160, 70, 45, {{160 + 25 * std::cos(a), 70 + 25 * std::sin(a)}}));
  }
  const GrayLoader load = [&](size_t i) { return photos[i]; };
  const SphereCamera ortho;
  const CircleCheck right = check_sphere_circle(photos.size(), load, ortho, SphereCircle{160, 70, 45});
  EXPECT_TRUE(right.plausible) << right.description;
  EXPECT_EQ(right.spots_inside, photos.size());
  // The same circle with y counted from the bottom edge (240 - 70): no outline, no highlight.
  const CircleCheck flipped = check_sphere_circle(photos.size(), load, ortho, SphereCircle{160, 170, 45});
  EXPECT_FALSE(flipped.plausible) << flipped.description;
  EXPECT_NE(flipped.description.find("NOT this sphere"), std::string::npos) << flipped.description;
}

} // namespace
