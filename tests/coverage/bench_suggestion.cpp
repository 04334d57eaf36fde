// bench_suggestion: time of the next-light step of run_coverage against the number of vertices
// (everything after the samples: classes, needs with the prediction failures of the photos taken,
// the diffuse and the specular suggestion learning from those photos, the vertices that need a new
// viewpoint), on a bumpy sphere seen by one camera with `--photos` lights already taken.
//   bench_suggestion [--max-vertices 2000000] [--photos 12] [--shadowed-above 0.5] [--csv out.csv]
// --shadowed-above Y: vertices above height Y never get a sample (as if in cast shadow), so that
// the predictions of every photo fail there (the learning suggestions' worst case: lower Y).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "run/coverage_run.h"
#include "test_scenes.h"

using namespace vbrdf;

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Counts as if `lights` had been photographed: covered where predicted, except a band of vertices
// (y > shadowed_above) in "cast shadow" for every light, so that the predictions there fail.
std::vector<CoverageCounts> simulated_counts(const MeshData &m, const Shot &shot,
                                             const std::vector<std::array<float, 3>> &lights, float shadowed_above,
                                             std::vector<uint8_t> &visible) {
  const size_t n = m.positions.size() / 3;
  std::vector<CoverageCounts> counts(n);
  visible.assign(n, 0);
  float c[3];
  camera_centre(shot, c);
  const LightSuggestionSettings s;
  for (size_t v = 0; v < n; ++v) {
    const float *p = &m.positions[3 * v], *nrm = &m.normals[3 * v];
    float e[3] = {c[0] - p[0], c[1] - p[1], c[2] - p[2]};
    const float l = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    for (float &x : e) x /= l;
    if (nrm[0] * e[0] + nrm[1] * e[1] + nrm[2] * e[2] <= 0.05f) continue;
    visible[v] = 1;
    counts[v].seen = uint16_t(lights.size());
    if (p[1] > shadowed_above) continue;  // shadowed band
    for (const auto &light : lights) {
      counts[v].diffuse += light_covers_diffuse(nrm, e, light.data(), s);
      counts[v].specular += light_covers_specular(nrm, e, light.data(), s);
    }
  }
  return counts;
}
} // namespace

int main(int argc, char **argv) {
  size_t max_vertices = 2000000;
  int photos = 12;
  float shadowed_above = 0.5f;
  std::string csv;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--max-vertices") max_vertices = std::stoul(argv[i + 1]);
    if (a == "--photos") photos = std::stoi(argv[i + 1]);
    if (a == "--csv") csv = argv[i + 1];
    if (a == "--shadowed-above") shadowed_above = std::stof(argv[i + 1]);
  }
  const float eye[3] = {0, 0, 6}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
  Viewpoint vp;
  vp.shot = test::make_look_at_shot(eye, target, up, 1200, 1024, 768);
  std::vector<std::array<float, 3>> lights;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0, 1);
  for (int i = 0; i < photos; ++i) {
    const float z = 0.2f + 0.75f * u(rng), az = 6.2831853f * u(rng), r = std::sqrt(1 - z * z);
    const float cam[3] = {r * std::cos(az), r * std::sin(az), z};
    std::array<float, 3> w;
    camera_to_world_direction(vp.shot, cam, w.data());
    lights.push_back(w);
    vp.rasters.push_back(size_t(i));
  }
  std::FILE *out = csv.empty() ? nullptr : std::fopen(csv.c_str(), "w");
  if (out) std::fprintf(out, "vertices,photos,needs_s,diffuse_s,specular_s,new_view_s,total_s,plain_diffuse_s,plain_specular_s\n");
  std::printf("%10s %7s %9s %9s %9s %9s %9s | %9s %9s\n", "vertices", "photos", "needs", "diffuse", "specular",
              "new view", "total", "plain d", "plain s");
  CoverageSettings settings;
  for (size_t n = 10000; n <= max_vertices; n = n < max_vertices && n * 10 > max_vertices ? max_vertices : n * 10) {
    const MeshData mesh = test::make_bumpy_sphere(n);
    const MeshView view = mesh.view();
    std::vector<uint8_t> visible;
    const std::vector<CoverageCounts> counts = simulated_counts(mesh, vp.shot, lights, shadowed_above, visible);
    std::vector<uint8_t> classes(counts.size());
    for (size_t v = 0; v < counts.size(); ++v) classes[v] = classify_coverage(counts[v]);

    auto t = Clock::now();
    std::vector<uint16_t> fd, fs;
    prediction_failures(view, classes, vp, directional_lights(lights), settings.suggest, fd, fs);
    const CoverageNeeds needs = coverage_needs(counts, nullptr, nullptr, settings, fd.data(), fs.data());
    const double t_needs = since(t);
    t = Clock::now();
    const LightSuggestion d = suggest_light_learning(view, vp.shot, visible.data(), needs.diffuse.data(),
                                                     CoverageKind::Diffuse, settings.suggest, 0, lights);
    const double t_d = since(t);
    t = Clock::now();
    const LightSuggestion s = suggest_light_learning(view, vp.shot, visible.data(), needs.specular.data(),
                                                     CoverageKind::Specular, settings.suggest, 0, lights);
    const double t_s = since(t);
    t = Clock::now();
    const std::vector<uint8_t> reasons = new_view_reasons(view, classes, {visible}, {vp}, settings.suggest);
    const double t_nv = since(t);
    t = Clock::now();
    suggest_next_light(view, vp.shot, visible.data(), needs.diffuse.data(), CoverageKind::Diffuse, settings.suggest);
    const double t_pd = since(t);
    t = Clock::now();
    suggest_next_light(view, vp.shot, visible.data(), needs.specular.data(), CoverageKind::Specular, settings.suggest);
    const double t_ps = since(t);
    const double total = t_needs + t_d + t_s + t_nv;
    std::printf("%10zu %7d %9.3f %9.3f %9.3f %9.3f %9.3f | %9.3f %9.3f   (diffuse covers %zu/%zu, specular %zu/%zu)\n",
                view.vertex_count, photos, t_needs, t_d, t_s, t_nv, total, t_pd, t_ps, d.covered_vertices,
                d.needing_vertices, s.covered_vertices, s.needing_vertices);
    if (out)
      std::fprintf(out, "%zu,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n", view.vertex_count, photos, t_needs, t_d, t_s, t_nv,
                   total, t_pd, t_ps);
    if (n == max_vertices) break;
  }
  if (out) std::fclose(out);
  return 0;
}
