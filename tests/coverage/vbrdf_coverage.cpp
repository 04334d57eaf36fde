// vbrdf_coverage: the coverage filter without MeshLab (GL through OSMesa): classifies every vertex
// of a project, suggests the next diffuse and specular light and writes the suggestion file.
//   vbrdf_coverage project.mlp [--lp F] [--out suggestions.txt] [--fit result.ply]
//                  [--viewpoint-raster N] [--visibility auto|gl|cpu] [--ts X] [--td X]
//                  [--min-elevation DEG] [--poor-dq X] [--poor-sq X] [--classes out.ply]
//                  [--min-diffuse N] [--min-specular N]
// --fit: DQ/SQ of an earlier fit (its result PLY) make vertices with a poor fit count as needing.
// --classes: writes the mesh coloured by class with float properties coverage_class, n_seen,
// n_diffuse, n_specular (for checks and viewing).
// Exit status: 0 success, 2 bad input (message on stderr), 3 processing error.
#include <iostream>
#include <memory>
#include <string>

#include "tool_errors.h"
#include "run/coverage_run.h"
#include "base/errors.h"
#include "tools/mesh_io.h"
#include "osmesa_context.h"
#include "io/output_ply.h"
#include "inputs/project.h"
#include "io/result_ply.h"
#include "thesis_settings.h"

using namespace vbrdf;

namespace {
int usage() {
  std::cerr << "usage: vbrdf_coverage project.mlp [--lp F] [--out F.txt] [--fit result.ply] [--viewpoint-raster N]\n"
               "                      [--visibility auto|gl|cpu] [--ts X] [--td X] [--min-elevation DEG]\n"
               "                      [--poor-dq X] [--poor-sq X] [--classes out.ply] [--min-diffuse N]\n"
               "                      [--min-specular N]\n";
  return 2;
}

void load_fit_quality(const std::string &path, size_t vertices, CoverageInput &input) {
  const ResultPly fit = read_result_ply(path);
  for (const char *name : {"dq", "sq"})
    if (!fit.vertex_properties.count(name))
      throw InputError("Fit result '" + path + "' has no per-vertex '" + name + "': use the PLY written by the fit.");
  if (fit.mesh.positions.size() / 3 != vertices)
    throw InputError("Fit result '" + path + "' has " + std::to_string(fit.mesh.positions.size() / 3) +
                     " vertices but the project's mesh has " + std::to_string(vertices) + ": use a fit of this mesh.");
  input.dq = fit.vertex_properties.at("dq");
  input.sq = fit.vertex_properties.at("sq");
  input.quality_source = path;
}

void write_classes(const std::string &path, const MeshView &mesh, const CoverageResult &r) {
  std::vector<VertexAttribute> attrs = {{"coverage_class", {}}, {"n_seen", {}}, {"n_diffuse", {}}, {"n_specular", {}}};
  for (size_t v = 0; v < mesh.vertex_count; ++v) {
    attrs[0].values.push_back(float(r.classes[v]));
    attrs[1].values.push_back(float(r.counts[v].seen));
    attrs[2].values.push_back(float(r.counts[v].diffuse));
    attrs[3].values.push_back(float(r.counts[v].specular));
  }
  write_result_ply(path, mesh, r.colors_rgba, attrs);
}
} // namespace

int main(int argc, char **argv) {
  if (argc < 2) return usage();
  CoverageSettings settings = vbrdf::test::thesis_coverage_settings();
  std::string mlp, fit_path, classes_path;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
      if (a == "--lp") settings.light_file = next();
      else if (a == "--out") settings.suggestion_file = next();
      else if (a == "--fit") fit_path = next();
      else if (a == "--classes") classes_path = next();
      else if (a == "--viewpoint-raster") settings.viewpoint_raster = std::stoi(next());
      else if (a == "--ts") settings.gather.specular_threshold = std::stof(next());
      else if (a == "--td") settings.gather.diffuse_threshold = std::stof(next());
      else if (a == "--min-elevation") settings.suggest.min_elevation_deg = std::stof(next());
      else if (a == "--poor-dq") settings.poor_dq = std::stof(next());
      else if (a == "--poor-sq") settings.poor_sq = std::stof(next());
      else if (a == "--min-diffuse") settings.min_diffuse = std::stoi(next());
      else if (a == "--min-specular") settings.min_specular = std::stoi(next());
      else if (a == "--visibility") {
        const std::string v = next();
        settings.visibility_choice = v == "gl" ? VisibilityChoice::GL : v == "cpu" ? VisibilityChoice::CPU : VisibilityChoice::Auto;
      } else if (!a.empty() && a[0] == '-') return usage();
      else mlp = a;
    }
  } catch (const std::exception &) {
    return usage();  // a non-numeric value
  }
  if (mlp.empty()) return usage();
  const LogFn log = [](const std::string &line) { std::cout << line << "\n"; };
  return test::run_tool([&]() -> int {
    const Project project = read_project(mlp);
    const MeshData mesh = load_mesh_ply(project.mesh_path);
    CoverageInput input;
    input.mesh = mesh.view();
    input.mesh_name = project.mesh_path;
    input.rasters = project.rasters;
    input.project_path = project.project_path;
    if (!fit_path.empty()) load_fit_quality(fit_path, input.mesh.vertex_count, input);

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
    auto visibility = make_visibility_backend(input.mesh, settings.visibility_choice, settings.visibility, get_proc, log);
    const CoverageResult r = run_coverage(input, settings, *visibility, {}, log);
    if (!classes_path.empty()) write_classes(classes_path, input.mesh, r);
    return 0;
  });
}
