#include "samples/samples.h"
#include "samples/reshade.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include "base/errors.h"
#include "base/vec3.h"
#include "samples/footprint.h"

namespace vbrdf {

namespace {

void report(const ProgressFn &progress, float fraction, const char *stage) {
  if (progress && !progress(std::min(std::max(fraction, 0.0f), 1.0f), stage))
    throw ProcessingError("cancelled by the user");
}

int bit_index(uint16_t flag) {
  int i = 0;
  while (flag > 1) flag >>= 1, ++i;
  return i;
}

// The vertices of [first, first + count) that at least one photo sees, as offsets from `first`,
// in order.
std::vector<uint32_t> seen_by_any(const VisibilityMasks &masks, size_t first, size_t count) {
  std::vector<uint32_t> active;
  const size_t words = masks.words(), end = first + count, rasters = words ? masks.seen.size() / words : 0;
  for (size_t w = first / 64; w * 64 < end; ++w) {
    uint64_t any = 0;
    for (size_t r = 0; r < rasters; ++r) any |= masks.seen[r * words + w];
    for (; any; any &= any - 1) {
      const size_t v = w * 64 + size_t(__builtin_ctzll(any));
      if (v >= first && v < end) active.push_back(uint32_t(v - first));
    }
  }
  return active;
}
} // namespace

uint16_t make_sample(const float position[3], const float normal_in[3], const Raster &raster, uint16_t raster_index,
                     const LightSource &light, const Photo &photo, bool camera_clear, bool light_clear,
                     const GatherSettings &settings, Sample &out, uint8_t own_texels, const ImagePoint *projected) {
  out = Sample{{0, 0, 0}, 0, 0, raster_index, 0, 0};
  float n[3] = {normal_in[0], normal_in[1], normal_in[2]};
  normalize3(n);
  float centre[3];
  camera_centre(raster.shot, centre);
  float e[3] = {centre[0] - position[0], centre[1] - position[1], centre[2] - position[2]};
  normalize3(e);

  uint16_t flags = 0;
  const ImagePoint ip = projected ? *projected : project_to_image(raster.shot, position);
  if (!ip.in_front || !(ip.x >= 0 && ip.y >= 0 && ip.x < float(raster.width()) && ip.y < float(raster.height())))
    flags |= kOffImage;
  if (dot3(n, e) <= 0) flags |= kBackFacing;
  if (!camera_clear) flags |= kOccluded;

  float light_dir[3];
  light_direction_at(light, position, light_dir);
  shade_sample(n, light_dir, e, settings.diffuse.uniform, settings, out);  // d, lobe_cos, shading flags
  flags |= out.flags;
  if (!light_clear) flags |= kCastShadow;

  if (!(flags & kNotSeen)) {
    own_texels &= kAllFootprintTexels;
    const bool partial = own_texels != kAllFootprintTexels;
    const bool own_only = partial && settings.own_surface_texels && own_texels != 0;
    if (partial) flags |= own_only ? kRimFootprint : kMixedPixel;
    const PixelSample px = sample_bilinear(photo, ip.x, ip.y, own_only ? own_texels : kAllFootprintTexels);
    if (!px.inside) flags |= kOffImage;  // not on the photo (or no footprint texel kept)
    if (px.saturated) flags |= kSaturated;
    for (int c = 0; c < 3; ++c) out.rgb[c] = px.rgb[c];
  }
  out.flags = flags & 0x3FFu;
  return flags;
}

float photo_resolution(const Raster &raster, const float position[3], const float n[3]) {
  float centre[3];
  camera_centre(raster.shot, centre);
  const float e[3] = {centre[0] - position[0], centre[1] - position[1], centre[2] - position[2]};
  const float dist2 = dot3(e, e);
  const float nl = std::sqrt(dot3(n, n));
  if (!(dist2 > 0) || !(nl > 0)) return 0.0f;
  const float ne = dot3(n, e) / (nl * std::sqrt(dist2));
  if (!(ne > 0)) return 0.0f;
  const float f = raster.shot.Intrinsics.FocalMm / raster.shot.Intrinsics.PixelSizeMm[0];
  return f * f / dist2 * ne;
}

namespace {
// What Sample::footprint needs (footprint.h): the mesh's normal gradients (null: footprints off, or
// no GGX lobe) and one FootprintCamera per distinct camera, camera_of[raster] (an RTI capture: one).
struct FootprintSetup {
  std::shared_ptr<const std::vector<float>> gradients;
  std::vector<FootprintCamera> cameras;
  std::vector<uint32_t> camera_of;
};

FootprintSetup footprint_setup(const MeshView &mesh, const std::vector<Raster> &rasters, const GatherSettings &settings) {
  FootprintSetup f;
  if (!settings.footprint || settings.lobe != LobeForm::GgxNH) return f;  // it matters to the GGX lobe only
  f.gradients = settings.normal_gradients;
  if (!f.gradients || f.gradients->size() != 9 * mesh.vertex_count)
    f.gradients = std::make_shared<const std::vector<float>>(normal_gradients(mesh));
  f.camera_of.assign(rasters.size(), 0);
  for (size_t r = 0; r < rasters.size(); ++r) {
    if (r > 0 && same_view(rasters[r], rasters[r - 1])) {
      f.camera_of[r] = f.camera_of[r - 1];
      continue;
    }
    f.camera_of[r] = uint32_t(f.cameras.size());
    f.cameras.push_back(footprint_camera(rasters[r]));
  }
  return f;
}

// The samples of each active vertex, in its slots [slot_begin[a], slot_begin[a + 1]): drops those
// that make_sample found not seen (moved to the front of the range, raster order kept; kept[a] =
// how many stay), sets each kept sample's resolution code against the vertex's best photo (0 for
// all without `resolution_weights`), and adds the kept samples' flags and photos to `stats`.
void finish_vertex_samples(std::vector<Sample> &samples, const std::vector<uint32_t> &slot_begin,
                           std::vector<uint32_t> &kept, const std::vector<Raster> &rasters, const MeshView &mesh,
                           size_t first, const std::vector<uint32_t> &active, bool resolution_weights,
                           const FootprintSetup &footprints, GatherStats &stats) {
#pragma omp parallel
  {
    uint64_t flag_counts[16] = {};
    std::vector<uint32_t> seen_vertices(rasters.size(), 0);
    std::vector<float> resolution(rasters.size(), 0.0f);
#pragma omp for schedule(dynamic, 1024)
    for (long long a = 0; a < (long long)active.size(); ++a) {
      Sample *begin = samples.data() + slot_begin[size_t(a)], *end = samples.data() + slot_begin[size_t(a) + 1];
      Sample *last = std::remove_if(begin, end, [](const Sample &s) { return (s.flags & kNotSeen) != 0; });
      kept[size_t(a)] = uint32_t(last - begin);
      const size_t v = first + active[size_t(a)];
      float best = 0;
      if (resolution_weights)
        for (const Sample *s = begin; s != last; ++s)
          best = std::max(best, resolution[s->raster] = photo_resolution(rasters[s->raster], mesh.positions + 3 * v,
                                                                           mesh.normals + 3 * v));
      uint32_t footprint_camera_index = UINT32_MAX;  // the photos of one camera share the footprint
      float footprint = 0.0f;
      for (Sample *s = begin; s != last; ++s) {
        for (uint16_t f = s->flags; f; f &= uint16_t(f - 1)) ++flag_counts[bit_index(uint16_t(f & -f))];
        s->resolution = best > 0 ? resolution_code(resolution[s->raster] / best) : 0;
        if (footprints.gradients && footprints.camera_of[s->raster] != footprint_camera_index) {
          footprint_camera_index = footprints.camera_of[s->raster];
          footprint = footprint_variance(footprints.cameras[footprint_camera_index], mesh.positions + 3 * v,
                                         mesh.normals + 3 * v, footprints.gradients->data() + 9 * v);
        }
        s->footprint = footprint;
        ++seen_vertices[s->raster];
      }
    }
#pragma omp critical(vbrdf_gather_stats)
    {
      for (int b = 0; b < 16; ++b) stats.flag_counts[b] += flag_counts[b];
      for (size_t r = 0; r < rasters.size(); ++r) stats.raster_seen_vertices[r] += seen_vertices[r];
    }
  }
}
} // namespace

GatherStats gather_samples(const MeshView &mesh, const std::vector<Raster> &rasters,
                           const std::vector<LightSource> &lights, const VisibilityMasks &masks,
                           const GatherSettings &settings, PhotoCache &photos,
                           const std::function<void(SampleChunk &)> &consume, const ProgressFn &progress) {
  const auto start = std::chrono::steady_clock::now();
  if (rasters.size() > 65535) throw InputError("More than 65535 photos in one project are not supported.");
  GatherStats stats;
  stats.raster_seen_vertices.assign(rasters.size(), 0);
  // The diffuse form per vertex (make_sample reads the uniform one): one settings copy per form.
  GatherSettings as_lambert = settings, as_coated = settings;
  as_lambert.diffuse = DiffuseForms::everywhere(DiffuseForm::Lambert);
  as_coated.diffuse = DiffuseForms::everywhere(DiffuseForm::Coated);
  const auto settings_of_vertex = [&](size_t v) -> const GatherSettings & {
    if (!settings.diffuse.varies()) return settings;
    return settings.diffuse.at(v) == DiffuseForm::Coated ? as_coated : as_lambert;
  };
  const size_t raster_count = std::max<size_t>(rasters.size(), 1);
  const FootprintSetup footprints = footprint_setup(mesh, rasters, settings);
  // Chunks are sized as a dense vertices x rasters block of samples would fit the budget (the
  // samples stored are at most that).
  const size_t chunk_vertices = std::max<size_t>(
      1024, settings.chunk_sample_bytes / (sizeof(Sample) * raster_count));
  SampleChunk chunk;
  std::vector<uint32_t> slot_begin;  // per active vertex: its first slot in chunk.samples
  std::vector<uint16_t> filled;      // per active vertex: slots written so far (rasters in order)
  // Where the chunk's vertices fall in the photo: the same for every photo of one camera (an RTI
  // capture: one projection per vertex instead of one per vertex and photo).
  std::vector<ImagePoint> projected;
  const Raster *projected_for = nullptr;

  for (size_t first = 0; first < mesh.vertex_count; first += chunk_vertices) {
    const size_t count = std::min(chunk_vertices, mesh.vertex_count - first);
    // Only the vertices some photo sees get slots (a restricted mask, e.g. the diffuse-form
    // pilot's 3 % of the mesh, or the far side of an object, costs nothing here), one slot per
    // photo that the masks say sees the vertex, written in place: no dense vertices x photos block
    // to zero, fill and copy out (at 1 M vertices x 24 photos it was 300 MB of fresh pages).
    const std::vector<uint32_t> active = seen_by_any(masks, first, count);
    slot_begin.assign(active.size() + 1, 0);
#pragma omp parallel for schedule(static)
    for (long long a = 0; a < (long long)active.size(); ++a) {
      uint32_t seen = 0;
      for (size_t r = 0; r < rasters.size(); ++r) seen += masks.is_seen(r, first + active[size_t(a)]);
      slot_begin[size_t(a) + 1] = seen;
    }
    for (size_t a = 0; a < active.size(); ++a) slot_begin[a + 1] += slot_begin[a];
    chunk.samples.resize(slot_begin[active.size()]);  // the capacity stays for the next chunk
    filled.assign(active.size(), 0);
    projected_for = nullptr;
    for (size_t r = 0; r < rasters.size(); ++r) {
      report(progress, (float(first) + float(count) * float(r) / float(raster_count)) / float(mesh.vertex_count),
             "gathering samples");
      const Raster &raster = rasters[r];
      if (!masks.sees_any(r, first, count)) {  // skip: do not even load the photo
        ++stats.rasters_skipped;
        continue;
      }
      const auto photo = photos.get(raster.image_path, raster.width(), raster.height());
      const LightSource &light = lights[r];
      if (!projected_for || !same_view(*projected_for, raster)) {
        projected.resize(active.size());
#pragma omp parallel for schedule(static)
        for (long long a = 0; a < (long long)active.size(); ++a)
          projected[size_t(a)] = project_to_image(raster.shot, mesh.positions + 3 * (first + active[size_t(a)]));
        projected_for = &raster;
      }
#pragma omp parallel for schedule(dynamic, 1024)
      for (long long a = 0; a < (long long)active.size(); ++a) {
        const size_t v = first + active[size_t(a)];
        if (!masks.is_seen(r, v)) continue;  // not seen: no slot (why is counted by the visibility pass)
        Sample &out = chunk.samples[slot_begin[size_t(a)] + filled[size_t(a)]++];
        make_sample(mesh.positions + 3 * v, mesh.normals + 3 * v, raster, uint16_t(r), light, *photo, true,
                    masks.is_lit(r, v), settings_of_vertex(v), out, masks.own_texels(r, v), &projected[size_t(a)]);
      }
    }
    std::vector<uint32_t> kept(active.size());
    finish_vertex_samples(chunk.samples, slot_begin, kept, rasters, mesh, first, active, settings.resolution_weights,
                          footprints, stats);
    // Offsets over the chunk's vertices (no samples for those no photo sees); samples that the
    // footprint put off the photo leave gaps, closed in vertex order (rare: photo borders).
    chunk.first_vertex = uint32_t(first);
    chunk.vertex_count = uint32_t(count);
    chunk.offsets.assign(count + 1, 0);
    for (size_t a = 0, i = 0; i < count; ++i) {
      chunk.offsets[i + 1] = chunk.offsets[i];
      if (a == active.size() || active[a] != i) continue;
      const uint32_t to = chunk.offsets[i];
      if (to != slot_begin[a] && kept[a] > 0)
        std::memmove(chunk.samples.data() + to, chunk.samples.data() + slot_begin[a], kept[a] * sizeof(Sample));
      chunk.offsets[i + 1] = to + kept[a];
      ++a;
    }
    chunk.samples.resize(chunk.offsets[count]);
    stats.stored += chunk.samples.size();
    ++stats.chunks;
    consume(chunk);
  }
  report(progress, 1.0f, "gathering samples");
  stats.pairs = uint64_t(mesh.vertex_count) * rasters.size();
  for (size_t r = 0; r < rasters.size(); ++r) {
    stats.flag_counts[bit_index(kOffImage)] += masks.off_image[r];
    stats.flag_counts[bit_index(kBackFacing)] += masks.back_facing[r];
    stats.flag_counts[bit_index(kOccluded)] += masks.occluded[r];
  }
  stats.photo_loads = photos.loads();
  stats.host_photo_reads = photos.host_reads();
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

void apply_light_falloff(SampleChunk &chunk, const MeshView &mesh, const std::vector<LightSource> &lights) {
  if (!any_positional(lights)) return;
#pragma omp parallel for schedule(dynamic, 1024)
  for (long long i = 0; i < (long long)chunk.vertex_count; ++i) {
    const float *x = mesh.positions + 3 * (size_t(chunk.first_vertex) + size_t(i));
    for (uint32_t k = chunk.offsets[size_t(i)]; k < chunk.offsets[size_t(i) + 1]; ++k) {
      Sample &s = chunk.samples[k];
      const float e = light_irradiance_at(lights[s.raster], x);
      for (float &c : s.rgb) c /= e;
    }
  }
}

size_t prefer_clean_samples(SampleChunk &chunk, int min_clean) {
  size_t demoted = 0;
#pragma omp parallel for reduction(+ : demoted) schedule(dynamic, 1024)
  for (long long i = 0; i < (long long)chunk.vertex_count; ++i) {
    Sample *first = chunk.samples.data() + chunk.offsets[size_t(i)];
    Sample *last = chunk.samples.data() + chunk.offsets[size_t(i) + 1];
    int clean = 0;
    for (const Sample *s = first; s != last; ++s) clean += is_diffuse_sample(*s) && !(s->flags & kRimFootprint);
    if (clean < min_clean) continue;
    for (Sample *s = first; s != last; ++s)
      if (s->flags & kRimFootprint) s->flags |= kMixedPixel, ++demoted;
  }
  return demoted;
}

} // namespace vbrdf
