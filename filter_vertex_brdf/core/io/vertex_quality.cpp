#include "io/vertex_quality.h"

#include <algorithm>
#include <cmath>

namespace vbrdf {

void neutral_quality_for_unmodelled(const std::vector<VertexFit> &fits, std::vector<float> &quality) {
  std::vector<float> modelled;
  for (size_t v = 0; v < fits.size() && v < quality.size(); ++v)
    if (fits[v].status != kFitNone && std::isfinite(quality[v])) modelled.push_back(quality[v]);
  float neutral = 0.0f;
  if (!modelled.empty()) {
    std::nth_element(modelled.begin(), modelled.begin() + std::ptrdiff_t(modelled.size() / 2), modelled.end());
    neutral = modelled[modelled.size() / 2];
  }
  for (size_t v = 0; v < fits.size() && v < quality.size(); ++v)
    if (fits[v].status == kFitNone || !std::isfinite(quality[v])) quality[v] = neutral;
}

} // namespace vbrdf
