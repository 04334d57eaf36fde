#include "visibility/visibility_masks.h"

#include <algorithm>

#include "base/errors.h"
#include "base/vec3.h"

namespace vbrdf {

namespace {

void report(const ProgressFn &progress, float fraction, const char *stage) {
  if (progress && !progress(std::min(std::max(fraction, 0.0f), 1.0f), stage))
    throw ProcessingError("cancelled by the user");
}

void pack_bits(const std::vector<uint8_t> &flags, uint64_t *words) {
  for (size_t v = 0; v < flags.size(); ++v)
    if (flags[v]) words[v / 64] |= uint64_t(1) << (v % 64);
}

} // namespace

bool same_view(const Raster &a, const Raster &b) {
  return same_shot(a.shot, b.shot) && a.width() == b.width() && a.height() == b.height();
}

bool VisibilityMasks::sees_any(size_t r, size_t first, size_t count) const {
  if (count == 0) return false;
  const uint64_t *w = &seen[r * words()];
  const size_t last = first + count - 1;
  for (size_t i = first / 64; i <= last / 64; ++i) {
    uint64_t bits = w[i];
    if (i == first / 64) bits &= ~uint64_t(0) << (first % 64);
    if (i == last / 64 && last % 64 != 63) bits &= (uint64_t(1) << (last % 64 + 1)) - 1;
    if (bits) return true;
  }
  return false;
}

uint8_t VisibilityMasks::own_texels(size_t r, size_t v) const {
  if (!is_mixed(r, v)) return kAllFootprintTexels;
  if (r >= footprints.size()) return 0;  // masks built without footprint lists: nothing known
  const std::vector<uint32_t> &list = footprints[r];
  const auto it = std::lower_bound(list.begin(), list.end(), uint32_t(v) << 4);
  return (it != list.end() && (*it >> 4) == v) ? uint8_t(*it & 0xFu) : uint8_t(0);
}

namespace {
// Combines the camera pass with the per-vertex frustum and facing tests into `seen`, counting why
// vertices are not seen (off image first, then back-facing, then occluded).
void classify_seen(const MeshView &mesh, const Raster &raster, const std::vector<uint8_t> &clear, uint64_t *seen_words,
                   uint64_t *mixed_words, uint32_t counts[4]) {
  float centre[3];
  camera_centre(raster.shot, centre);
  uint64_t off = 0, back = 0, occ = 0, seen = 0;
  const long long words = (long long)((mesh.vertex_count + 63) / 64);
#pragma omp parallel for reduction(+ : off, back, occ, seen) schedule(static)
  for (long long w = 0; w < words; ++w) {
    uint64_t bits = 0, mixed_bits = 0;
    const size_t end = std::min(mesh.vertex_count, size_t(w + 1) * 64);
    for (size_t v = size_t(w) * 64; v < end; ++v) {
      const float *p = mesh.positions + 3 * v, *n = mesh.normals + 3 * v;
      const ImagePoint ip = project_to_image(raster.shot, p);
      if (!ip.in_front || !(ip.x >= 0 && ip.y >= 0 && ip.x < float(raster.width()) && ip.y < float(raster.height()))) {
        ++off;
        continue;
      }
      const float e[3] = {centre[0] - p[0], centre[1] - p[1], centre[2] - p[2]};
      if (dot3(n, e) <= 0) {
        ++back;
        continue;
      }
      if (!clear[v]) {
        ++occ;
        continue;
      }
      bits |= uint64_t(1) << (v % 64);
      if (clear[v] & kFootprintPartial) mixed_bits |= uint64_t(1) << (v % 64);
      ++seen;
    }
    seen_words[w] = bits;
    mixed_words[w] = mixed_bits;
  }
  counts[0] = uint32_t(off), counts[1] = uint32_t(back), counts[2] = uint32_t(occ), counts[3] = uint32_t(seen);
}

// The sorted (v << 4 | own-texel mask) list of the vertices marked in `mixed_words`.
std::vector<uint32_t> footprint_list(const std::vector<uint8_t> &clear, const uint64_t *mixed_words, size_t words) {
  std::vector<uint32_t> list;
  for (size_t w = 0; w < words; ++w)
    for (uint64_t bits = mixed_words[w]; bits; bits &= bits - 1) {
      const size_t v = w * 64 + size_t(__builtin_ctzll(bits));
      list.push_back(uint32_t(v) << 4 | (clear[v] & 0xFu));
    }
  return list;
}
} // namespace

VisibilityMasks compute_visibility(const MeshView &mesh, const std::vector<Raster> &rasters,
                                   const std::vector<LightSource> &lights,
                                   VisibilityBackend &backend, const ProgressFn &progress) {
  VisibilityMasks masks;
  masks.vertex_count = mesh.vertex_count;
  masks.raster_count = rasters.size();
  masks.seen.assign(masks.words() * rasters.size(), 0);
  masks.lit.assign(masks.words() * rasters.size(), 0);
  masks.mixed.assign(masks.words() * rasters.size(), 0);
  masks.footprints.assign(rasters.size(), {});
  if (mesh.vertex_count >= (size_t(1) << 28))
    throw InputError("Meshes of more than 268 million vertices are not supported.");
  for (auto *v : {&masks.off_image, &masks.back_facing, &masks.occluded, &masks.seen_count}) v->assign(rasters.size(), 0);
  // The camera pass depends on the shot only: photos from the camera of the previous pass (an RTI
  // capture: one camera, many lights) reuse its codes (same_shot: equal to 1e-6 relative).
  std::vector<uint8_t> camera(mesh.vertex_count), buffer(mesh.vertex_count);
  const Shot *camera_shot = nullptr;
  const size_t words = masks.words();
  for (size_t r = 0; r < rasters.size(); ++r) {
    report(progress, float(r) / float(rasters.size()), "visibility");
    bool new_camera = false;
    if (!camera_shot || !same_shot(*camera_shot, rasters[r].shot)) {
      std::fill(camera.begin(), camera.end(), 0);
      backend.camera_pass(rasters[r].shot, camera.data());
      camera_shot = &rasters[r].shot;
      ++masks.camera_passes;
      new_camera = true;
    }
    // What the camera sees depends on its shot and photo size only: a photo of the previous
    // photo's camera copies its classification (no projection of every vertex again, and no
    // OpenMP region, whose idle workers spin, between two shadow passes).
    if (!new_camera && same_view(rasters[r], rasters[r - 1])) {
      std::copy_n(&masks.seen[(r - 1) * words], words, &masks.seen[r * words]);
      std::copy_n(&masks.mixed[(r - 1) * words], words, &masks.mixed[r * words]);
      masks.off_image[r] = masks.off_image[r - 1], masks.back_facing[r] = masks.back_facing[r - 1];
      masks.occluded[r] = masks.occluded[r - 1], masks.seen_count[r] = masks.seen_count[r - 1];
      masks.footprints[r] = masks.footprints[r - 1];
    } else {
      uint32_t counts[4];
      classify_seen(mesh, rasters[r], camera, &masks.seen[r * words], &masks.mixed[r * words], counts);
      masks.off_image[r] = counts[0], masks.back_facing[r] = counts[1], masks.occluded[r] = counts[2];
      masks.seen_count[r] = counts[3];
      masks.footprints[r] = footprint_list(camera, &masks.mixed[r * words], words);
    }
    if (masks.seen_count[r] == 0) continue;  // a photo that sees nothing needs no shadow pass
    std::fill(buffer.begin(), buffer.end(), 0);
    // Shadow tests for the vertices this photo sees only (the others' lit bits are never read).
    backend.light_pass(lights[r], buffer.data(), &masks.seen[r * words]);
    pack_bits(buffer, &masks.lit[r * words]);
  }
  report(progress, 1.0f, "visibility");
  return masks;
}

void restrict_to_vertices(VisibilityMasks &masks, const std::vector<uint8_t> &vertex_mask) {
  if (vertex_mask.empty()) return;
  if (vertex_mask.size() != masks.vertex_count)
    throw InputError("internal: vertex mask of " + std::to_string(vertex_mask.size()) + " entries for " +
                     std::to_string(masks.vertex_count) + " vertices");
  const size_t words = masks.words();
  std::vector<uint64_t> keep(words, 0);
  for (size_t v = 0; v < vertex_mask.size(); ++v)
    if (vertex_mask[v]) keep[v / 64] |= uint64_t(1) << (v % 64);
  for (size_t r = 0; r < masks.raster_count; ++r) {
    uint32_t seen = 0;
    for (size_t w = 0; w < words; ++w) {
      for (std::vector<uint64_t> *bits : {&masks.seen, &masks.lit, &masks.mixed})
        if (bits->size() == masks.raster_count * words) (*bits)[r * words + w] &= keep[w];
      seen += uint32_t(__builtin_popcountll(masks.seen[r * words + w]));
    }
    if (r < masks.seen_count.size()) masks.seen_count[r] = seen;
  }
}

std::vector<uint8_t> every_kth_vertex(const std::vector<uint8_t> &eligible, size_t target, size_t &count) {
  size_t eligible_count = 0;
  for (uint8_t e : eligible) eligible_count += e != 0;
  const size_t step = std::max<size_t>(1, eligible_count / std::max<size_t>(1, target));
  std::vector<uint8_t> keep(eligible.size(), 0);
  count = 0;
  for (size_t v = 0, k = 0; v < eligible.size(); ++v)
    if (eligible[v] && k++ % step == 0) keep[v] = 1, ++count;
  return keep;
}

} // namespace vbrdf
