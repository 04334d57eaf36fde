// Frame time of the live view (core/relight/live_relight.h, the render plugin "Vertex BRDF:
// relight") on a large mesh, through OSMesa (here: llvmpipe on the machine's cores).
//
//   bench_live_relight [--vertices N] [--width W] [--height H] [--frames F]
//
// A bumpy unit sphere of about N vertices (default 1,000,000) with varying per-vertex fits fills
// most of a W x H view (default 862 x 920, MeshLab's 3-D view in the GUI tests' 1280 x 1024
// window); the light moves every frame. Reports the upload time and, per display mode, the
// median and worst time of F frames (draw + glFinish, no read-back).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <vector>

#include "osmesa_context.h"
#include "relight/live_relight.h"
#include "test_scenes.h"

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int run(int argc, char **argv) {
  size_t vertices = 1000000;
  int width = 862, height = 920, frames = 10;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--vertices")) vertices = size_t(std::atol(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--width")) width = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--height")) height = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--frames")) frames = std::atoi(argv[i + 1]);
    else {
      std::fprintf(stderr, "unknown option %s\n", argv[i]);
      return 2;
    }
  }
  const vbrdf::MeshData mesh = vbrdf::test::make_bumpy_sphere(vertices);
  const size_t n = mesh.positions.size() / 3;
  std::vector<vbrdf::VertexFit> fits(n);
  for (size_t v = 0; v < n; ++v) {
    vbrdf::VertexFit &f = fits[v];
    const float *p = &mesh.positions[3 * v];
    f.color[0] = 1.0f, f.color[1] = 0.6f + 0.3f * p[0], f.color[2] = 0.4f + 0.2f * p[1];
    f.kd = 0.5f;
    f.ks = v % 5 == 0 ? 0.0f : 0.3f;
    f.shininess = f.ks > 0 ? 20.0f + 10.0f * p[2] : 0.0f;
    f.status = f.ks > 0 ? vbrdf::kFitFull : vbrdf::kFitDiffuseOnly;
    f.dq = 1.0f + p[0], f.sq = 1.0f + p[1];
  }
  vbrdf::test::OsMesaContext context;
  const auto t_upload = std::chrono::steady_clock::now();
  vbrdf::LiveRelight live(mesh.view(), fits, context.get_proc_address(), vbrdf::LobeForm::PhongRE,
                          vbrdf::DiffuseForms::everywhere(vbrdf::DiffuseForm::Lambert));
  const double upload = seconds_since(t_upload);
  // Camera 3 units away on +z, 40 degree vertical field of view.
  vbrdf::LiveView view;
  const double f = 1.0 / std::tan(20.0 * M_PI / 180.0), near_d = 1.0, far_d = 5.0;
  std::fill(view.projection, view.projection + 16, 0.0);
  view.projection[0] = f * height / width;
  view.projection[5] = f;
  view.projection[10] = -(far_d + near_d) / (far_d - near_d);
  view.projection[11] = -1;
  view.projection[14] = -2 * far_d * near_d / (far_d - near_d);
  view.modelview[14] = -3.0;
  std::printf("live view benchmark: %zu vertices, %zu triangles, %dx%d, %s\n", n, mesh.indices.size() / 3, width, height,
              context.renderer().c_str());
  std::printf("upload (arrays + GL buffers + shader): %.3f s\n", upload);
  const char *names[] = {"full model", "diffuse only", "specular only", "fit_status", "DQ", "SQ"};
  for (int mode : {0, 3}) {
    view.display = vbrdf::LiveDisplay(mode);
    std::vector<double> times;
    for (int i = 0; i < frames + 1; ++i) {
      const double a = 0.3 * i;
      view.light_eye[0] = float(std::sin(a)), view.light_eye[1] = 0.3f, view.light_eye[2] = float(std::cos(a));
      const auto t0 = std::chrono::steady_clock::now();
      live.render_offscreen(view, width, height, false);
      if (i > 0) times.push_back(seconds_since(t0));  // the first frame allocates the target
    }
    std::sort(times.begin(), times.end());
    std::printf("%-13s frame time: median %.1f ms, worst %.1f ms over %d frames (%.1f frames/s)\n", names[mode],
                1e3 * times[times.size() / 2], 1e3 * times.back(), frames, 1.0 / times[times.size() / 2]);
  }
  return 0;
}

} // namespace

int main(int argc, char **argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "bench_live_relight: %s\n", e.what());
    return 1;
  }
}
