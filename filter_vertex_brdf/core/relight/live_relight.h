#pragma once
// Live relighting: draws a mesh with its per-vertex reflectance fits into the caller's framebuffer for a
// view given as GL matrices and a light given in eye coordinates, as an interactive viewer has
// them (MeshLab's render plugin "Vertex BRDF: relight" is a thin adapter over this class). The
// model is shaders/reflectance_model.glsl, the same GLSL the relight renderer (relight_render.h) uses;
// their differences (no cast shadows here, orthographic views, exposure and sRGB output) are
// stated in that file. Independent of MeshLab: GL through a get-proc-address (core 3.3 suffices).
//
// Display modes: the full model, its diffuse or specular term alone (all times the exposure,
// clipped at 1, sRGB-encoded), or false colours of fit_status / DQ / SQ (live_legend.h) shaded by
// 0.35 + 0.65 max(N.L, 0) so that the shape stays readable. Unfitted vertices (fit_status 0) are
// grey in the model modes (the relight renderer draws them black); N.L <= 0 is black.
#include <cstddef>
#include <memory>
#include <vector>

#include "base/mesh_view.h"
#include "fit/reflectance_fit.h"
#include "gl/gl_context.h"  // GetProcAddressFn
#include "model/diffuse_form.h"
#include "model/lobe.h"

namespace vbrdf {

enum class LiveDisplay : int {
  Full = 0,             // rho d + k_s s^alpha
  Diffuse = 1,          // rho d
  Specular = 2,         // k_s s^alpha
  FitStatus = 3,        // false colours of fit_status (live_legend.h)
  DiffuseQuality = 4,   // DQ, 0..2
  SpecularQuality = 5,  // SQ, 0..2
};

struct LiveView {
  double modelview[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // world -> eye, column-major
  double projection[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; // column-major
  // The light in eye coordinates, as glGetLightfv(GL_LIGHT0, GL_POSITION) returns it: w = 0 a
  // direction towards the light (MeshLab's), else a position (taken as a direction from the
  // object's centre: the live view lights with unit irradiance from one direction).
  float light_eye[4] = {0, 0, 1, 0};
  LiveDisplay display = LiveDisplay::Full;
  float exposure = 1.0f;    // multiplies the model's linear value before clipping (modes 0-2)
  bool encode_srgb = true;  // false: linear output, unclipped (tests compare with the relight renderer)
};

// A direction given in eye coordinates (e.g. MeshLab's directional light) in world coordinates:
// the inverse of the modelview's linear part applied, normalised. False when that part is singular
// or the result is zero or not finite.
bool eye_to_world_direction(const double modelview[16], const double eye_direction[3], double world_out[3]);

class LiveRelight {
public:
  // Uploads the mesh (positions relative to its bounding-box centre, for precision) and one
  // VertexFit per vertex (k_s = 0 vertices get the median shininess, reflectance_model_source.h).
  // Requires a current GL >= 3.3 context for the object's lifetime. Throws InputError when the
  // counts differ or an index is out of range, ProcessingError when the context cannot compile
  // the shader.
  LiveRelight(const MeshView &mesh, const std::vector<VertexFit> &fits, const GetProcAddressFn &get_proc,
              LobeForm lobe, const DiffuseForms &diffuse);
  ~LiveRelight();
  LiveRelight(const LiveRelight &) = delete;
  LiveRelight &operator=(const LiveRelight &) = delete;

  // Draws into the bound framebuffer and viewport with depth testing (GL_LESS, depth written);
  // every other state it touches is restored (GlStateGuard). Throws InputError for a singular
  // modelview or a zero light.
  void draw(const LiveView &view);

  // Draws into an off-screen float target of width x height (cleared to 0) and reads it back:
  // RGBA, row 0 = top; alpha 1 on the surface, 0 on the background. For tests and benchmarks;
  // read_back = false waits for the frame (glFinish) and returns nothing (frame timing).
  std::vector<float> render_offscreen(const LiveView &view, int width, int height, bool read_back = true);

  size_t vertex_count() const;

private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace vbrdf
