#include <algorithm>
#include <cmath>
#include <vector>

#include "base/errors.h"
#include "visibility/visibility.h"

namespace vbrdf {

int resolved_shadow_map_size(const MeshView &mesh, const VisibilitySettings &settings) {
  if (settings.shadow_map_size > 0) return settings.shadow_map_size;
  if (settings.shadow_map_size < 0)
    throw InputError("The shadow map size must be positive, or 0 for automatic (got " +
                     std::to_string(settings.shadow_map_size) + ").");
  const size_t triangles = mesh.index_count / 3;
  if (triangles == 0) return 1024;
  // Median edge length over at most ~4096 triangles spread over the mesh.
  std::vector<float> edges;
  const size_t step = std::max<size_t>(1, triangles / 4096);
  for (size_t t = 0; t < triangles; t += step) {
    const float *a = mesh.positions + 3 * size_t(mesh.indices[3 * t]);
    const float *b = mesh.positions + 3 * size_t(mesh.indices[3 * t + 1]);
    const float d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    edges.push_back(std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
  }
  std::nth_element(edges.begin(), edges.begin() + long(edges.size() / 2), edges.end());
  const float median_edge = edges[edges.size() / 2];
  const float radius = 0.5f * compute_bounds(mesh).diagonal();
  if (!(median_edge > 0) || !(radius > 0)) return 1024;
  const float wanted = 8.0f * radius / median_edge;  // texel = 2 radius / size <= edge / 4
  int size = 1024;
  while (size < 4096 && float(size) < wanted) size *= 2;
  return size;
}

} // namespace vbrdf
