#pragma once
// Samples: one per (vertex, photo) pair in which the vertex is seen by the photo's camera.
// Everything later stages read (colour, fit, coverage) comes from here.
//
// Memory: visibility is computed per photo for all vertices and kept as bit masks
// (visibility/visibility_masks.h); pixel samples are then produced per vertex chunk, so the number
// of photos and vertices is limited by disk and time, not by memory. A sample is 24 bytes.
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "base/callbacks.h"  // ProgressFn
#include "inputs/camera.h"
#include "model/defaults.h"
#include "model/diffuse_form.h"
#include "model/lobe.h"
#include "inputs/light_source.h"
#include "base/mesh_view.h"
#include "inputs/photo.h"
#include "visibility/visibility_masks.h"

namespace vbrdf {

enum SampleFlag : uint16_t {
  kOffImage = 1u << 0,        // projects outside the photo or behind the camera (never stored)
  kBackFacing = 1u << 1,      // N.E <= 0 (never stored)
  kOccluded = 1u << 2,        // hidden by other geometry from the camera (never stored)
  kAttachedShadow = 1u << 3,  // N.L <= 0: faces away from the light
  kCastShadow = 1u << 4,      // other geometry between the vertex and the light
  kSaturated = 1u << 5,       // a channel is clipped in the bilinear footprint
  kGrazing = 1u << 6,         // 0 < N.L < T_d
  kHighlight = 1u << 7,       // R.E > T_s (specular sample)
  kMixedPixel = 1u << 8,      // the pixel footprint also covers background/another surface, and
                              //   the colour includes it (no own-surface texel, or plain bilinear)
  kRimFootprint = 1u << 9,    // the footprint straddles a depth jump; the colour comes from its
                              //   own-surface texels only (GatherSettings::own_surface_texels)
};
constexpr uint16_t kNotSeen = kOffImage | kBackFacing | kOccluded;
constexpr uint16_t kShadowed = kAttachedShadow | kCastShadow;

struct Sample {
  float rgb[3];      // linear pixel colour (bilinear)
  float d;           // the diffuse factor: N.L, or with the coat's Fresnel transmission
                     //   (GatherSettings::diffuse, diffuse_form.h); <= 0 exactly when N.L <= 0
  float lobe_cos;    // s: the specular lobe's cosine, R.E or N.H (GatherSettings::lobe, lobe.h);
                     //   E = unit vector from the vertex to the camera centre
  uint16_t raster;   // index of the photo
  uint16_t flags : 10;      // SampleFlag bits
  uint16_t resolution : 6;  // how well this photo resolves the vertex, relative to the vertex's
                            //   best-resolving photo: weight 2^(-resolution/8) (resolution_weight)
  float footprint = 0;      // variance of the shading normal over the photo's pixel footprint of the
                            //   vertex (samples/footprint.h; 0 = none, or not computed): the GGX
                            //   lobe is seen through it (lobe.h ggx_lobe_through_footprint)
};
static_assert(sizeof(Sample) == 28, "Sample must stay compact");

// The fit's weight factor for a sample's photo resolution: 1 for the photos that resolve the
// vertex best (and for every sample when all its photos see it alike, e.g. one camera), down to
// 2^(-63/8) = 0.004. See gather_samples for how the code is set.
inline float resolution_weight(const Sample &s) { return std::exp2(-float(s.resolution) / 8.0f); }
// The code of a resolution ratio in (0, 1] (1 = the best photo of the vertex): round(-8 log2 ratio),
// clamped to [0, 63]; a non-finite or non-positive ratio gives 63.
inline uint16_t resolution_code(float ratio) {
  if (!(ratio > 0)) return 63;
  const float q = std::round(-8.0f * std::log2(std::fmin(ratio, 1.0f)));
  return uint16_t(std::fmin(std::fmax(q, 0.0f), 63.0f));
}
// How finely the photo of `raster` resolves a surface point at `position` with unit normal `n`:
// pixels per unit surface area, (f / dist)^2 N.E (f: focal length in pixels, dist: distance to
// the camera centre), as MeshLab's colour projection weights by angle and depth. 0 when
// back-facing.
float photo_resolution(const Raster &raster, const float position[3], const float n[3]);

// Usable for the diffuse colour: lit, not grazing, not a highlight, not saturated, clean pixel.
inline bool is_diffuse_sample(const Sample &s) {
  return (s.flags & (kShadowed | kSaturated | kGrazing | kHighlight | kMixedPixel)) == 0;
}
// Usable as specular evidence: lit, unsaturated, clean highlight.
inline bool is_specular_sample(const Sample &s) {
  return (s.flags & (kShadowed | kSaturated | kMixedPixel)) == 0 && (s.flags & kHighlight) != 0;
}
// Usable to score a model's prediction (held-out errors, residuals): lit, unsaturated, clean pixel,
// d > 0, every value finite.
inline bool is_scorable_sample(const Sample &s) {
  return !(s.flags & (kShadowed | kSaturated | kMixedPixel | kNotSeen)) && s.d > 0 && std::isfinite(s.d) &&
         std::isfinite(s.lobe_cos) && std::isfinite(s.rgb[0]) && std::isfinite(s.rgb[1]) && std::isfinite(s.rgb[2]);
}

struct GatherSettings {
  float specular_threshold = kDefaultSpecularThreshold;  // T_s on R.E
  float diffuse_threshold = kFitDiffuseThreshold;        // T_d on N.L (coverage: CoverageSettings sets its own)
  PhotoEncoding encoding = PhotoEncoding::Auto;
  float saturation_level = kSaturationLevel;   // fraction of the maximum code value counted as clipped
  size_t photo_cache_bytes = size_t(2) << 30;  // decoded photos kept in memory
  // Photos the host application has already decoded (the plugin: MeshLab's raster images), read
  // in place instead of decoded again; they take none of photo_cache_bytes. Empty: decode files.
  std::shared_ptr<const HostPhotos> host_photos;
  size_t chunk_sample_bytes = size_t(256) << 20; // target size of one chunk's samples
  // Where a vertex's 2x2 bilinear footprint straddles a depth jump (silhouette, contact), take
  // the colour from the footprint texels on the vertex's own surface, re-weighted (the fit's
  // choice). false: plain bilinear over all 4 texels, mixed or not (the RTI evaluation protocol:
  // held-out photos are compared as sampled, contamination included).
  bool own_surface_texels = true;
  // The lobe's cosine stored in Sample::lobe_cos (lobe.h). The fit's ReflectanceFitOptions::lobe
  // (run/fit_run.cpp keeps them equal). kHighlight stays R.E > T_s whichever the form.
  LobeForm lobe = kDefaultLobe;
  // The diffuse term's form stored in Sample::d (diffuse_form.h), per vertex where it varies
  // (gather_samples; make_sample takes `uniform`). kGrazing stays N.L < T_d on the plain cosine.
  DiffuseForms diffuse;
  // Weight samples by their photo's resolution of the vertex (Sample::resolution); false: every
  // code 0 (all photos alike). Off by default: on the spot pair the two-camera fit scored worse
  // with it (docs/decisions/lobe_half_angle.md).
  bool resolution_weights = false;
  // Fill Sample::footprint (the normal variance over the photo's pixel footprint, footprint.h) for
  // the GGX lobe; false, or another lobe form: every footprint 0 (the lobe at the vertex alone).
  bool footprint = true;
  // The mesh's normal_gradients (footprint.h) when the caller has them (the fit computes them once
  // for its pilot and its gather); empty: gather_samples computes them.
  std::shared_ptr<const std::vector<float>> normal_gradients;
};

// Builds the sample of vertex (position, normal) in raster `raster_index` whose photo is `photo`,
// lit by `light` (its direction at the vertex: light_direction_at). The colour is the photo's,
// NOT divided by the light's fall-off (apply_light_falloff does that, after colour correction).
// `camera_clear`/`light_clear` come from the depth passes (occlusion / cast shadow);
// `own_texels` is the footprint mask of the camera pass (kAllFootprintTexels: a clean footprint).
// A partial footprint gives kRimFootprint and the own texels' colour when
// settings.own_surface_texels and any own texel remains, else kMixedPixel and the plain bilinear
// colour. Returns the flags; when the result has any kNotSeen flag, `out` holds only flags and
// geometry terms. `projected`: project_to_image(raster.shot, position) when the caller has it.
uint16_t make_sample(const float position[3], const float normal[3], const Raster &raster, uint16_t raster_index,
                     const LightSource &light, const Photo &photo, bool camera_clear, bool light_clear,
                     const GatherSettings &settings, Sample &out, uint8_t own_texels = kAllFootprintTexels,
                     const ImagePoint *projected = nullptr);

struct SampleChunk {
  uint32_t first_vertex = 0;
  uint32_t vertex_count = 0;
  std::vector<uint32_t> offsets;  // vertex_count + 1 entries: samples of vertex first_vertex + i
  std::vector<Sample> samples;    //   are samples[offsets[i] .. offsets[i+1])
};

struct GatherStats {
  uint64_t pairs = 0;             // vertex x raster pairs examined
  uint64_t stored = 0;            // samples stored (seen by the camera)
  uint64_t flag_counts[16] = {};  // pairs with each SampleFlag bit set (index = bit position)
  std::vector<uint32_t> raster_seen_vertices;  // per raster: vertices it sees
  size_t chunks = 0;
  size_t rasters_skipped = 0;     // raster x chunk pairs skipped because the raster sees no vertex there
  size_t photo_loads = 0;         // photo files decoded
  size_t host_photo_reads = 0;    // photos read in place from the host's decoded images (GatherSettings::host_photos)
  double seconds = 0;
};

// Sample::resolution: for each vertex, photo_resolution of every sample's photo relative to the
// best among the vertex's samples (resolution_code), when settings.resolution_weights.
// Streams samples chunk by chunk (vertex ranges sized by settings.chunk_sample_bytes) to
// `consume`. Chunks arrive in vertex order; the chunk object is reused after `consume` returns,
// so `consume` may modify it (the fit corrects the samples' colours in place).
// Only pairs the masks mark as seen are sampled; a photo that sees no vertex of a chunk is not
// even loaded (GatherStats::rasters_skipped counts such raster x chunk pairs).
GatherStats gather_samples(const MeshView &mesh, const std::vector<Raster> &rasters,
                           const std::vector<LightSource> &lights, const VisibilityMasks &masks,
                           const GatherSettings &settings, PhotoCache &photos,
                           const std::function<void(SampleChunk &)> &consume, const ProgressFn &progress = {});

// Point lights: divides each sample's colour by the irradiance of its light at its vertex
// (light_irradiance_at), so that the fit sees every sample as under unit light, as with
// directional lights. Call it after colour correction (which need not be linear). Flags and the
// saturation test (made on the photo's values) are unchanged. A no-op for directional lights;
// the factor is finite and positive (clamped distance), so no NaN arises.
void apply_light_falloff(SampleChunk &chunk, const MeshView &mesh, const std::vector<LightSource> &lights);

// Rim samples (kRimFootprint: colour from part of a footprint that straddles a silhouette or
// contact) still carry some of the other side through the sensor's pixel area. A vertex with at
// least `min_clean` clean diffuse samples (is_diffuse_sample without kRimFootprint) does not need
// them: its rim samples are marked kMixedPixel (left out by the strict fit and the diffuse
// estimate, like every back end's). Vertices with fewer keep them. Returns the samples demoted.
size_t prefer_clean_samples(SampleChunk &chunk, int min_clean = 2);

} // namespace vbrdf
