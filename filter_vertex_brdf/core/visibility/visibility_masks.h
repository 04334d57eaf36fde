#pragma once
// Which vertex each photo sees and which its light reaches, for every photo: bit masks from the
// depth passes of a VisibilityBackend (2 bits per vertex and photo, plus the footprint lists of
// silhouettes and contacts). Every later stage (samples, registration, the fit's footprints,
// coverage) reads them; none runs a depth pass of its own.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "base/callbacks.h"  // ProgressFn
#include "base/mesh_view.h"
#include "inputs/camera.h"
#include "inputs/light_source.h"
#include "visibility/visibility.h"

namespace vbrdf {

// Per-photo, per-vertex bits from the depth passes: `seen` = inside the photo, front-facing and
// not occluded (the camera pass combined with the per-vertex frustum/facing test), `lit` = not in
// cast shadow, tested for the vertices the photo sees only (the others read as lit). Per-photo
// counts say why vertices were not seen.
struct VisibilityMasks {
  size_t vertex_count = 0;
  size_t raster_count = 0;
  std::vector<uint64_t> seen;  // raster-major: word (r * words() + v / 64), bit v % 64
  std::vector<uint64_t> lit;
  std::vector<uint64_t> mixed;  // seen, but the pixel footprint straddles a depth jump
  // Per raster, for its mixed vertices only, sorted: (v << 4) | mask of the footprint texels on the
  // vertex's own surface (visibility.h). Sparse: only rims and contacts are listed.
  std::vector<std::vector<uint32_t>> footprints;
  std::vector<uint32_t> off_image, back_facing, occluded, seen_count;  // per raster
  size_t camera_passes = 0;  // camera passes run: one per run of rasters with the same shot
  size_t words() const { return (vertex_count + 63) / 64; }
  bool is_seen(size_t r, size_t v) const { return (seen[r * words() + v / 64] >> (v % 64)) & 1u; }
  bool is_lit(size_t r, size_t v) const { return (lit[r * words() + v / 64] >> (v % 64)) & 1u; }
  bool is_mixed(size_t r, size_t v) const { return (mixed[r * words() + v / 64] >> (v % 64)) & 1u; }
  // Own-surface texels of the footprint of vertex v in raster r: kAllFootprintTexels unless mixed.
  uint8_t own_texels(size_t r, size_t v) const;
  // True when raster r sees at least one vertex in [first, first + count).
  bool sees_any(size_t r, size_t first, size_t count) const;
};

// Runs the camera and light depth passes for every raster. lights[r] is the light of raster r.
// A raster whose shot is the previous camera pass's (same_shot) reuses that pass's codes.
VisibilityMasks compute_visibility(const MeshView &mesh, const std::vector<Raster> &rasters,
                                   const std::vector<LightSource> &lights,
                                   VisibilityBackend &backend, const ProgressFn &progress = {});

// "Only on selection": clears the seen, lit and mixed bits of every vertex with vertex_mask[v] == 0,
// so that no stage samples it (it reads as seen by no photo), and recounts seen_count. An empty
// mask keeps every vertex. Throws InputError when the mask's size is not the vertex count.
void restrict_to_vertices(VisibilityMasks &masks, const std::vector<uint8_t> &vertex_mask);

// A pilot's subsample: every k-th vertex with eligible[v] != 0, in vertex order, k chosen for about
// `target` of them (all when fewer). Returns the mask for restrict_to_vertices; count = how many.
std::vector<uint8_t> every_kth_vertex(const std::vector<uint8_t> &eligible, size_t target, size_t &count);

// Photos of one camera (same shot and photo size) see the same vertices at the same image points.
bool same_view(const Raster &a, const Raster &b);

} // namespace vbrdf
