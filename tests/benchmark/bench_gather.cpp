// bench_gather: time of sample gathering (visibility depth passes + pixel samples + diffuse
// colour) on a project, for the GL back end (OSMesa llvmpipe) and the CPU ray caster, using the
// first P photos. Prints one CSV line per run:
//   backend,vertices,photos,width,height,visibility_s,gather_s,total_s,samples
//   bench_gather project.mlp [--backend gl|gl-readback|cpu|both|all] [--photos 4,8,16,32] [--csv-header] [--passes]
//                [--shadow-map N] [--camera-divisor D]   (0 = automatic, the default: visibility/pass_size.h)
// gl: depth tests in a compute shader (the fit's default); gl-readback: depth maps read back and tested
// on the CPU; both = gl and cpu; all = the three.
// --passes: instead, the time of one camera pass (the first raster's camera, photo size) and one
// light pass (its light; the sizes the fit uses unless set), measured on the second call of each
// (render targets exist), after the back end's setup (upload / grid); camera_map is the camera
// pass's map (WxH), shadow_map the light pass's side (0 for the CPU):
//   passes,backend,vertices,width,height,camera_map,shadow_map,setup_s,camera_pass_s,light_pass_s
// (The GL visibility unit tests check these passes for correctness only: timing a shared test
// machine makes a flaky test, so the figures live here.)
#include <chrono>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "samples/diffuse_color.h"
#include "inputs/light_file.h"
#include "tools/mesh_io.h"
#include "osmesa_context.h"
#include "run/fit_run.h"
#include "inputs/project.h"
#include "visibility/visibility_gl.h"
#include "thesis_settings.h"

using namespace vbrdf;

namespace {
double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

std::vector<int> parse_list(const std::string &s) {
  std::vector<int> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');) out.push_back(std::stoi(item));
  return out;
}
// Back ends: "gl" (depth tests in a compute shader where the context has one), "gl-readback" (the
// depth maps read back and tested on the CPU), "cpu" (the ray caster).
const char *const kBackends[] = {"gl", "gl-readback", "cpu"};

bool wanted(const std::string &asked, const std::string &backend) {
  return asked == backend || asked == "all" || (asked == "both" && backend != "gl-readback");
}

VisibilitySettings g_settings;  // automatic pass sizes, as the fit, unless set on the command line

std::unique_ptr<VisibilityBackend> make_backend(const std::string &backend, const MeshData &mesh,
                                                test::OsMesaContext &context) {
  VisibilitySettings settings = g_settings;
  settings.depth_tests_on_gpu = backend != "gl-readback";
  return backend == "cpu" ? make_cpu_visibility(mesh.view(), settings)
                          : make_gl_visibility(mesh.view(), context.get_proc_address(), settings);
}

// One camera and one light pass, timed on their second call (see the header).
void time_passes(const std::string &backend, const MeshData &mesh, const Raster &raster, const LightSource &light,
                 test::OsMesaContext &context) {
  const double t0 = now();
  auto vis = make_backend(backend, mesh, context);
  const double setup = now() - t0;
  std::vector<uint8_t> out(mesh.positions.size() / 3);
  vis->camera_pass(raster.shot, out.data());
  vis->light_pass(light, out.data());
  const double t1 = now();
  vis->camera_pass(raster.shot, out.data());
  const double t2 = now();
  vis->light_pass(light, out.data());
  const double t3 = now();
  const VisibilityBackend::PassSizes sizes = vis->last_pass_sizes();
  std::printf("passes,%s,%zu,%d,%d,%dx%d,%d,%.3f,%.3f,%.3f\n", backend.c_str(), mesh.positions.size() / 3, raster.width(),
              raster.height(), sizes.camera_width, sizes.camera_height, sizes.shadow_map, setup, t2 - t1, t3 - t2);
  std::fflush(stdout);
}

} // namespace

int main(int argc, char **argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_gather project.mlp [--backend gl|gl-readback|cpu|both|all] [--photos 4,8,16,32] [--csv-header] "
                         "[--passes] [--shadow-map N] [--camera-divisor D]\n");
    return 2;
  }
  std::string backend = "both";
  std::vector<int> photo_counts;
  bool header = false, passes = false;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--backend" && i + 1 < argc) backend = argv[++i];
    else if (a == "--photos" && i + 1 < argc) photo_counts = parse_list(argv[++i]);
    else if (a == "--csv-header") header = true;
    else if (a == "--passes") passes = true;
    else if (a == "--shadow-map" && i + 1 < argc) g_settings.shadow_map_size = std::stoi(argv[++i]);
    else if (a == "--camera-divisor" && i + 1 < argc) g_settings.camera_pass_divisor = std::stoi(argv[++i]);
  }
  const Project project = read_project(argv[1]);
  const MeshData mesh = load_mesh_ply(project.mesh_path);
  const auto all_lights =
      resolve_lights(project.rasters, find_default_light_file(project.rasters, project.project_path), LightPlacement());
  if (photo_counts.empty()) photo_counts.push_back(int(project.rasters.size()));
  test::OsMesaContext context;
  if (passes) {
    if (header) std::printf("passes,backend,vertices,width,height,camera_map,shadow_map,setup_s,camera_pass_s,light_pass_s\n");
    for (const std::string b : kBackends)
      if (wanted(backend, b)) time_passes(b, mesh, project.rasters.at(0), all_lights.at(0), context);
    return 0;
  }
  if (header) std::printf("backend,vertices,photos,width,height,visibility_s,gather_s,total_s,samples\n");
  for (const std::string b : kBackends) {
    if (!wanted(backend, b)) continue;
    for (int count : photo_counts) {
      const size_t p = std::min(size_t(count), project.rasters.size());
      std::vector<Raster> rasters(project.rasters.begin(), project.rasters.begin() + long(p));
      std::vector<LightSource> lights(all_lights.begin(), all_lights.begin() + long(p));
      const double t0 = now();
      auto vis = make_backend(b, mesh, context);
      const VisibilityMasks masks = compute_visibility(mesh.view(), rasters, lights, *vis);
      const double t1 = now();
      GatherSettings gs = vbrdf::test::thesis_gather_settings();
      PhotoCache cache(gs.encoding, gs.saturation_level, gs.photo_cache_bytes);
      std::vector<DiffuseEstimate> est(mesh.positions.size() / 3);
      const GatherStats stats = gather_samples(mesh.view(), rasters, lights, masks, gs, cache, [&](const SampleChunk &c) {
        estimate_diffuse_chunk(c, &est[c.first_vertex]);
      });
      const double t2 = now();
      std::printf("%s,%zu,%zu,%d,%d,%.3f,%.3f,%.3f,%llu\n", b.c_str(), mesh.positions.size() / 3, p, rasters[0].width(),
                  rasters[0].height(), t1 - t0, t2 - t1, t2 - t0, (unsigned long long)stats.stored);
      std::fflush(stdout);
    }
  }
  return 0;
}
