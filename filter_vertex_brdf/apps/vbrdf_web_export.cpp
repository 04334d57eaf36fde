// vbrdf-web-export: a fit result as a GLB and the viewer pages beside it, without MeshLab (the
// installed counterpart of the filter "Vertex BRDF: export for the web"). Run with --help for the
// usage; docs/web.md. The work is the core's (publish/web_export.h); this file only parses,
// reports and writes.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "base/errors.h"
#include "base/number_format.h"
#include "inputs/project.h"
#include "publish/web_export.h"
#include "publish/web_viewer.h"

using namespace vbrdf;

namespace {

const char *const kUsage =
    "usage: vbrdf-web-export RESULT.ply [--project P.mlp] [--lights FILE] [--out MODEL.glb] [--no-viewer]\n"
    "                        [--title TEXT] [--overwrite]\n"
    "\n"
    "Writes the fit result (the PLY written by 'Vertex BRDF: fit per-vertex reflectance' or vbrdf_fit)\n"
    "as a binary glTF 2.0 file that a browser relights with the product's model, and beside it\n"
    "  MODEL.html         the viewer with the GLB embedded: opens from the file system, no server\n"
    "  MODEL_hosted.html  the viewer loading MODEL.glb by URL: put both files on a web server\n"
    "\n"
    "  --out FILE       the GLB to write (default: RESULT without .ply, plus _web.glb)\n"
    "  --project P.mlp  the capture's project: its viewpoints and photo lights go into the GLB\n"
    "  --lights FILE    the light file (.lp, .json, .dome) instead of the project's default one\n"
    "  --no-viewer      write the GLB alone\n"
    "  --title TEXT     the pages' title (default: the GLB's file name)\n"
    "  --overwrite      replace existing files (default: refuse)\n"
    "\n"
    "Exit status 0: written; 1: bad input (the message names the file and the remedy); 2: bad usage.\n";

[[noreturn]] void usage(const std::string &why) {
  std::fprintf(stderr, "vbrdf-web-export: %s\n\n%s", why.c_str(), kUsage);
  std::exit(2);
}

std::string file_name(const std::string &path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

} // namespace

int main(int argc, char **argv) {
  std::string result_path, project_path, lights, out, title;
  bool viewer = true, overwrite = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(a + " needs a value");
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--project") project_path = value();
    else if (a == "--lights") lights = value();
    else if (a == "--out") out = value();
    else if (a == "--title") title = value();
    else if (a == "--no-viewer") viewer = false;
    else if (a == "--overwrite") overwrite = true;
    else if (!a.empty() && a[0] == '-') usage("unknown option '" + a + "'");
    else if (result_path.empty()) result_path = a;
    else usage("one result PLY only ('" + a + "' is a second)");
  }
  if (result_path.empty()) usage("no result PLY given");
  if (!lights.empty() && project_path.empty()) usage("--lights needs --project (the photos the lights belong to)");
  if (out.empty()) {
    out = result_path;
    if (out.size() > 4 && out.compare(out.size() - 4, 4, ".ply") == 0) out.resize(out.size() - 4);
    out += "_web.glb";
  }
  if (title.empty()) title = file_name(web_output_paths(out).glb);
  try {
    const ResultPly result = read_result_ply(result_path);
    WebCapture capture;
    if (!project_path.empty()) {
      const Project project = read_project(project_path);
      capture = web_capture_of(project.rasters, project.project_path, lights, result.mesh.view());
    } else {
      capture.note = "no --project: the GLB has no photo lights or cameras";
    }
    const WebGlb glb = build_web_glb(result, result_path, capture);
    const WebOutputPaths paths =
        write_web_outputs(glb, out, viewer, overwrite ? OverwritePolicy::Replace : OverwritePolicy::Refuse, title);
    std::printf("vbrdf-web-export: %s: %s\n", paths.glb.c_str(), glb.summary().c_str());
    std::printf("  capture: %s%s, %s%s%s\n", counted(capture.lights.size(), "photo light").c_str(),
                capture.light_file.empty() ? "" : (" from " + capture.light_file).c_str(),
                counted(capture.cameras.size(), "viewpoint").c_str(), capture.note.empty() ? "" : "; ", capture.note.c_str());
    if (viewer) std::printf("  viewer: %s (opens from the file system), %s (beside the GLB on a server)\n",
                            paths.html.c_str(), paths.hosted_html.c_str());
    return 0;
  } catch (const InputError &e) {
    std::fprintf(stderr, "vbrdf-web-export: %s\n", e.what());
    return 1;
  } catch (const ProcessingError &e) {
    std::fprintf(stderr, "vbrdf-web-export: %s\n", e.what());
    return 1;
  }
}
