#include "bench_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <unordered_map>

#include <vcg/complex/complex.h>
#include <vcg/complex/algorithms/clean.h>
#include <vcg/complex/algorithms/local_optimization.h>
#include <vcg/complex/algorithms/local_optimization/tri_edge_collapse_quadric.h>
#include <vcg/complex/algorithms/update/normal.h>
#include <vcg/complex/algorithms/update/topology.h>
#include <vcg/complex/algorithms/closest.h>
#include <vcg/complex/algorithms/update/bounding.h>
#include <vcg/space/index/grid_static_ptr.h>

namespace vbrdf {
namespace bench {

namespace {

class DVertex;
class DEdge;
class DFace;
struct DTypes : public vcg::UsedTypes<vcg::Use<DVertex>::AsVertexType, vcg::Use<DEdge>::AsEdgeType,
                                      vcg::Use<DFace>::AsFaceType> {};
class DVertex : public vcg::Vertex<DTypes, vcg::vertex::VFAdj, vcg::vertex::Coord3f, vcg::vertex::Normal3f,
                                   vcg::vertex::Mark, vcg::vertex::Qualityf, vcg::vertex::BitFlags> {
public:
  vcg::math::Quadric<double> &Qd() { return q; }

private:
  vcg::math::Quadric<double> q;
};
class DEdge : public vcg::Edge<DTypes> {};
class DFace : public vcg::Face<DTypes, vcg::face::VFAdj, vcg::face::VertexRef, vcg::face::Normal3f,
                               vcg::face::BitFlags> {};
class DMesh : public vcg::tri::TriMesh<std::vector<DVertex>, std::vector<DFace>> {};

typedef vcg::tri::BasicVertexPair<DVertex> VertexPair;
class Collapse : public vcg::tri::TriEdgeCollapseQuadric<DMesh, VertexPair, Collapse, vcg::tri::QInfoStandard<DVertex>> {
public:
  typedef vcg::tri::TriEdgeCollapseQuadric<DMesh, VertexPair, Collapse, vcg::tri::QInfoStandard<DVertex>> TECQ;
  Collapse(const VertexPair &p, int i, vcg::BaseParameterClass *pp) : TECQ(p, i, pp) {}
};

void to_vcg(const MeshData &in, DMesh &m) {
  const size_t nv = in.positions.size() / 3, nf = in.indices.size() / 3;
  auto vi = vcg::tri::Allocator<DMesh>::AddVertices(m, nv);
  for (size_t v = 0; v < nv; ++v, ++vi) vi->P() = vcg::Point3f(&in.positions[3 * v]);
  auto fi = vcg::tri::Allocator<DMesh>::AddFaces(m, nf);
  for (size_t f = 0; f < nf; ++f, ++fi)
    for (int k = 0; k < 3; ++k) fi->V(k) = &m.vert[in.indices[3 * f + size_t(k)]];
}

// The surface a point is projected onto: faces with the normals and marks vcglib's closest-point
// query wants.
class SVertex;
class SFace;
struct STypes : public vcg::UsedTypes<vcg::Use<SVertex>::AsVertexType, vcg::Use<SFace>::AsFaceType> {};
class SVertex : public vcg::Vertex<STypes, vcg::vertex::Coord3f, vcg::vertex::Normal3f, vcg::vertex::BitFlags> {};
class SFace : public vcg::Face<STypes, vcg::face::VertexRef, vcg::face::Normal3f, vcg::face::Mark,
                               vcg::face::BitFlags> {};
class SMesh : public vcg::tri::TriMesh<std::vector<SVertex>, std::vector<SFace>> {};

MeshData from_vcg(DMesh &m) {
  vcg::tri::Allocator<DMesh>::CompactEveryVector(m);
  vcg::tri::UpdateNormal<DMesh>::PerVertexNormalizedPerFace(m);
  MeshData out;
  for (const DVertex &v : m.vert)
    for (int k = 0; k < 3; ++k) {
      out.positions.push_back(v.cP()[k]);
      out.normals.push_back(v.cN()[k]);
    }
  for (const DFace &f : m.face)
    for (int k = 0; k < 3; ++k) out.indices.push_back(uint32_t(vcg::tri::Index(m, f.cV(k))));
  return out;
}

} // namespace

MeshData decimate(const MeshData &in, size_t target_vertices) {
  const size_t nv = in.positions.size() / 3;
  if (nv <= target_vertices) return in;
  DMesh m;
  to_vcg(in, m);
  vcg::tri::Clean<DMesh>::RemoveUnreferencedVertex(m);
  vcg::tri::Allocator<DMesh>::CompactEveryVector(m);
  vcg::tri::UpdateTopology<DMesh>::VertexFace(m);
  vcg::tri::UpdateFlags<DMesh>::FaceBorderFromVF(m);
  vcg::tri::UpdateBounding<DMesh>::Box(m);

  vcg::tri::TriEdgeCollapseQuadricParameter pp;
  pp.QualityThr = 0.3;
  pp.PreserveBoundary = false;
  pp.FastPreserveBoundary = true;  // as MeshLab's filter does for "preserve boundary"
  pp.NormalCheck = true;
  pp.NormalThrRad = M_PI / 4.0;
  pp.OptimalPlacement = true;
  vcg::LocalOptimization<DMesh> session(m, &pp);
  session.Init<Collapse>();
  // The session's goal is a face count: aim it at the input's face/vertex ratio and lower it while
  // vertices remain above the target (borders keep the ratio below 2). Stops when the heap is empty.
  double faces = double(target_vertices) * double(m.fn) / double(std::max(1, m.vn));
  while (size_t(m.vn) > target_vertices) {
    session.SetTargetSimplices(std::max(1, int(faces)));
    if (!session.DoOptimization()) break;
    faces = std::min(faces - 1, faces * double(target_vertices) / double(m.vn));
  }
  session.Finalize<Collapse>();
  return from_vcg(m);
}

std::vector<size_t> nearest_vertices(const MeshView &from, const MeshView &to) {
  std::vector<size_t> out(to.vertex_count, 0);
  if (from.vertex_count == 0) return out;
  const Bounds b = compute_bounds(from);
  // About 2 source vertices per cell.
  const double cell = std::max(1e-12, double(b.diagonal()) / std::cbrt(double(from.vertex_count) / 2.0) / 1.7320508);
  auto key = [](int x, int y, int z) {
    return (int64_t(x) * 73856093) ^ (int64_t(y) * 19349663) ^ (int64_t(z) * 83492791);
  };
  auto coord = [&](float p, int k) { return int(std::floor((double(p) - b.min[k]) / cell)); };
  std::unordered_map<int64_t, std::vector<size_t>> grid;
  for (size_t v = 0; v < from.vertex_count; ++v) {
    const float *p = from.positions + 3 * v;
    grid[key(coord(p[0], 0), coord(p[1], 1), coord(p[2], 2))].push_back(v);
  }
  const ptrdiff_t n = ptrdiff_t(to.vertex_count);
#pragma omp parallel for schedule(dynamic, 256)
  for (ptrdiff_t v = 0; v < n; ++v) {
    const float *p = to.positions + 3 * v;
    const int c[3] = {coord(p[0], 0), coord(p[1], 1), coord(p[2], 2)};
    double best = std::numeric_limits<double>::max();
    size_t best_index = 0;
    // Grow the searched shell until the best distance is inside the searched cube.
    for (int r = 0; r < 1 << 20; ++r) {
      for (int dx = -r; dx <= r; ++dx)
        for (int dy = -r; dy <= r; ++dy)
          for (int dz = -r; dz <= r; ++dz) {
            if (std::max(std::abs(dx), std::max(std::abs(dy), std::abs(dz))) != r) continue;
            const auto it = grid.find(key(c[0] + dx, c[1] + dy, c[2] + dz));
            if (it == grid.end()) continue;
            for (size_t s : it->second) {
              const float *q = from.positions + 3 * s;
              const double d = double(q[0] - p[0]) * (q[0] - p[0]) + double(q[1] - p[1]) * (q[1] - p[1]) +
                               double(q[2] - p[2]) * (q[2] - p[2]);
              if (d < best) best = d, best_index = s;
            }
          }
      if (best < std::numeric_limits<double>::max() && std::sqrt(best) <= double(r) * cell) break;
    }
    out[size_t(v)] = best_index;
  }
  return out;
}

std::vector<float> resample_onto(const MeshData &surface, MeshData &mesh) {
  const size_t ns = surface.positions.size() / 3, nf = surface.indices.size() / 3;
  if (ns == 0 || nf == 0 || surface.normals.size() != 3 * ns)
    throw std::runtime_error("resample_onto: the surface needs faces and vertex normals");
  SMesh s;
  auto vi = vcg::tri::Allocator<SMesh>::AddVertices(s, ns);
  for (size_t v = 0; v < ns; ++v, ++vi) {
    vi->P() = vcg::Point3f(&surface.positions[3 * v]);
    vi->N() = vcg::Point3f(&surface.normals[3 * v]);
  }
  auto fi = vcg::tri::Allocator<SMesh>::AddFaces(s, nf);
  for (size_t f = 0; f < nf; ++f, ++fi)
    for (int k = 0; k < 3; ++k) fi->V(k) = &s.vert[surface.indices[3 * f + size_t(k)]];
  // Zero-area faces (at a UV sphere's poles, say) have no barycentric coordinates to interpolate with.
  vcg::tri::Clean<SMesh>::RemoveZeroAreaFace(s);
  vcg::tri::Allocator<SMesh>::CompactFaceVector(s);
  vcg::tri::UpdateNormal<SMesh>::PerFaceNormalized(s);
  vcg::tri::UpdateBounding<SMesh>::Box(s);
  vcg::GridStaticPtr<SFace, float> grid;
  grid.Set(s.face.begin(), s.face.end());

  const size_t nv = mesh.positions.size() / 3;
  mesh.normals.resize(3 * nv);
  std::vector<float> moved(nv, 0.0f);
  const float max_distance = s.bbox.Diag();
  // Serial: the query marks faces in the mesh it searches.
  for (size_t v = 0; v < nv; ++v) {
    const vcg::Point3f p(&mesh.positions[3 * v]);
    float distance = max_distance;
    vcg::Point3f closest, normal, barycentric;
    if (!vcg::tri::GetClosestFaceBase(s, grid, p, max_distance, distance, closest, normal, barycentric)) continue;
    normal.Normalize();
    for (int k = 0; k < 3; ++k) {
      mesh.positions[3 * v + size_t(k)] = closest[k];
      mesh.normals[3 * v + size_t(k)] = normal[k];
    }
    moved[v] = (closest - p).Norm();
  }
  return moved;
}

} // namespace bench
} // namespace vbrdf
