// vbrdf_web_reference: what the browser test compares the web viewer with.
//
//   vbrdf_web_reference render RESULT.ply PROJECT.mlp OUT_DIR [--width W] [--cameras N] [--lights M]
//     The product's relight renderer (relight/relight_render.h, OSMesa) at N cameras x M lights:
//     cameras orbited from the project's first viewpoint around the mesh's bounding-box centre
//     (azimuth spread over +-25 degrees, elevation 0 / +10 / -8), the viewport W pixels wide with the
//     viewpoint's aspect (default: the viewpoint's own size, the photos' resolution); lights: M of the project's photo lights spread over the list (their
//     directions, as directional lights of unit irradiance). Writes OUT_DIR/reference.json (the GL
//     view and projection matrices of each camera, the light directions, the image files) and one
//     raw float32 RGBA image per camera and light (linear RGB, RelitPixel class in alpha, row 0 =
//     top): the renderer's own output before any clipping.
//
//   vbrdf_web_reference check RESULT.ply MODEL.glb
//     Reads the GLB back (tinygltf) and checks every attribute against the result PLY, float32 bit
//     for bit (web_glb_check.h); exit status 1 with the first difference.
//
//   vbrdf_web_reference synthesize VERTICES OUT.ply
//     A bumpy sphere of about VERTICES vertices with a plausible, smoothly varying fit in every
//     result attribute (for the size and speed figures; not a measurement of any capture).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "base/errors.h"
#include "inputs/light_file.h"
#include "inputs/light_source.h"
#include "inputs/project.h"
#include "io/output_ply.h"
#include "io/result_ply.h"
#include "io/result_schema.h"
#include "osmesa_context.h"
#include "relight/orbit_camera.h"
#include "relight/relight_render.h"
#include "test_scenes.h"
#include "web_glb_check.h"

using namespace vbrdf;

namespace {

std::string json_array(const float *v, int n) {
  std::ostringstream s;
  s.precision(9);
  s << "[";
  for (int i = 0; i < n; ++i) s << (i ? ", " : "") << v[i];
  s << "]";
  return s.str();
}

int render(int argc, char **argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: vbrdf_web_reference render RESULT.ply PROJECT.mlp OUT_DIR [--width W] [--cameras N] [--lights M]\n");
    return 2;
  }
  const std::string result_path = argv[2], project_path = argv[3], out_dir = argv[4];
  int width = 0, n_cameras = 3, n_lights = 8;  // width 0: the viewpoint's own
  for (int i = 5; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--width") width = std::atoi(argv[i + 1]);
    else if (a == "--cameras") n_cameras = std::atoi(argv[i + 1]);
    else if (a == "--lights") n_lights = std::atoi(argv[i + 1]);
  }
  const ResultPly result = read_result_ply(result_path);
  LobeForm lobe;
  DiffuseForms diffuse;
  const std::vector<VertexFit> fits = fits_from_result(result, result_path, &lobe, &diffuse);
  const Project project = read_project(project_path);
  if (project.rasters.empty()) throw InputError("Project '" + project_path + "' has no raster.");
  const MeshView mesh = result.mesh.view();
  const std::string light_file = find_default_light_file(project.rasters, project.project_path);
  if (light_file.empty()) throw InputError("Project '" + project_path + "': no light file lists every photo.");
  const std::vector<LightSource> photo_lights =
      resolve_lights(project.rasters, light_file, light_placement_of(mesh, 0, 0));

  // Cameras: the first viewpoint, resized to `width`, orbited around the box centre.
  const Bounds box = compute_bounds(mesh);
  const std::array<float, 3> c = box.centre();
  Shot base = project.rasters[0].shot;
  if (width <= 0) width = base.Intrinsics.ViewportPx[0];
  const float scale = float(width) / float(base.Intrinsics.ViewportPx[0]);
  const int height = int(std::lround(base.Intrinsics.ViewportPx[1] * scale));
  base.Intrinsics.ViewportPx[0] = width;
  base.Intrinsics.ViewportPx[1] = height;
  base.Intrinsics.CenterPx[0] *= scale;
  base.Intrinsics.CenterPx[1] *= scale;
  base.Intrinsics.PixelSizeMm[0] /= scale;
  base.Intrinsics.PixelSizeMm[1] /= scale;
  const float elevations[3] = {0.0f, 10.0f, -8.0f};
  std::vector<Shot> shots;
  for (int i = 0; i < n_cameras; ++i) {
    const float az = n_cameras > 1 ? -25.0f + 50.0f * float(i) / float(n_cameras - 1) : 0.0f;
    shots.push_back(orbit_shot(base, c.data(), az, elevations[i % 3], 1.0f));
  }
  std::vector<LightSource> lights;
  for (int j = 0; j < n_lights; ++j) {
    const size_t k = size_t(j) * photo_lights.size() / size_t(n_lights);
    lights.push_back(LightSource::directional(photo_lights[k].direction));
  }

  test::OsMesaContext gl;
  RelightRenderSettings settings;
  settings.lobe = lobe;
  settings.diffuse = diffuse;
  RelightRenderer renderer(mesh, fits, gl.get_proc_address(), settings);

  std::ostringstream json;
  json << "{\n  \"width\": " << width << ", \"height\": " << height << ",\n  \"renderer\": \""
       << renderer.renderer_name() << "\",\n  \"lobe_form\": " << int(lobe) << ",\n  \"cameras\": [\n";
  for (size_t i = 0; i < shots.size(); ++i) {
    float view[16], proj[16];
    gl_view_matrix(shots[i], view);
    // Near and far as the relight renderer chooses them (the box's corners in depth).
    float dmin = 1e30f, dmax = -1e30f;
    for (int k = 0; k < 8; ++k) {
      const float p[3] = {(k & 1) ? box.max[0] : box.min[0], (k & 2) ? box.max[1] : box.min[1],
                          (k & 4) ? box.max[2] : box.min[2]};
      const float z = view[2] * p[0] + view[6] * p[1] + view[10] * p[2] + view[14];
      dmin = std::min(dmin, -z);
      dmax = std::max(dmax, -z);
    }
    const float far_d = std::max(dmax, 1e-6f) * 1.01f + 0.002f * box.diagonal();
    const float near_d = std::max(dmin * 0.99f, far_d * 1e-4f);
    gl_projection_matrix(shots[i], near_d, far_d, proj);
    json << "    {\"view\": " << json_array(view, 16) << ", \"projection\": " << json_array(proj, 16) << "}"
         << (i + 1 < shots.size() ? "," : "") << "\n";
  }
  json << "  ],\n  \"lights\": [\n";
  for (size_t j = 0; j < lights.size(); ++j)
    json << "    " << json_array(lights[j].direction.data(), 3) << (j + 1 < lights.size() ? "," : "") << "\n";
  json << "  ],\n  \"images\": [\n";
  for (size_t i = 0; i < shots.size(); ++i)
    for (size_t j = 0; j < lights.size(); ++j) {
      const RelitImage img = renderer.render(shots[i], lights[j]);
      std::vector<float> rgba(size_t(img.width) * size_t(img.height) * 4);
      for (size_t p = 0; p < size_t(img.width) * size_t(img.height); ++p) {
        for (int k = 0; k < 3; ++k) rgba[4 * p + size_t(k)] = img.rgb[3 * p + size_t(k)];
        rgba[4 * p + 3] = float(img.pixel_class[p]);
      }
      const std::string name = "ref_c" + std::to_string(i) + "_l" + std::to_string(j) + ".f32";
      std::ofstream f(out_dir + "/" + name, std::ios::binary);
      f.write(reinterpret_cast<const char *>(rgba.data()), std::streamsize(rgba.size() * sizeof(float)));
      if (!f) throw ProcessingError("cannot write " + out_dir + "/" + name);
      json << "    {\"camera\": " << i << ", \"light\": " << j << ", \"file\": \"" << name << "\"}"
           << (i + 1 < shots.size() || j + 1 < lights.size() ? "," : "") << "\n";
    }
  json << "  ]\n}\n";
  std::ofstream f(out_dir + "/reference.json");
  f << json.str();
  if (!f) throw ProcessingError("cannot write " + out_dir + "/reference.json");
  std::printf("vbrdf_web_reference: %zu cameras x %zu lights, %dx%d, %s\n", shots.size(), lights.size(), width, height,
              renderer.renderer_name());
  return 0;
}

int synthesize(int argc, char **argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: vbrdf_web_reference synthesize VERTICES OUT.ply\n");
    return 2;
  }
  const MeshData mesh = test::make_bumpy_sphere(size_t(std::atoll(argv[2])));
  const size_t n = mesh.positions.size() / 3;
  std::vector<VertexRecord> records(n);
  for (size_t v = 0; v < n; ++v) {
    const float *p = &mesh.positions[3 * v];
    VertexRecord &r = records[v];
    const float a = 0.5f + 0.5f * std::sin(7.0f * p[0] + 3.0f * p[1]), b = 0.5f + 0.5f * std::cos(5.0f * p[2] - 2.0f * p[0]);
    r.fit.color[0] = 1.0f;
    r.fit.color[1] = 0.4f + 0.5f * a;
    r.fit.color[2] = 0.2f + 0.6f * b;
    r.fit.kd = 0.3f + 0.5f * b;
    r.fit.ks = a > 0.3f ? 0.05f + 0.4f * a : 0.0f;
    r.fit.shininess = r.fit.ks > 0 ? 5.0f + 120.0f * b : 0.0f;
    r.fit.dq = 2.0f * a;
    r.fit.sq = 2.0f * b;
    r.fit.status = r.fit.ks > 0 ? kFitFull : kFitDiffuseOnly;
    if (p[2] < -0.8f) r.fit = VertexFit{{0, 0, 0}, 0, 0, 0, 0, 0, 0, 0, kFitNone, 0};
    for (int k = 0; k < 3; ++k) r.diffuse[k] = r.fit.kd * r.fit.color[k];
    r.lobe_form = 2;
    r.diffuse_form = p[0] > 0 ? 1.0f : 0.0f;
    for (int k = 0; k < 3; ++k) r.mesh_normal[k] = mesh.normals[3 * v + size_t(k)];
  }
  std::vector<uint8_t> colors(4 * n, 200);
  write_result_ply(argv[3], mesh.view(), colors, result_attributes(records, true));
  std::printf("vbrdf_web_reference: %s: %zu vertices, %zu triangles\n", argv[3], n, mesh.indices.size() / 3);
  return 0;
}

} // namespace

int main(int argc, char **argv) {
  try {
    if (argc >= 2 && std::string(argv[1]) == "render") return render(argc, argv);
    if (argc >= 4 && std::string(argv[1]) == "check") {
      const std::string why = check_glb_against_result(argv[2], argv[3]);
      if (!why.empty()) {
        std::fprintf(stderr, "vbrdf_web_reference: %s differs from %s: %s\n", argv[3], argv[2], why.c_str());
        return 1;
      }
      std::printf("vbrdf_web_reference: %s carries %s's attributes exactly\n", argv[3], argv[2]);
      return 0;
    }
    if (argc >= 2 && std::string(argv[1]) == "synthesize") return synthesize(argc, argv);
    std::fprintf(stderr, "usage: vbrdf_web_reference render|synthesize ...\n");
    return 2;
  } catch (const std::exception &e) {
    std::fprintf(stderr, "vbrdf_web_reference: %s\n", e.what());
    return 1;
  }
}
