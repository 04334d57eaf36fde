#pragma once
// CPU renderer of the synthetic captures: z-buffer rasterisation through a vcg::Shot (supersampled,
// perspective-correct interpolation of per-vertex attributes), Phong shading, cast shadows by
// exact ray casts, PNG encoding (8-bit sRGB or 16-bit linear).
#include <cstdint>
#include <limits>
#include <vector>

#include <opencv2/core.hpp>

#include "synth_bvh.h"
#include "synth_camera.h"
#include "synth_scene.h"

namespace synth {

struct ShadeSettings {
  float irradiance = 1.0f;  // E, white light (point light: at reference_distance from it)
  bool linear16 = false;    // 16-bit linear PNG instead of 8-bit sRGB
  float noise_sigma = 0;    // Gaussian noise std-dev in linear units (0..1 = full scale)
  uint64_t seed = 1;        // noise seed
  bool coated_diffuse = false;  // diffuse body under a clear coat of index 1.5 (--coated-diffuse):
                                //   k_d N.L C scaled by the Fresnel transmission in and out, t(N.L) t(N.V) / t(1)^2
  bool coat_glossy_only = false;  // ... only where k_s > 0 (--coated-glossy: a coated and a bare material)
};

// The model, per colour channel, without the visibility factor:
//   E * (kd * max(N.L, 0) * C + ks * max(R.V, 0)^shininess),  R = 2 (N.L) N - L
// N unit normal, L unit direction towards the light, V unit direction towards the camera centre.
// With `coated`, the diffuse term is multiplied by t(N.L) t(N.V) / t(1)^2, t the unpolarised
// Fresnel transmission into index 1.5 (exact, no clamp: the truth, not the fit's model).
V3 phong(float kd, float ks, float shininess, V3 color, V3 N, V3 L, V3 V, float irradiance, bool coated = false);

// The light of one photo, world frame: directional (the same direction everywhere) or an
// isotropic point light whose irradiance at x is E * (reference_distance / |position - x|)^2.
struct Light {
  V3 direction;                // directional: unit vector towards the light
  bool point = false;
  V3 position;                 // point light: where it is
  float reference_distance = 1;  // point light: distance at which the irradiance is E (> 0)
};

// What a surface point x receives from `light`: unit direction towards it, distance to it
// (infinity for a directional light) and the irradiance factor (1 for a directional light).
// A point light at x itself (distance below 1e-6 reference distances) gives direction (0,0,0)
// and factor 0: the point is not lit, never NaN.
struct LightAt {
  V3 L;
  float distance;
  float falloff;
};
LightAt light_at(const Light &light, V3 x);

// Scene-wide data shared by all photos.
struct RenderContext {
  RenderContext(const Scene &scene);
  const Scene &scene;
  Bvh bvh;
  std::vector<V3> face_normal;  // geometric normals (unit, outwards)
  float ray_eps;                // shadow-ray origin offset along the normal (world units)

  // 1 when N.L > 0, the geometric normal faces the light and the ray towards it is free.
  // Directional light: unit direction L, infinite ray. With `distance` (a point light): L is
  // the unit direction from p to the light, and the ray stops at the light.
  bool lit(V3 p, V3 geometric_normal, V3 shading_normal, V3 L,
           float distance = std::numeric_limits<float>::infinity()) const;
};

// Visible surface per sample of one view (ss x ss samples per pixel, box-filtered by
// render_photo): triangle id (-1 = background) and perspective-correct barycentrics of
// vertices 1 and 2.
struct ViewRaster {
  int width = 0, height = 0, ss = 1;
  std::vector<int32_t> tri;
  std::vector<float> b1, b2;
};
ViewRaster rasterize(const RenderContext &ctx, const Shot &shot, int ss);

struct PhotoStats {
  uint64_t covered_pixels = 0;    // pixels with at least one object sample
  uint64_t saturated_pixels = 0;  // covered pixels with a clipped channel
};

// One photo under `light` (world frame), BGR, CV_8UC3 or CV_16UC3. Per sample: L and the
// irradiance factor from light_at() at the interpolated position. `photo_key` decorrelates the
// noise of different photos.
cv::Mat render_photo(const RenderContext &ctx, const ViewRaster &raster, const Shot &shot,
                     const Light &light, const ShadeSettings &settings, uint64_t photo_key,
                     PhotoStats &stats);

// Encodings (value clipped to [0, 1] first).
uint8_t encode_srgb8(float linear);
uint16_t encode_linear16(float linear);

} // namespace synth
