// vbrdf_fit: runs the filter's core pipeline on a .mlp without MeshLab (GL through OSMesa).
//   vbrdf_fit project.mlp [--lp lights.lp|.json|.dome] [--dome-radius R] [--light-unit-scale S] [--out result.ply] [--visibility auto|gl|cpu]
//             [--ts 0.9] [--td 0.2] [--encoding auto|srgb|linear] [--shadow-map 2048] [--depth-tests gpu|cpu]
//             [--fit auto|gpu|cpu|off] [--iterations 20] [--alpha0 10] [--min-specular 2]
//             [--photo-dir DIR] [--color-correction off|auto|required] [--materials on|off] [--max-materials 4]
//             [--photo-shadows on|off]
//             [--lobe re|nh|ggx] [--diffuse auto|lambert|coated] [--photo-memory-mb N] [--resolution-weights on|off]
//             [--footprint on|off] [--deconvolve on|off] [--deconvolve-lambda 0.02] [--deconvolve-edge 0.5] [--deconvolve-misfit 0.01]
//             [--registration on|off] [--registration-threshold 0.25] [--registration-residual on|off]
//             [--shading-normals on|off] [--normal-prior DEG] [--normal-neighbours DEG] [--normal-rounds N] [--normal-highlights on|off] [--normal-min-gain G]
//             [--no-remedies]   (thesis behaviour: no highlight weight cap, no prior, k_s free with
//                                one highlight sample; to show the diffuse holes it causes)
// --photo-dir: take each raster's photo (same file name) from DIR instead (e.g. 16-bit linear/).
// Exit status: 0 success, 2 bad input (message on stderr), 3 processing error.
#include <cstdio>
#include <cstring>
#include <iostream>
#include <memory>
#include <string>

#include "tool_errors.h"
#include "base/errors.h"
#include "base/file_util.h"
#include "tools/mesh_io.h"
#include "osmesa_context.h"
#include "run/fit_run.h"
#include "inputs/project.h"

using namespace vbrdf;

namespace {
int usage() {
  std::cerr << "usage: vbrdf_fit project.mlp [--lp F] [--dome-radius R] [--light-unit-scale S] [--out F.ply] [--visibility auto|gl|cpu] [--ts X] [--td X]\n"
               "                 [--encoding auto|srgb|linear] [--shadow-map N] [--camera-divisor D] [--depth-tests gpu|cpu] [--fit auto|gpu|cpu|off]\n"
               "                 [--iterations N] [--alpha0 X] [--min-specular N] [--photo-dir D]\n"
               "                 [--color-correction off|auto|required] [--no-remedies]\n"
               "                 [--materials on|off] [--max-materials N] [--material-lobes-everywhere] [--no-robust-colour]\n"
               "                 [--min-heldout-photos N]\n"
               "                 [--photo-shadows on|off]\n"
               "                 [--lobe re|nh|ggx] [--diffuse auto|lambert|coated] [--photo-memory-mb N] [--resolution-weights on|off]\n"
               "                 [--footprint on|off] [--deconvolve on|off] [--deconvolve-lambda 0.02] [--deconvolve-edge 0.5] [--deconvolve-misfit 0.01]\n"
               "                 [--registration on|off] [--registration-threshold PX]\n"
               "                 [--registration-residual on|off]\n"
               "                 [--shading-normals on|off] [--normal-prior DEG] [--normal-neighbours DEG] [--normal-rounds N] [--normal-highlights on|off] [--normal-min-gain G]\n";
  return 2;
}
} // namespace

int main(int argc, char **argv) {
  if (argc < 2) return usage();
  FitSettings settings;
  std::string mlp, photo_dir;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (a == "--lp") settings.light_file = next();
    else if (a == "--dome-radius") settings.dome_radius = std::stof(next());
    else if (a == "--light-unit-scale") settings.light_unit_scale = std::stof(next());
    else if (a == "--out") settings.output_ply = next();
    else if (a == "--ts") settings.gather.specular_threshold = std::stof(next());
    else if (a == "--td") settings.gather.diffuse_threshold = std::stof(next());
    else if (a == "--shadow-map") settings.visibility.shadow_map_size = std::stoi(next());
    else if (a == "--camera-divisor") settings.visibility.camera_pass_divisor = std::stoi(next());
    else if (a == "--depth-tests") settings.visibility.depth_tests_on_gpu = next() != "cpu";  // gpu (default) | cpu
    else if (a == "--iterations") settings.reflectance.max_iterations = std::stoi(next());
    else if (a == "--alpha0") settings.reflectance.alpha_init = std::stof(next());
    else if (a == "--min-specular") settings.reflectance.min_specular_samples = std::stoi(next());
    else if (a == "--photo-dir") photo_dir = next();
    else if (a == "--materials") settings.materials = next() == "on";
    else if (a == "--photo-shadows") settings.photo_shadows.enabled = next() == "on";
    else if (a == "--photo-memory-mb") settings.gather.photo_cache_bytes = size_t(std::stoull(next())) << 20;
    else if (a == "--lobe") {
      if (!parse_lobe_form(next(), settings.reflectance.lobe)) return usage();
    } else if (a == "--diffuse") {
      const std::string v = next();
      if (v == "auto") settings.diffuse_choice = DiffuseTermChoice::Auto;
      else if (v == "lambert") settings.diffuse_choice = DiffuseTermChoice::Lambert;
      else if (v == "coated") settings.diffuse_choice = DiffuseTermChoice::Coated;
      else return usage();
    } else if (a == "--resolution-weights") settings.gather.resolution_weights = next() == "on";
    else if (a == "--footprint") settings.gather.footprint = next() == "on";
    else if (a == "--deconvolve") settings.deconvolve_albedo = next() == "on";
    else if (a == "--registration") settings.registration.enabled = next() == "on";
    else if (a == "--registration-threshold") settings.registration.threshold_px = std::stof(next());
    else if (a == "--registration-residual") settings.registration_residual.enabled = next() == "on";
    else if (a == "--shading-normals") settings.shading_normals.enabled = next() == "on";
    else if (a == "--normal-prior") settings.shading_normals.mesh_normal_degrees = std::stof(next());
    else if (a == "--normal-neighbours") settings.shading_normals.neighbour_degrees = std::stof(next());
    else if (a == "--normal-rounds") settings.shading_normals.rounds = std::stoi(next());
    else if (a == "--normal-min-gain") settings.shading_normals.min_gain = std::stof(next());
    else if (a == "--normal-highlights") settings.shading_normals.use_highlights = next() == "on";
    else if (a == "--deconvolve-lambda") settings.deconvolution.lambda = std::stof(next());
    else if (a == "--deconvolve-edge") settings.deconvolution.edge_contrast = std::stof(next());
    else if (a == "--deconvolve-misfit") settings.deconvolution.misfit_tolerance = std::stof(next());
    else if (a == "--material-lobes-everywhere") settings.material_options.keep_full_fits = false;
    else if (a == "--no-robust-colour") settings.material_options.robust_colour = false;
    else if (a == "--max-materials") settings.material_options.max_materials = std::stoi(next());
    else if (a == "--min-heldout-photos") settings.material_options.min_heldout_photos = size_t(std::stoul(next()));
    else if (a == "--color-correction") {
      const std::string v = next();
      if (v == "off") settings.color_correction = ColorCorrectionChoice::Off;
      else if (v == "auto") settings.color_correction = ColorCorrectionChoice::Auto;
      else if (v == "required") settings.color_correction = ColorCorrectionChoice::Required;
      else return usage();
    }
    else if (a == "--no-remedies") {
      settings.reflectance.specular_weight_cap = 1e30f;
      settings.reflectance.diffuse_prior = 0;
      settings.reflectance.min_specular_samples = 1;
      settings.reflectance.min_lobe_samples = 1 << 30;
    }
    else if (a == "--fit") {
      const std::string v = next();
      settings.fit_reflectance = v != "off";
      settings.fit_backend = v == "gpu" ? FitBackendChoice::GPU : v == "cpu" ? FitBackendChoice::CPU : FitBackendChoice::Auto;
    }
    else if (a == "--visibility") {
      const std::string v = next();
      settings.visibility_choice = v == "gl" ? VisibilityChoice::GL : v == "cpu" ? VisibilityChoice::CPU : VisibilityChoice::Auto;
    } else if (a == "--encoding") {
      const std::string v = next();
      settings.gather.encoding = v == "srgb" ? PhotoEncoding::SRGB : v == "linear" ? PhotoEncoding::Linear : PhotoEncoding::Auto;
    } else if (!a.empty() && a[0] == '-') return usage();
    else mlp = a;
  }
  const LogFn log = [](const std::string &line) { std::cout << line << "\n"; };
  return test::run_tool([&]() -> int {
    const Project project = read_project(mlp);
    const MeshData mesh = load_mesh_ply(project.mesh_path);
    FitInput input;
    input.mesh = mesh.view();
    input.mesh_name = project.mesh_path;
    input.mesh_path = project.mesh_path;
    input.mesh_colors = mesh.colors;
    input.rasters = project.rasters;
    if (!photo_dir.empty())
      for (Raster &r : input.rasters) r.image_path = join_path(photo_dir, file_name_of(r.image_path));
    input.project_path = project.project_path;
    validate_input(input);

    std::unique_ptr<test::OsMesaContext> gl;
    std::function<void *(const char *)> get_proc;
    if (settings.visibility_choice != VisibilityChoice::CPU || settings.fit_backend != FitBackendChoice::CPU) {
      try {
        gl.reset(new test::OsMesaContext());
        get_proc = gl->get_proc_address();
      } catch (const std::exception &e) {
        log(std::string("OSMesa context unavailable: ") + e.what());
      }
    }
    auto visibility = make_visibility_backend(input.mesh, settings.visibility_choice, settings.visibility, get_proc, log);
    std::unique_ptr<ReflectanceFitter> fitter;
    if (settings.fit_reflectance)
      fitter = make_reflectance_fitter(settings.fit_backend, get_proc, log);
    run_fit(input, settings, *visibility, fitter.get(), {}, log);
    return 0;
  });
}
