// Shading normals refined from the photos (fit/shading_normals.h) and the samples shaded again with
// them (samples/reshade.h): a sphere of known reflectance under 24 lights whose mesh normals are off
// by a few degrees, fitted and refined as the pipeline's chunk consumer does.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "base/mesh_adjacency.h"
#include "base/vec3.h"
#include "fit/reflectance_fit.h"
#include "fit/shading_normals.h"
#include "inputs/camera.h"
#include "samples/reshade.h"
#include "test_scenes.h"
#include "thesis_settings.h"

using namespace vbrdf;

namespace {

// The truth: unit sphere at the origin (normal = position), GGX reflectance, camera on +z.
struct NormalCapture {
  MeshData mesh;                 // the mesh as given: positions exact, normals as set by perturb()
  std::vector<float> truth;      // the surface's normals
  std::vector<Raster> rasters;   // one per light, one camera
  std::vector<LightSource> lights;
  VertexFit model;
  GatherSettings gather = vbrdf::test::thesis_gather_settings();
};

NormalCapture make_capture(size_t light_count = 24) {
  NormalCapture c;
  const float centre[3] = {0, 0, 0}, eye[3] = {0.3f, 0.4f, 4.0f}, up[3] = {0, 1, 0};
  c.mesh = test::make_sphere(centre, 1.0f, 30, 60);
  c.truth = c.mesh.normals;
  const Shot shot = test::make_look_at_shot(eye, centre, up, 600.0f, 640, 480);
  for (size_t k = 0; k < light_count; ++k) {
    const double th = (20.0 + 50.0 * double(k % 3) / 2.0) * kPi / 180, ph = 2 * kPi * double(k) / double(light_count);
    c.lights.push_back(LightSource::directional(
        {float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)), float(std::cos(th))}));
    Raster r;
    r.label = "light_" + std::to_string(k);
    r.shot = shot;
    c.rasters.push_back(r);
  }
  c.model = VertexFit{{1.0f, 0.7f, 0.5f}, 0.6f, 0.4f, 300.0f, 0, 0, 0, 0, kFitFull, 1};  // a glossy lobe: its energy only in the highlights
  c.gather.lobe = LobeForm::GgxNH;
  c.gather.diffuse_threshold = 0.2f;
  return c;
}

// Every mesh normal turned by `degrees` about a random tangent axis (seeded).
void perturb(NormalCapture &c, float degrees) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> angle(0.0f, float(2 * kPi));
  const float t = std::tan(degrees * float(kPi) / 180);
  for (size_t v = 0; v < c.truth.size() / 3; ++v) {
    const float *n = &c.truth[3 * v];
    float a[3] = {std::fabs(n[0]) < 0.9f ? 1.0f : 0.0f, std::fabs(n[0]) < 0.9f ? 0.0f : 1.0f, 0.0f}, t1[3], t2[3];
    cross3(n, a, t1);
    normalize3(t1);
    cross3(n, t1, t2);
    const float phi = angle(rng);
    float *out = &c.mesh.normals[3 * v];
    for (int k = 0; k < 3; ++k) out[k] = n[k] + t * (std::cos(phi) * t1[k] + std::sin(phi) * t2[k]);
    normalize3(out);
  }
}

// The samples of the vertices the camera sees (N.E > 0.3 with the true normal): the photo's colour
// from the true normal, the shading terms from the mesh's, as the gatherer makes them.
SampleChunk gather(const NormalCapture &c) {
  SampleChunk chunk;
  const size_t n = c.truth.size() / 3;
  chunk.first_vertex = 0;
  chunk.vertex_count = uint32_t(n);
  chunk.offsets.push_back(0);
  float centre[3];
  camera_centre(c.rasters[0].shot, centre);
  for (size_t v = 0; v < n; ++v) {
    const float *p = &c.mesh.positions[3 * v];
    float e[3] = {centre[0] - p[0], centre[1] - p[1], centre[2] - p[2]};
    normalize3(e);
    if (dot3(&c.truth[3 * v], e) > 0.3f)
      for (size_t k = 0; k < c.lights.size(); ++k) {
        const float *l = c.lights[k].direction.data();
        Sample truth{}, s{};
        shade_sample(&c.truth[3 * v], l, e, DiffuseForm::Lambert, c.gather, truth);
        evaluate_reflectance(c.model, truth.d, truth.lobe_cos, LobeForm::GgxNH, s.rgb);
        s.raster = uint16_t(k);
        shade_sample(&c.mesh.normals[3 * v], l, e, DiffuseForm::Lambert, c.gather, s);
        if (truth.d <= 0) s.flags |= kCastShadow;  // the surface's own shadow: dark, and the mesh's test says so
        chunk.samples.push_back(s);
      }
    chunk.offsets.push_back(uint32_t(chunk.samples.size()));
  }
  return chunk;
}

ReflectanceFitOptions fit_options() {
  ReflectanceFitOptions o = vbrdf::test::thesis_fit_options();
  o.lobe = LobeForm::GgxNH;
  return o;
}

// Every vertex of the chunk fitted from its samples (CPU reference).
std::vector<VertexFit> fit_all(const SampleChunk &chunk) {
  std::vector<VertexFit> fits(chunk.vertex_count);
  fit_chunk_cpu(chunk, fit_options(), fits.data());
  return fits;
}

// The pipeline's alternation: refine, shade again, fit again (the vertices that moved).
std::vector<float> refine(const NormalCapture &c, SampleChunk &chunk, std::vector<VertexFit> &fits,
                          const ShadingNormalSettings &settings) {
  const MeshView mesh = c.mesh.view();
  const MeshAdjacency adjacency = build_mesh_adjacency(mesh);
  std::vector<float> normals = c.mesh.normals, moved(mesh.vertex_count, -1.0f);
  std::vector<uint8_t> changed(chunk.vertex_count), active;
  for (int round = 0; round < settings.rounds; ++round) {
    refine_shading_normals(chunk, mesh, adjacency, c.rasters, c.lights, DiffuseForms(), LobeForm::GgxNH, fits.data(),
                           settings, round ? active.data() : nullptr, normals.data(), moved.data(), changed.data());
    reshade_chunk(chunk, mesh, normals.data(), changed.data(), c.rasters, c.lights, c.gather);
    fit_chunk_cpu(chunk, fit_options(), fits.data());
    active = changed;
  }
  return normals;
}

// Median and 95th percentile of the angle (degrees) to the truth over the vertices with samples.
std::pair<double, double> angle_to_truth(const NormalCapture &c, const SampleChunk &chunk, const std::vector<float> &n) {
  std::vector<double> a;
  for (size_t v = 0; v < chunk.vertex_count; ++v) {
    if (chunk.offsets[v + 1] == chunk.offsets[v]) continue;
    const double cosine = std::min(1.0f, dot3(&c.truth[3 * v], &n[3 * v]));
    a.push_back(std::acos(cosine) * 180 / kPi);
  }
  std::sort(a.begin(), a.end());
  return {a[a.size() / 2], a[size_t(0.95 * double(a.size() - 1))]};
}
} // namespace

// Shading with the normal the samples were gathered with changes nothing: reshade is make_sample's
// shading, term for term.
TEST(ShadingNormals, ReshadeWithTheSameNormalsChangesNothing) {
  NormalCapture c = make_capture();
  SampleChunk chunk = gather(c);
  const std::vector<Sample> before = chunk.samples;
  std::vector<uint8_t> all(chunk.vertex_count, 1);
  reshade_chunk(chunk, c.mesh.view(), c.mesh.normals.data(), all.data(), c.rasters, c.lights, c.gather);
  ASSERT_EQ(before.size(), chunk.samples.size());
  for (size_t i = 0; i < before.size(); ++i) {
    EXPECT_EQ(before[i].flags, chunk.samples[i].flags) << i;
    EXPECT_NEAR(before[i].d, chunk.samples[i].d, 1e-6) << i;  // the normal is normalised again: an ulp
    EXPECT_NEAR(before[i].lobe_cos, chunk.samples[i].lobe_cos, 1e-6) << i;
  }
}

// Normals 4 degrees off (a smoothed scan): the refined ones are closer to the surface's, in median
// and p95, and the refit reflectance is closer to the truth than the fit with the mesh's normals.
TEST(ShadingNormals, RefinementCorrectsPerturbedNormals) {
  NormalCapture c = make_capture();
  perturb(c, 4.0f);
  SampleChunk chunk = gather(c);
  std::vector<VertexFit> fits = fit_all(chunk);
  double kd_error_before = 0, kd_error_after = 0;
  size_t fitted = 0;
  for (const VertexFit &f : fits)
    if (has_model(f)) kd_error_before += std::fabs(f.kd - c.model.kd), ++fitted;
  ASSERT_GT(fitted, 300u);
  const auto before = angle_to_truth(c, chunk, c.mesh.normals);
  const std::vector<float> refined = refine(c, chunk, fits, ShadingNormalSettings());
  const auto after = angle_to_truth(c, chunk, refined);
  EXPECT_NEAR(before.first, 4.0, 0.01);
  EXPECT_LT(after.first, 0.25 * before.first) << "median angle to the truth";
  EXPECT_LT(after.second, 0.5 * before.second) << "p95 angle to the truth";
  for (const VertexFit &f : fits)
    if (has_model(f)) kd_error_after += std::fabs(f.kd - c.model.kd);
  EXPECT_LT(kd_error_after, 0.5 * kd_error_before);
}

// Exact normals stay where they are (the samples agree with them), and lights all from one side
// leave the normal where the samples cannot tell: the mesh's is kept, not pushed around.
TEST(ShadingNormals, ExactNormalsStayAndUndeterminedOnesKeepTheMesh) {
  NormalCapture c = make_capture();
  SampleChunk chunk = gather(c);
  std::vector<VertexFit> fits = fit_all(chunk);
  const auto exact = angle_to_truth(c, chunk, refine(c, chunk, fits, ShadingNormalSettings()));
  EXPECT_LT(exact.first, 0.25);  // the fitted lobe is not exactly the truth's: a little play
  EXPECT_LT(exact.second, 1.0);

  NormalCapture few = make_capture(3);  // three lights: too few samples for the normal
  perturb(few, 4.0f);
  SampleChunk sparse = gather(few);
  std::vector<VertexFit> sparse_fits = fit_all(sparse);
  const std::vector<float> kept = refine(few, sparse, sparse_fits, ShadingNormalSettings());
  EXPECT_EQ(kept, few.mesh.normals);
}

// One vertex solved on its own (the diffuse form's pilot) is the chunk's solve without the
// neighbour term: the same normals, and closer to the surface's than the perturbed mesh's.
TEST(ShadingNormals, OneVertexSolveIsTheChunkSolveWithoutNeighbours) {
  NormalCapture c = make_capture();
  perturb(c, 4.0f);
  SampleChunk chunk = gather(c);
  std::vector<VertexFit> fits = fit_all(chunk);
  ShadingNormalSettings settings;
  settings.neighbour_sweeps = 0;
  const MeshView mesh = c.mesh.view();
  std::vector<float> chunk_normals = c.mesh.normals, moved(mesh.vertex_count, -1.0f);
  std::vector<uint8_t> changed(chunk.vertex_count);
  refine_shading_normals(chunk, mesh, build_mesh_adjacency(mesh), c.rasters, c.lights, DiffuseForms(), LobeForm::GgxNH,
                         fits.data(), settings, nullptr, chunk_normals.data(), moved.data(), changed.data());
  float centre[3];
  camera_centre(c.rasters[0].shot, centre);
  std::vector<float> centres;
  for (size_t r = 0; r < c.rasters.size(); ++r) centres.insert(centres.end(), centre, centre + 3);
  std::vector<float> one_by_one = c.mesh.normals;
  size_t moved_count = 0;
  for (size_t v = 0; v < chunk.vertex_count; ++v) {
    const uint32_t begin = chunk.offsets[v], end = chunk.offsets[v + 1];
    moved_count += refine_vertex_normal(chunk.samples.data() + begin, end - begin, &c.mesh.positions[3 * v],
                                        &c.mesh.normals[3 * v], centres.data(), c.lights, fits[v],
                                        DiffuseForm::Lambert, LobeForm::GgxNH, settings, &one_by_one[3 * v]);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(one_by_one[3 * v + k], chunk_normals[3 * v + k], 1e-6) << v;
  }
  EXPECT_GT(moved_count, 300u);
  EXPECT_LT(angle_to_truth(c, chunk, one_by_one).first, 0.5 * angle_to_truth(c, chunk, c.mesh.normals).first);
}
