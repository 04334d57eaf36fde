#pragma once
// The shading terms of samples for another shading normal: Sample::d, Sample::lobe_cos and the
// flags that depend on the normal (kAttachedShadow, kGrazing, kHighlight), computed as
// make_sample computes them. Colour, visibility (kOccluded, kCastShadow: the mesh's geometry),
// saturation, footprint flags, resolution and footprint variance stay as gathered. Used when the
// shading normals are refined from the photos (fit/shading_normals.h).
#include <cstdint>
#include <vector>

#include "base/mesh_view.h"
#include "inputs/light_source.h"
#include "inputs/photo.h"
#include "samples/samples.h"

namespace vbrdf {

// Sets the normal-dependent terms and flags of `s` for unit shading normal `n`, unit direction
// towards the light `l` and towards the camera `e`, diffuse form `form`; thresholds and lobe form
// from `settings` (T_d on the plain N.L, T_s on R.E, as make_sample).
void shade_sample(const float n[3], const float l[3], const float e[3], DiffuseForm form, const GatherSettings &settings,
                  Sample &s);

// The `count` samples of one vertex at `position` shaded again with unit normal `n` (shade_sample;
// camera centres 3 per raster, lights[raster] at the vertex). Footprints stay as they are.
void reshade_vertex(Sample *samples, size_t count, const float n[3], const float position[3], const float *centres,
                    const std::vector<LightSource> &lights, DiffuseForm form, const GatherSettings &settings);

// Every sample of the chunk's vertices with changed[i] != 0 (i = vertex - chunk.first_vertex)
// shaded again with normals[3 v] (unit; a zero normal leaves the vertex as it is); positions from
// `mesh`, camera centres from the rasters, lights[raster] at the vertex. `gradients` (9 per mesh
// vertex: normal_gradients of these normals, footprint.h; null: footprints kept): Sample::footprint
// is computed again from them, as the gatherer computes it, where the gatherer computed one.
void reshade_chunk(SampleChunk &chunk, const MeshView &mesh, const float *normals, const uint8_t *changed,
                   const std::vector<Raster> &rasters, const std::vector<LightSource> &lights,
                   const GatherSettings &settings, const float *gradients = nullptr);

} // namespace vbrdf
