#pragma once
// Which vertices a photo's sample of a vertex averages, and with what weights. The sample at
// vertex v is the photo bilinearly interpolated at v's projection: a blend of a 2x2 block of
// pixels, each of which averages the surface inside it. Where the mesh is as fine as the pixels
// (or finer), that surface belongs to several vertices, so the sample is a weighted mean of their
// reflectances, not v's own:
//
//   sample(v) = sum_u W(v, u) rho(u),   sum_u W(v, u) = 1
//
// The albedo deconvolution (fit/albedo_deconvolution.h) inverts this to recover each vertex's own
// reflectance, and the relighting evaluation predicts a photo through the same weights.
//
// How W is found (per vertex and camera): each own-surface texel of the bilinear footprint
// (visibility.h: the camera pass's mask) is split into 4 x 4 subpixels carrying its bilinear weight;
// each subpixel takes the triangle nearest the camera among the triangles around v that cover it
// (the vertices within 3 pixels of v's projection, and always v's 1-ring, at most kMaxCandidateVertices),
// and spreads its weight over that triangle's corners by barycentric coordinates. Subpixels whose
// triangle lies off v's own surface (depth beyond own_surface_depth_slack, e.g. the ring folding
// behind a silhouette) or that no candidate covers are dropped and the rest renormalised. When
// nothing is left the row is v alone (weight 1).
#include <cstdint>
#include <vector>

#include "base/mesh_view.h"
#include "inputs/camera.h"
#include "samples/samples.h"

namespace vbrdf {

constexpr size_t kMaxCandidateVertices = 96;  // a bound on the work per row on very fine meshes

// Rows of W, compressed: row k is vertex row_vertex[k]'s sample in camera row_camera[k]; its
// entries are [offsets[k], offsets[k + 1]) of (entry_vertex, entry_weight), weights summing to 1.
// row_share[k]: the part of vertex row_vertex[k]'s samples taken in that camera (the photos of the
// camera that see and light it, over all such photos): the shares of one vertex's rows sum to 1.
// Rows are in vertex order, then camera order.
struct FootprintRows {
  std::vector<uint32_t> row_vertex, row_camera;
  std::vector<float> row_share;
  std::vector<uint32_t> offsets{0};
  std::vector<uint32_t> entry_vertex;
  std::vector<float> entry_weight;
  // camera_of_raster[r]: the camera (a run of photos with one registration, same_shot) of raster r
  // among those asked for; -1 for the rasters not asked for.
  std::vector<int32_t> camera_of_raster;
  size_t camera_count = 0;
  size_t rows() const { return row_vertex.size(); }
};

// The albedo-edge rule: colours whose per-channel ranges [low, high] differ, in some channel, by
// more than `contrast` times the brightest of them (the largest high; none positive: no edge).
bool spans_albedo_edge(const double low[3], const double high[3], double contrast);

// The rows of every vertex with wanted[v] != 0 (null: every vertex) seen and lit by at least one of
// the rasters `raster_indices` (indices into `rasters` and `masks`), one row per camera that sees it.
// `depth_tolerance`: the visibility passes' tolerance in world units (VisibilitySettings::
// depth_tolerance times the mesh's bounding-box diagonal). OpenMP over vertices; each camera
// projects every vertex once. Safeguards: out-of-range indices and degenerate (zero-area) triangles
// are skipped; a vertex behind the camera or whose footprint has no own texel gets no row.
// `edge` (optional): rows only where per-vertex colours `edge->rgb` (3 per vertex) span an albedo
// edge (spans_albedo_edge, edge->contrast) over the corners of the triangles the footprint may
// cover (a superset of its row's vertices, v included): the rows that can span an edge, without
// building the others (fit/albedo_deconvolution.h footprint_spans_an_edge then decides on the row).
struct EdgeFilter {
  const float *rgb = nullptr;
  float contrast = 0;
};
FootprintRows footprint_rows(const MeshView &mesh, const std::vector<Raster> &rasters, const VisibilityMasks &masks,
                             const std::vector<size_t> &raster_indices, const uint8_t *wanted, float depth_tolerance,
                             const EdgeFilter *edge = nullptr);

// sample(row) = sum over the row's entries of weight * rgb[entry]: what each row's photo sample
// shows of per-vertex reflectances `rgb` (3 per vertex). out: 3 per row.
void blur_through_footprints(const FootprintRows &rows, const float *rgb, float *out);

} // namespace vbrdf
