#pragma once
// Publishing a fit on the web: a fit result (a result PLY, io/result_ply.h) as one binary glTF 2.0
// file (GLB) that a browser relights with the product's model, and the viewer page beside it
// (publish/web_viewer.h). MeshLab-independent; the filter "Vertex BRDF: export for the web" and the
// command-line tool vbrdf-web-export are thin callers. Layout in full: docs/web.md#the-glb.
//
// The GLB (written with tinygltf): one scene, one node, one mesh, one indexed triangle primitive
//   POSITION    VEC3 float  the result's x y z, as stored
//   NORMAL      VEC3 float  the result's nx ny nz (the shading normals the model was fitted with)
//   indices     SCALAR uint32
//   COLOR_0     VEC3 float  linear k_d C, each channel clamped to [0, 1] (glTF's range)
//   _ALBEDO     VEC3 float  linear k_d C unclamped; only when some channel of some vertex exceeds 1
//   _KS, _SHININESS, _DIFFUSE_FORM, _FIT_STATUS, _DQ, _SQ   SCALAR float: the result's ks,
//               shininess, diffuse_form, fit_status, dq, sq, as stored (float32, bit for bit)
// The model is declared in the primitive's extras.vbrdf_model (lobe form, diffuse form, coat index
// and minimum cosine, the shininess of k_s = 0 vertices, what every attribute means); the capture
// (photo lights, viewpoint cameras, world frame) in the scene's extras.vbrdf_capture. The material
// is a plain pbrMetallicRoughness fallback for generic viewers: base colour 1 (times COLOR_0),
// metallic 0, roughness (2 / (alpha + 2))^(1/4) of the median shininess alpha of the fitted lobes.
//
// Errors: InputError naming the result file and the remedy for a result without a reflectance
// model (a missing model attribute), without triangles, with a non-finite value or a zero normal
// (nothing of the kind reaches the file: glTF readers and the viewer would show garbage), or with
// mixed lobe forms; ProcessingError when the GLB cannot be serialised or written.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "inputs/camera.h"
#include "base/output_file.h"
#include "io/result_ply.h"
#include "model/lobe.h"

namespace vbrdf {

// What the photos of the capture contribute (optional: an empty capture exports the model alone).
struct WebCapture {
  struct Light {
    std::string image;                   // photo file name
    std::array<float, 3> direction{};    // world, unit, towards the light (a point light: from the object's centre)
    bool positional = false;
    std::array<float, 3> position{};     // point light, world frame, mesh units
  };
  struct Camera {
    std::string label;                   // the first raster of the viewpoint
    int photos = 0;                      // rasters of this viewpoint
    int width = 0, height = 0;           // pixels
    float focal_px = 0;                  // focal length in pixels (vertical)
    float centre_px[2] = {0, 0};         // principal point, image pixels (top-left origin, y down)
    std::array<float, 3> position{};     // camera centre, world
    float view[16] = {};                 // world -> camera (OpenGL: looks down -z, y up), column-major
  };
  std::vector<Light> lights;
  std::vector<Camera> cameras;
  std::string light_file;                // the file the lights came from ("" when none)
  std::string note;                      // why there are no lights or cameras, for logs ("" otherwise)
};

// The capture of `rasters` (one camera per viewpoint: rasters with the same shot, camera.h
// same_shot) and their lights from `light_file` (light_source.h resolve_lights; "" = the default
// light file of the rasters beside `project_path`, light_file.h). Without a qualifying light file
// the lights stay empty and `note` says why; a light file that exists but does not read throws
// its InputError.
WebCapture web_capture_of(const std::vector<Raster> &rasters, const std::string &project_path,
                          const std::string &light_file, const MeshView &mesh);

struct WebGlb {
  std::vector<uint8_t> bytes;  // the GLB file
  size_t vertices = 0, triangles = 0, modelled = 0;  // modelled: fit_status != 0
  bool albedo_written = false;  // _ALBEDO present (some k_d C channel above 1)
  LobeForm lobe = LobeForm::PhongRE;
  float typical_shininess = 1;  // the shininess k_s = 0 vertices are drawn with
  float roughness = 1;          // the fallback material's
  std::string summary() const;  // one line for logs: counts, bytes per vertex, forms
};

// Builds the GLB of `result` (read from `result_path`, named in messages) and `capture`.
WebGlb build_web_glb(const ResultPly &result, const std::string &result_path, const WebCapture &capture);

// The files written beside each other by write_web_outputs.
struct WebOutputPaths {
  std::string glb;          // <name>.glb
  std::string html;         // <name>.html: the viewer with the GLB embedded (opens from file://)
  std::string hosted_html;  // <name>_hosted.html: the viewer loading <name>.glb by URL (a web server)
};
// The paths for a GLB path (its extension replaced; a path without ".glb" gets it appended).
WebOutputPaths web_output_paths(const std::string &glb_path);

// Writes the GLB and, when `with_viewer`, both viewer pages (publish/web_viewer.h), each
// atomically (base/output_file.h), after checking every path against `policy` (nothing is written
// when one is refused). Throws InputError (a refused or unwritable path; `with_viewer` in a build
// without the viewer, with the remedy) or ProcessingError (I/O). Returns the paths written.
WebOutputPaths write_web_outputs(const WebGlb &glb, const std::string &glb_path, bool with_viewer,
                                 OverwritePolicy policy, const std::string &title);

} // namespace vbrdf
