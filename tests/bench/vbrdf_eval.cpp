// vbrdf_eval: scores a fit result (the PLY written by the filter) on photos held out from the fit:
// relit CIEDE2000 (mean, median, p95) and PSNR over the seen, lit, unsaturated, clean samples.
//   vbrdf_eval --result fit.ply --project heldout/project.mlp [--lp heldout/lights.lp]
//              [--photo-dir DIR] [--visibility gl|cpu] [--max-mean-de X] [--max-p95-de Y]
// --photo-dir: take each raster's photo (same file name) from DIR instead (e.g. 16-bit linear/).
// Exit status 1 when a bound is exceeded, 2 on bad input.
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "errors.h"
#include "file_util.h"
#include "light_file.h"
#include "osmesa_context.h"
#include "pipeline.h"
#include "project.h"
#include "relight.h"
#include "result_ply.h"
#include "visibility_gl.h"

using namespace vbrdf;

int main(int argc, char **argv) {
  std::string result_path, mlp, lp, photo_dir, backend = "gl";
  double max_mean = -1, max_p95 = -1;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--result") result_path = v;
    else if (a == "--project") mlp = v;
    else if (a == "--lp") lp = v;
    else if (a == "--photo-dir") photo_dir = v;
    else if (a == "--visibility") backend = v;
    else if (a == "--max-mean-de") max_mean = std::stod(v);
    else if (a == "--max-p95-de") max_p95 = std::stod(v);
  }
  if (result_path.empty() || mlp.empty()) {
    std::cerr << "usage: vbrdf_eval --result fit.ply --project heldout/project.mlp [--lp F] [--photo-dir D]\n";
    return 2;
  }
  try {
    const ResultPly result = read_result_ply(result_path);
    const std::vector<VertexFit> fits = fits_from_result(result, result_path);
    Project project = read_project(mlp);
    if (lp.empty()) lp = find_default_light_file(project.project_path, project.rasters.front().image_path);
    const auto lights = resolve_light_directions(project.rasters, lp);
    if (!photo_dir.empty())
      for (Raster &r : project.rasters) r.image_path = join_path(photo_dir, file_name_of(r.image_path));
    std::unique_ptr<test::OsMesaContext> context;
    std::unique_ptr<VisibilityBackend> visibility;
    if (backend == "gl") {
      context.reset(new test::OsMesaContext());
      visibility = make_gl_visibility(result.mesh.view(), context->get_proc_address(), VisibilitySettings());
    } else {
      visibility = make_cpu_visibility(result.mesh.view(), VisibilitySettings());
    }
    const RelightStats s = evaluate_relighting(result.mesh.view(), fits, project.rasters, lights, *visibility, GatherSettings());
    std::printf("relit on %zu held-out photos: %zu samples, CIEDE2000 mean %.3f, median %.3f, p95 %.3f; PSNR %.2f dB\n",
                project.rasters.size(), s.samples, s.mean_de2000, s.median_de2000, s.p95_de2000, s.psnr_db);
    for (size_t r = 0; r < project.rasters.size(); ++r)
      std::printf("  %-32s %7zu samples, mean CIEDE2000 %.3f\n", project.rasters[r].label.c_str(), s.per_raster_samples[r],
                  s.per_raster_mean_de2000[r]);
    bool ok = s.samples > 0;
    if (max_mean >= 0 && s.mean_de2000 > max_mean) ok = false, std::printf("FAIL: mean %.3f > %.3f\n", s.mean_de2000, max_mean);
    if (max_p95 >= 0 && s.p95_de2000 > max_p95) ok = false, std::printf("FAIL: p95 %.3f > %.3f\n", s.p95_de2000, max_p95);
    return ok ? 0 : 1;
  } catch (const InputError &e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception &e) {
    std::cerr << "error: " << e.what() << "\n";
    return 3;
  }
}
