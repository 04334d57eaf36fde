#include "samples/reshade.h"

#include "base/vec3.h"
#include "inputs/camera.h"
#include "samples/footprint.h"

namespace vbrdf {

void shade_sample(const float n[3], const float l[3], const float e[3], DiffuseForm form, const GatherSettings &settings,
                  Sample &s) {
  const float d = dot3(n, l);
  const float r_dot_e = lobe_cosine(LobeForm::PhongRE, n, l, e);  // decides kHighlight whatever the form
  s.d = diffuse_factor(form, d, dot3(n, e));
  s.lobe_cos = settings.lobe == LobeForm::PhongRE ? r_dot_e : lobe_cosine(settings.lobe, n, l, e);
  uint16_t flags = uint16_t(s.flags & ~(kAttachedShadow | kGrazing | kHighlight));
  if (d <= 0) flags |= kAttachedShadow;
  if (d > 0 && d < settings.diffuse_threshold) flags |= kGrazing;
  if (d > 0 && r_dot_e > settings.specular_threshold) flags |= kHighlight;
  s.flags = flags & 0x3FFu;
}

void reshade_vertex(Sample *samples, size_t count, const float n[3], const float position[3], const float *centres,
                    const std::vector<LightSource> &lights, DiffuseForm form, const GatherSettings &settings) {
  for (size_t k = 0; k < count; ++k) {
    Sample &s = samples[k];
    const float *c = centres + 3 * size_t(s.raster);
    float e[3] = {c[0] - position[0], c[1] - position[1], c[2] - position[2]};
    normalize3(e);
    float l[3];
    light_direction_at(lights[s.raster], position, l);
    shade_sample(n, l, e, form, settings, s);
  }
}

void reshade_chunk(SampleChunk &chunk, const MeshView &mesh, const float *normals, const uint8_t *changed,
                   const std::vector<Raster> &rasters, const std::vector<LightSource> &lights,
                   const GatherSettings &settings, const float *gradients) {
  std::vector<float> centres(3 * rasters.size());
  for (size_t r = 0; r < rasters.size(); ++r) camera_centre(rasters[r].shot, &centres[3 * r]);
  const bool footprints = gradients && settings.footprint && settings.lobe == LobeForm::GgxNH;
  std::vector<FootprintCamera> cameras;
  if (footprints)
    for (const Raster &r : rasters) cameras.push_back(footprint_camera(r));
#pragma omp parallel for schedule(dynamic, 256)
  for (long long i = 0; i < (long long)chunk.vertex_count; ++i) {
    if (changed && !changed[i]) continue;
    const size_t v = chunk.first_vertex + size_t(i);
    float n[3] = {normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]};
    if (!(normalize3(n) > 0)) continue;
    const float *p = mesh.positions + 3 * v;
    Sample *samples = chunk.samples.data() + chunk.offsets[size_t(i)];
    const size_t count = chunk.offsets[size_t(i) + 1] - chunk.offsets[size_t(i)];
    reshade_vertex(samples, count, n, p, centres.data(), lights, settings.diffuse.at(v), settings);
    if (footprints)
      for (size_t k = 0; k < count; ++k)
        if (samples[k].footprint > 0)
          samples[k].footprint = footprint_variance(cameras[samples[k].raster], p, n, gradients + 9 * v);
  }
}

} // namespace vbrdf
