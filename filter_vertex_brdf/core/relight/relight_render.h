#pragma once
// Image-space relighting: renders the fitted per-vertex reflectance model (reflectance_fit.h) with OpenGL for
// any camera (vcg::Shot) and light (light_source.h: directional or point), with cast shadows from
// a shadow map (light_view.h). The render is compared with a photo pixel by pixel in
// relight_compare.h (CIEDE2000, PSNR; the pixel rules are stated here), shown to people by
// relight_images.h (render | photo | heat map, contact sheet) and run over a project's rasters by
// relight_report.h (the relight filter's table and files).
//
// Shading is per pixel: the vertex normal and the model parameters (rho = k_d C, k_s, alpha) are
// interpolated over each triangle and the model is evaluated per fragment as evaluate_reflectance does,
// by shaders/reflectance_model.glsl (shared with the live view, live_relight.h; differences stated there)
// (E from the fragment to the camera centre; the lobe's cosine R.E, R = 2(N.L)N - L, or N.H as
// settings.lobe says; the diffuse factor N.L or coated as settings.diffuse says, diffuse_form.h). Where k_s = 0 the shininess is
// undefined (0); such vertices take the median shininess of the fitted lobes, so that a lobe fades
// with k_s across a triangle instead of widening. Lights are directional with unit irradiance, as
// in the fit: the render is in the photos' linear units.
//
// Comparison with a photo uses the "lit visible" pixels: rendered lit (N.L > 0, not in cast
// shadow), every vertex of the triangle fitted, all 8 neighbours on the same surface (no
// silhouette or depth jump: those photo pixels mix surfaces) and no clipped photo channel.
// The prediction is clipped at 1 (what a camera records) for CIEDE2000 and PSNR.
// Beside it, labelled, the whole surface (the RTI protocol): every lit or unfitted surface pixel,
// silhouettes and depth jumps included, unfitted surface predicted black; clipped pixels left out.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "inputs/camera.h"
#include "inputs/light_source.h"
#include "base/mesh_view.h"
#include "fit/reflectance_fit.h"
#include "gl/gl_context.h"  // GetProcAddressFn

namespace vbrdf {

// Per-pixel classes of a render.
enum RelitPixel : uint8_t {
  kRelitBackground = 0,  // no surface
  kRelitLit = 1,         // lit surface with a fitted model
  kRelitShadowed = 2,    // N.L <= 0 or in cast shadow: the model predicts black
  kRelitNoFit = 3,       // a vertex of the triangle has no fit (kFitNone)
};

struct RelitImage {
  int width = 0, height = 0;
  std::vector<float> rgb;            // linear RGB, 3 per pixel, row 0 = top of the image
  std::vector<uint8_t> pixel_class;  // RelitPixel per pixel
  std::vector<float> depth;          // view depth of the surface (0 on background)
};

struct RelightRenderSettings {
  int shadow_map_size = kDefaultShadowMapSize;  // light-view depth map, pixels per side; 0 = automatic, as the
                                  // fit's visibility pass (resolved_shadow_map_size)
  float depth_tolerance = kDefaultDepthTolerance; // shadow test slack, fraction of the bounding-box diagonal
  LobeForm lobe = kDefaultLobe;  // the fit's lobe form (its result's lobe_form; lobe.h)
  DiffuseForms diffuse;  // the fit's diffuse forms, per vertex where they vary (its result's diffuse_form; diffuse_form.h)
};

// Renders one mesh with its per-vertex fits (one VertexFit per vertex). The mesh and the fits are
// uploaded once; each render() draws a shadow map from the light and the surface from the camera.
// Requires a current OpenGL >= 3.3 context (core or compatibility) for the object's lifetime and
// leaves the host's GL state as it was (GlStateGuard). Throws ProcessingError when the context
// cannot run the passes, InputError for a fit count that does not match the mesh, a bad index or
// a negative shadow map size.
class RelightRenderer {
public:
  RelightRenderer(const MeshView &mesh, const std::vector<VertexFit> &fits, const GetProcAddressFn &get_proc,
                  const RelightRenderSettings &settings = RelightRenderSettings());
  ~RelightRenderer();
  RelightRenderer(const RelightRenderer &) = delete;
  RelightRenderer &operator=(const RelightRenderer &) = delete;

  // Renders the viewport of `shot` (no lens distortion) lit by `light` (directional, or a point
  // light with its per-fragment direction and fall-off, light_source.h), with cast shadows from
  // light_view.h's shadow map. Throws InputError for an invalid shot, a zero light direction or a
  // point light within the mesh's bounding sphere, ProcessingError when the viewport exceeds the
  // GL limits.
  RelitImage render(const Shot &shot, const LightSource &light);

  const char *renderer_name() const;  // GL_RENDERER, for logs

private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

// The model's image as the camera of `shot` records it: rendered with up to `max_scale` x
// `max_scale` subpixels per photo pixel (fewer for large photos: at most 2^23 subpixels, and
// within the GL size limits) and box-filtered back to the photo's size, as a sensor pixel
// integrates the light over its area, so that silhouettes and contacts are partly covered as in
// a photo. CV_32FC3 linear RGB, row 0 = top, the shot's size; background and shadow 0.
cv::Mat render_as_photographed(RelightRenderer &renderer, const Shot &shot, const LightSource &light,
                               int max_scale = 4);

} // namespace vbrdf
