// vbrdf_fit: runs the filter's core pipeline on a .mlp without MeshLab (GL through OSMesa).
//   vbrdf_fit project.mlp [--lp lights.lp] [--out result.ply] [--visibility auto|gl|cpu]
//             [--ts 0.9] [--td 0.5] [--encoding auto|srgb|linear] [--shadow-map 2048]
// Exit status: 0 success, 2 bad input (message on stderr), 3 processing error.
#include <cstdio>
#include <cstring>
#include <iostream>
#include <memory>
#include <string>

#include "errors.h"
#include "mesh_io.h"
#include "osmesa_context.h"
#include "pipeline.h"
#include "project.h"

using namespace vbrdf;

namespace {
int usage() {
  std::cerr << "usage: vbrdf_fit project.mlp [--lp F] [--out F.ply] [--visibility auto|gl|cpu] [--ts X] [--td X]\n"
               "                 [--encoding auto|srgb|linear] [--shadow-map N]\n";
  return 2;
}
} // namespace

int main(int argc, char **argv) {
  if (argc < 2) return usage();
  FitSettings settings;
  std::string mlp;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (a == "--lp") settings.light_file = next();
    else if (a == "--out") settings.output_ply = next();
    else if (a == "--ts") settings.gather.specular_threshold = std::stof(next());
    else if (a == "--td") settings.gather.diffuse_threshold = std::stof(next());
    else if (a == "--shadow-map") settings.visibility.shadow_map_size = std::stoi(next());
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
  try {
    const Project project = read_project(mlp);
    const MeshData mesh = load_mesh_ply(project.mesh_path);
    FitInput input;
    input.mesh = mesh.view();
    input.mesh_name = project.mesh_path;
    input.mesh_path = project.mesh_path;
    input.mesh_colors = mesh.colors;
    input.rasters = project.rasters;
    input.project_path = project.project_path;
    validate_input(input);

    std::unique_ptr<test::OsMesaContext> gl;
    std::function<void *(const char *)> get_proc;
    if (settings.visibility_choice != VisibilityChoice::CPU) {
      try {
        gl.reset(new test::OsMesaContext());
        get_proc = gl->get_proc_address();
      } catch (const std::exception &e) {
        log(std::string("OSMesa context unavailable: ") + e.what());
      }
    }
    auto visibility = make_visibility_backend(input.mesh, settings, get_proc, log);
    run_fit(input, settings, *visibility, {}, log);
    return 0;
  } catch (const InputError &e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception &e) {
    std::cerr << "error: " << e.what() << "\n";
    return 3;
  }
}
