#include "inputs/viewpoints.h"

#include <algorithm>
#include <string>

#include "base/errors.h"

namespace vbrdf {

std::vector<Viewpoint> group_viewpoints(const std::vector<Raster> &rasters) {
  std::vector<Viewpoint> out;
  for (size_t r = 0; r < rasters.size(); ++r) {
    auto it = std::find_if(out.begin(), out.end(), [&](const Viewpoint &v) { return same_shot(v.shot, rasters[r].shot); });
    if (it == out.end()) {
      out.push_back(Viewpoint{rasters[r].shot, {}});
      it = out.end() - 1;
    }
    it->rasters.push_back(r);
  }
  return out;
}

std::vector<std::vector<size_t>> rasters_by_viewpoint(const std::vector<Raster> &rasters) {
  std::vector<std::vector<size_t>> groups;
  for (Viewpoint &v : group_viewpoints(rasters)) groups.push_back(std::move(v.rasters));
  return groups;
}

size_t viewpoint_of_raster(const std::vector<Viewpoint> &viewpoints, size_t raster) {
  for (size_t i = 0; i < viewpoints.size(); ++i)
    if (std::find(viewpoints[i].rasters.begin(), viewpoints[i].rasters.end(), raster) != viewpoints[i].rasters.end())
      return i;
  throw InputError("Raster " + std::to_string(raster) + " does not exist: choose a raster index between 0 and the "
                   "number of rasters minus one (-1 = the last raster).");
}

} // namespace vbrdf
