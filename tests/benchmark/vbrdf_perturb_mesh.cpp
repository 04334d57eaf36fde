// A copy of a mesh as a scan gives it, for the imperfect-capture benchmark (imperfect_captures.py):
//   vbrdf_perturb_mesh in.ply out.ply [--smooth-normals ROUNDS] [--target-median DEG] [--decimate F]
// --smooth-normals: ROUNDS rounds of 1-ring averaging of the vertex normals (each normal replaced by
// the normalised sum of its own and its neighbours'), positions unchanged: a scanned mesh's normals
// are smoother than the surface's. --target-median: as many rounds (at least ROUNDS, at most 100) as
// it takes to move the normals by DEG degrees median (a fine mesh needs more rounds than a coarse
// one for the same smoothing). --decimate: the mesh decimated to F times its vertices (vcglib's
// quadric edge collapse, as MeshLab's filter), then every original vertex moved to the closest point
// of the decimated surface with the normal interpolated there: the original vertices and faces (so
// per-vertex ground truth still applies) with the geometry of a scan half as fine. Decimation comes
// before smoothing. Prints how far the normals moved (median and p95 degrees) and, with --decimate,
// the positions (median and p95, in thousandths of the bounding-box diagonal).
// The input is only read; the output may not be the input.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "base/errors.h"
#include "base/mesh_adjacency.h"
#include "base/vec3.h"
#include "bench_mesh.h"
#include "fit/shading_normals.h"  // summarise_moved
#include "io/output_ply.h"
#include "tools/mesh_io.h"

using namespace vbrdf;

namespace {
void smooth_normals(const MeshAdjacency &adj, int rounds, std::vector<float> &normals) {
  const size_t n = adj.vertex_count();
  for (int r = 0; r < rounds; ++r) {
    std::vector<float> next(normals);
    for (size_t v = 0; v < n; ++v) {
      float *out = &next[3 * v];
      for (uint32_t a = adj.offsets[v]; a < adj.offsets[v + 1]; ++a)
        for (int k = 0; k < 3; ++k) out[k] += normals[3 * adj.neighbours[a] + size_t(k)];
      normalize3(out);
    }
    normals.swap(next);
  }
}

} // namespace

int main(int argc, char **argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: vbrdf_perturb_mesh in.ply out.ply [--smooth-normals ROUNDS]\n");
    return 2;
  }
  const std::string in = argv[1], out = argv[2];
  int rounds = 0;
  float target_median = 0, decimate = 0;
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--smooth-normals" && i + 1 < argc) rounds = std::atoi(argv[++i]);
    else if (a == "--target-median" && i + 1 < argc) target_median = float(std::atof(argv[++i]));
    else if (a == "--decimate" && i + 1 < argc) decimate = float(std::atof(argv[++i]));
    else {
      std::fprintf(stderr, "vbrdf_perturb_mesh: unknown option '%s'\n", a.c_str());
      return 2;
    }
  }
  if (decimate < 0 || decimate >= 1) {
    std::fprintf(stderr, "vbrdf_perturb_mesh: --decimate takes a fraction of the vertices in (0, 1)\n");
    return 2;
  }
  if (in == out) {
    std::fprintf(stderr, "vbrdf_perturb_mesh: the output would overwrite the input\n");
    return 2;
  }
  try {
    MeshData mesh = load_mesh_ply(in, true);
    const std::vector<float> original = mesh.normals;
    const MeshAdjacency adjacency = build_mesh_adjacency(mesh.view());
    const auto moved = [&]() {
      std::vector<float> angles;
      for (size_t v = 0; v < original.size() / 3; ++v) {
        const float c = dot3(&original[3 * v], &mesh.normals[3 * v]);
        angles.push_back(float(std::acos(std::fmax(-1.0f, std::fmin(1.0f, c))) * 180.0 / kPi));
      }
      return angles;
    };
    if (decimate > 0) {
      const size_t vertices = mesh.positions.size() / 3;
      const MeshData coarse = bench::decimate(mesh, size_t(double(decimate) * double(vertices)));
      const std::vector<float> shift = bench::resample_onto(coarse, mesh);
      const float diagonal = compute_bounds(mesh.view()).diagonal();
      std::vector<float> permille;
      for (float d : shift) permille.push_back(1000.0f * d / std::fmax(diagonal, 1e-20f));
      const MovedSummary p = summarise_moved(permille);
      std::printf("decimated to %zu of %zu vertices; positions moved: median %.3f, p95 %.3f per mille of the diagonal\n",
                  coarse.positions.size() / 3, vertices, p.median, p.p95);
    }
    smooth_normals(adjacency, rounds, mesh.normals);
    std::vector<float> angles = moved();
    while (target_median > 0 && summarise_moved(angles).median < target_median && rounds < 100) {
      smooth_normals(adjacency, 1, mesh.normals);
      ++rounds;
      angles = moved();
    }
    std::vector<uint8_t> colors = mesh.colors;
    if (colors.size() != 4 * (mesh.positions.size() / 3)) colors.assign(4 * (mesh.positions.size() / 3), 255);
    write_result_ply(out, mesh.view(), colors, {});
    const MovedSummary moved_by = summarise_moved(angles);
    std::printf("normals moved: median %.2f deg, p95 %.2f deg (%d rounds of 1-ring averaging)\n", moved_by.median,
                moved_by.p95, rounds);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "vbrdf_perturb_mesh: %s\n", e.what());
    return 1;
  }
  return 0;
}
