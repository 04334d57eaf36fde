#include "samples/footprint_weights.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/mesh_adjacency.h"
#include "visibility/visibility.h"

namespace vbrdf {
namespace {

constexpr float kCandidateRadiusPx = 3.0f;  // the footprint reaches 1.5 px from the projection, plus margin
constexpr int kSubpixels = 4;               // per axis and texel

// The triangles of every vertex, compressed (faces of v: face_of[offsets[v] .. offsets[v + 1])).
struct VertexFaces {
  std::vector<uint32_t> offsets, faces;
};

VertexFaces vertex_faces(const MeshView &mesh) {
  VertexFaces vf;
  const size_t n = mesh.vertex_count, n_faces = mesh.index_count / 3;
  vf.offsets.assign(n + 1, 0);
  auto valid = [&](size_t f) {
    const uint32_t *t = mesh.indices + 3 * f;
    return t[0] < n && t[1] < n && t[2] < n;
  };
  for (size_t f = 0; f < n_faces; ++f)
    if (valid(f))
      for (int k = 0; k < 3; ++k) ++vf.offsets[mesh.indices[3 * f + k] + 1];
  for (size_t v = 0; v < n; ++v) vf.offsets[v + 1] += vf.offsets[v];
  vf.faces.resize(vf.offsets[n]);
  std::vector<uint32_t> fill(vf.offsets.begin(), vf.offsets.end() - 1);
  for (size_t f = 0; f < n_faces; ++f)
    if (valid(f))
      for (int k = 0; k < 3; ++k) vf.faces[fill[mesh.indices[3 * f + k]]++] = uint32_t(f);
  return vf;
}

// Every vertex projected into one camera: image point and depth along the viewing axis.
struct Projection {
  std::vector<float> x, y, depth;
  std::vector<uint8_t> in_front;
};

Projection project_all(const MeshView &mesh, const Shot &shot) {
  Projection p;
  const size_t n = mesh.vertex_count;
  p.x.resize(n), p.y.resize(n), p.depth.resize(n), p.in_front.resize(n);
#pragma omp parallel for schedule(static)
  for (long long vi = 0; vi < (long long)n; ++vi) {
    const size_t v = size_t(vi);
    const ImagePoint ip = project_to_image(shot, mesh.positions + 3 * v);
    p.x[v] = ip.x, p.y[v] = ip.y, p.in_front[v] = ip.in_front;
    p.depth[v] = view_depth(shot, mesh.positions + 3 * v);
  }
  return p;
}

// A candidate triangle in image space: corners, depths, and the inverse of twice its signed area.
struct ImageTriangle {
  uint32_t corner[3];
  float x[3], y[3], depth[3];
  float inv_area;
};

struct Entry {
  uint32_t vertex;
  float weight;
};

void add_weight(std::vector<Entry> &entries, uint32_t vertex, float weight) {
  for (Entry &e : entries)
    if (e.vertex == vertex) {
      e.weight += weight;
      return;
    }
  entries.push_back({vertex, weight});
}

// The vertices around v whose triangles its footprint may cover (see the header).
void candidate_vertices(const MeshAdjacency &adj, const Projection &p, uint32_t v, std::vector<uint32_t> &vertices) {
  vertices.assign(1, v);
  const float r2 = kCandidateRadiusPx * kCandidateRadiusPx;
  for (size_t head = 0; head < vertices.size() && vertices.size() < kMaxCandidateVertices; ++head) {
    const uint32_t w = vertices[head];
    for (uint32_t k = adj.offsets[w]; k < adj.offsets[w + 1] && vertices.size() < kMaxCandidateVertices; ++k) {
      const uint32_t u = adj.neighbours[k];
      if (std::find(vertices.begin(), vertices.end(), u) != vertices.end()) continue;
      const float dx = p.x[u] - p.x[v], dy = p.y[u] - p.y[v];
      if (w == v || (p.in_front[u] && dx * dx + dy * dy <= r2)) vertices.push_back(u);  // the 1-ring always
    }
  }
}

// The triangles of `vertices`, in image space.
void candidate_triangles(const MeshView &mesh, const VertexFaces &vf, const Projection &p,
                         const std::vector<uint32_t> &vertices, std::vector<ImageTriangle> &out) {
  std::vector<uint32_t> faces;
  for (uint32_t w : vertices) faces.insert(faces.end(), vf.faces.begin() + vf.offsets[w], vf.faces.begin() + vf.offsets[w + 1]);
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  out.clear();
  for (uint32_t f : faces) {
    ImageTriangle t;
    bool ok = true;
    for (int k = 0; k < 3; ++k) {
      const uint32_t c = mesh.indices[3 * f + k];
      t.corner[k] = c, t.x[k] = p.x[c], t.y[k] = p.y[c], t.depth[k] = p.depth[c];
      ok = ok && p.in_front[c];
    }
    const float area2 = (t.x[1] - t.x[0]) * (t.y[2] - t.y[0]) - (t.x[2] - t.x[0]) * (t.y[1] - t.y[0]);
    if (!ok || !(std::fabs(area2) > 1e-9f)) continue;  // behind the camera, degenerate or edge-on
    t.inv_area = 1.0f / area2;
    out.push_back(t);
  }
}

// The row of vertex v in one camera: the entries, weights summing to 1. Each candidate triangle
// is rasterised over the footprint's 8 x 8 subpixels (those of its bounding box only); each
// subpixel keeps the nearest triangle covering it.
void footprint_row(const std::vector<ImageTriangle> &triangles, const Projection &p, uint32_t v, uint8_t own_texels,
                   float depth_slack, std::vector<Entry> &entries) {
  constexpr int kSide = 2 * kSubpixels;  // subpixels per axis over the 2 x 2 texels
  constexpr float kStep = 1.0f / kSubpixels;
  entries.clear();
  const float fx = p.x[v] - 0.5f, fy = p.y[v] - 0.5f;
  const float x0 = std::floor(fx), y0 = std::floor(fy), ax = fx - x0, ay = fy - y0;
  const float bilinear[4] = {(1 - ax) * (1 - ay), ax * (1 - ay), (1 - ax) * ay, ax * ay};
  float best_depth[kSide * kSide], best_b[kSide * kSide][3];
  const ImageTriangle *best[kSide * kSide];
  for (int i = 0; i < kSide * kSide; ++i) best_depth[i] = std::numeric_limits<float>::infinity(), best[i] = nullptr;
  for (const ImageTriangle &t : triangles) {
    const float min_x = std::min(t.x[0], std::min(t.x[1], t.x[2])), max_x = std::max(t.x[0], std::max(t.x[1], t.x[2]));
    const float min_y = std::min(t.y[0], std::min(t.y[1], t.y[2])), max_y = std::max(t.y[0], std::max(t.y[1], t.y[2]));
    // Subpixel centres x0 + (i + 0.5) kStep inside [min_x, max_x].
    const int i0 = std::max(0, int(std::ceil((min_x - x0) / kStep - 0.5f - 1e-4f)));
    const int i1 = std::min(kSide - 1, int(std::floor((max_x - x0) / kStep - 0.5f + 1e-4f)));
    const int j0 = std::max(0, int(std::ceil((min_y - y0) / kStep - 0.5f - 1e-4f)));
    const int j1 = std::min(kSide - 1, int(std::floor((max_y - y0) / kStep - 0.5f + 1e-4f)));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        if (!(own_texels & footprint_texel_bit((j / kSubpixels) * 2 + i / kSubpixels))) continue;
        const float px = x0 + (float(i) + 0.5f) * kStep, py = y0 + (float(j) + 0.5f) * kStep;
        const float b1 = ((px - t.x[0]) * (t.y[2] - t.y[0]) - (t.x[2] - t.x[0]) * (py - t.y[0])) * t.inv_area;
        const float b2 = ((t.x[1] - t.x[0]) * (py - t.y[0]) - (px - t.x[0]) * (t.y[1] - t.y[0])) * t.inv_area;
        const float b0 = 1 - b1 - b2;
        const float eps = -1e-5f;
        if (b0 < eps || b1 < eps || b2 < eps) continue;
        const float z = b0 * t.depth[0] + b1 * t.depth[1] + b2 * t.depth[2];
        const int s = j * kSide + i;
        if (z < best_depth[s]) best_depth[s] = z, best[s] = &t, best_b[s][0] = b0, best_b[s][1] = b1, best_b[s][2] = b2;
      }
  }
  float kept = 0;
  for (int s = 0; s < kSide * kSide; ++s) {
    // Nothing covers it, or what does is not v's surface (the ring folding behind a silhouette).
    if (!best[s] || !(std::fabs(best_depth[s] - p.depth[v]) <= depth_slack)) continue;
    const int texel = (s / kSide / kSubpixels) * 2 + (s % kSide) / kSubpixels;
    const float w = bilinear[texel] / float(kSubpixels * kSubpixels);
    if (!(w > 0)) continue;
    for (int c = 0; c < 3; ++c)
      if (best_b[s][c] > 0) add_weight(entries, best[s]->corner[c], w * best_b[s][c]);
    kept += w;
  }
  if (!(kept > 0)) {
    entries.assign(1, {v, 1.0f});
    return;
  }
  for (Entry &e : entries) e.weight /= kept;
}

// Per vertex, the range of `rgb` over it and its 1-ring (3 lows, then 3 highs): a triangle of a
// candidate vertex has its corners there, so the union over the candidates bounds a row's range.
std::vector<float> ring_ranges(const MeshAdjacency &adj, const float *rgb, size_t n) {
  std::vector<float> out(6 * n);
#pragma omp parallel for schedule(static)
  for (long long vi = 0; vi < (long long)n; ++vi) {
    const size_t v = size_t(vi);
    float *r = &out[6 * v];
    for (int c = 0; c < 3; ++c) r[c] = r[3 + c] = rgb[3 * v + size_t(c)];
    for (uint32_t k = adj.offsets[v]; k < adj.offsets[v + 1]; ++k)
      for (int c = 0; c < 3; ++c) {
        const float x = rgb[3 * size_t(adj.neighbours[k]) + size_t(c)];
        r[c] = std::min(r[c], x), r[3 + c] = std::max(r[3 + c], x);
      }
  }
  return out;
}

// Whether the ranges of `vertices` (ring_ranges) together exceed the contrast.
bool rings_span_contrast(const std::vector<uint32_t> &vertices, const std::vector<float> &ranges, float contrast) {
  double low[3] = {1e30, 1e30, 1e30}, high[3] = {-1e30, -1e30, -1e30};
  for (uint32_t u : vertices)
    for (int c = 0; c < 3; ++c)
      low[c] = std::min(low[c], double(ranges[6 * u + c])), high[c] = std::max(high[c], double(ranges[6 * u + 3 + c]));
  return spans_albedo_edge(low, high, contrast);
}

// Whether `rgb` over the triangles' corners (every vertex a row can hold) differs, in some channel,
// by more than contrast x the brightest.
bool spans_contrast(const std::vector<ImageTriangle> &triangles, const float *rgb, float contrast) {
  double low[3] = {1e30, 1e30, 1e30}, high[3] = {-1e30, -1e30, -1e30};
  for (const ImageTriangle &t : triangles)
    for (uint32_t u : t.corner)
      for (int c = 0; c < 3; ++c) low[c] = std::min(low[c], double(rgb[3 * u + c])), high[c] = std::max(high[c], double(rgb[3 * u + c]));
  return spans_albedo_edge(low, high, contrast);
}

} // namespace

FootprintRows footprint_rows(const MeshView &mesh, const std::vector<Raster> &rasters, const VisibilityMasks &masks,
                             const std::vector<size_t> &raster_indices, const uint8_t *wanted, float depth_tolerance,
                             const EdgeFilter *edge) {
  FootprintRows out;
  const size_t n = mesh.vertex_count;
  out.camera_of_raster.assign(rasters.size(), -1);
  // Cameras: the asked-for rasters grouped by registration (same_shot), each with its photos.
  std::vector<std::vector<size_t>> cameras;
  for (size_t r : raster_indices) {
    if (r >= rasters.size() || r >= masks.raster_count) continue;
    size_t c = 0;
    while (c < cameras.size() && !same_shot(rasters[cameras[c].front()].shot, rasters[r].shot)) ++c;
    if (c == cameras.size()) cameras.emplace_back();
    cameras[c].push_back(r);
    out.camera_of_raster[r] = int32_t(c);
  }
  out.camera_count = cameras.size();
  if (cameras.empty() || n == 0) return out;

  const MeshAdjacency adj = build_mesh_adjacency(mesh);
  const VertexFaces vf = vertex_faces(mesh);
  const std::vector<float> ranges = edge ? ring_ranges(adj, edge->rgb, n) : std::vector<float>();
  // Per camera: every vertex's count of seen-and-lit photos and its row (compressed, vertex order).
  struct CameraRows {
    std::vector<uint16_t> lit_count;
    std::vector<uint32_t> offsets;
    std::vector<Entry> entries;
  };
  std::vector<CameraRows> per_camera(cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c) {
    const Raster &camera = rasters[cameras[c].front()];
    const Projection p = project_all(mesh, camera.shot);
    const float focal_px = camera.shot.Intrinsics.FocalMm / camera.shot.Intrinsics.PixelSizeMm[0];
    CameraRows &cr = per_camera[c];
    cr.lit_count.assign(n, 0);
    std::vector<std::vector<Entry>> rows(n);
#pragma omp parallel
    {
      std::vector<uint32_t> vertices;
      std::vector<ImageTriangle> triangles;
#pragma omp for schedule(dynamic, 256)
      for (long long vi = 0; vi < (long long)n; ++vi) {
        const uint32_t v = uint32_t(vi);
        if ((wanted && !wanted[v]) || !p.in_front[v]) continue;
        uint32_t count = 0;
        for (size_t r : cameras[c]) count += masks.is_seen(r, v) && masks.is_lit(r, v);
        const uint8_t own = masks.own_texels(cameras[c].front(), v);
        if (count == 0 || own == 0) continue;
        candidate_vertices(adj, p, v, vertices);
        if (edge && !rings_span_contrast(vertices, ranges, edge->contrast)) continue;  // cheap bound first
        candidate_triangles(mesh, vf, p, vertices, triangles);
        if (edge && !spans_contrast(triangles, edge->rgb, edge->contrast)) continue;
        cr.lit_count[v] = uint16_t(std::min<uint32_t>(count, 65535u));
        footprint_row(triangles, p, v, own, own_surface_depth_slack(p.depth[v], focal_px, depth_tolerance), rows[v]);
      }
    }
    cr.offsets.assign(n + 1, 0);
    for (size_t v = 0; v < n; ++v) {
      cr.entries.insert(cr.entries.end(), rows[v].begin(), rows[v].end());
      cr.offsets[v + 1] = uint32_t(cr.entries.size());
      std::vector<Entry>().swap(rows[v]);
    }
  }
  for (uint32_t v = 0; v < n; ++v) {
    uint32_t total = 0;
    for (const CameraRows &cr : per_camera) total += cr.lit_count[v];
    for (size_t c = 0; c < cameras.size() && total > 0; ++c) {
      const CameraRows &cr = per_camera[c];
      if (cr.lit_count[v] == 0) continue;
      out.row_vertex.push_back(v);
      out.row_camera.push_back(uint32_t(c));
      out.row_share.push_back(float(cr.lit_count[v]) / float(total));
      for (uint32_t e = cr.offsets[v]; e < cr.offsets[v + 1]; ++e)
        out.entry_vertex.push_back(cr.entries[e].vertex), out.entry_weight.push_back(cr.entries[e].weight);
      out.offsets.push_back(uint32_t(out.entry_vertex.size()));
    }
  }
  return out;
}

bool spans_albedo_edge(const double low[3], const double high[3], double contrast) {
  const double top = std::max(high[0], std::max(high[1], high[2]));
  if (!(top > 0)) return false;
  for (int c = 0; c < 3; ++c)
    if (high[c] - low[c] > contrast * top) return true;
  return false;
}

void blur_through_footprints(const FootprintRows &rows, const float *rgb, float *out) {
#pragma omp parallel for schedule(static)
  for (long long k = 0; k < (long long)rows.rows(); ++k) {
    float sum[3] = {0, 0, 0};
    for (uint32_t e = rows.offsets[size_t(k)]; e < rows.offsets[size_t(k) + 1]; ++e)
      for (int c = 0; c < 3; ++c) sum[c] += rows.entry_weight[e] * rgb[3 * size_t(rows.entry_vertex[e]) + size_t(c)];
    for (int c = 0; c < 3; ++c) out[3 * size_t(k) + size_t(c)] = sum[c];
  }
}

} // namespace vbrdf
