// bench_coverage: time of one next-light suggestion (diffuse and specular) against the number of
// vertices, on a bumpy sphere seen by one camera. Prints a table; --csv FILE writes it too.
//   bench_coverage [--max-vertices 2000000] [--csv out.csv]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "coverage/coverage.h"
#include "test_scenes.h"

using namespace vbrdf;

int main(int argc, char **argv) {
  size_t max_vertices = 2000000;
  std::string csv;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--max-vertices") max_vertices = std::stoul(argv[i + 1]);
    if (a == "--csv") csv = argv[i + 1];
  }
  const float eye[3] = {0, 0, 6}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
  const Shot shot = test::make_look_at_shot(eye, target, up, 1200, 1024, 768);
  const LightSuggestionSettings s;
  std::FILE *out = csv.empty() ? nullptr : std::fopen(csv.c_str(), "w");
  if (out) std::fprintf(out, "vertices,kind,seconds,covered,needing\n");
  std::printf("%10s %9s %9s %9s %9s\n", "vertices", "kind", "seconds", "covered", "needing");
  for (size_t n = 10000; n <= max_vertices; n = n < max_vertices && n * 10 > max_vertices ? max_vertices : n * 10) {
    const MeshData mesh = test::make_bumpy_sphere(n);
    const size_t nv = mesh.positions.size() / 3;
    std::vector<uint8_t> visible(nv);
    for (size_t v = 0; v < nv; ++v) visible[v] = mesh.positions[3 * v + 2] > 0;
    std::vector<float> needs(nv, 1.0f);
    for (CoverageKind kind : {CoverageKind::Diffuse, CoverageKind::Specular}) {
      const auto t0 = std::chrono::steady_clock::now();
      const LightSuggestion sg = suggest_next_light(mesh.view(), shot, visible.data(), needs.data(), kind, s);
      const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const char *name = kind == CoverageKind::Diffuse ? "diffuse" : "specular";
      std::printf("%10zu %9s %9.3f %9zu %9zu\n", nv, name, sec, sg.covered_vertices, sg.needing_vertices);
      if (out) std::fprintf(out, "%zu,%s,%.4f,%zu,%zu\n", nv, name, sec, sg.covered_vertices, sg.needing_vertices);
    }
    if (n == max_vertices) break;
  }
  if (out) std::fclose(out);
  return 0;
}
