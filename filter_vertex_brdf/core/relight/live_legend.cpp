// False colours of the live view (live_legend.h).
#include "relight/live_legend.h"

#include <algorithm>
#include <cmath>

namespace vbrdf {

const std::vector<LegendEntry> &fit_status_legend() {
  static const std::vector<LegendEntry> legend = {
      {"0 no fit", {{0.35f, 0.35f, 0.35f}}},
      {"1 diffuse only (k_s = 0)", {{0.20f, 0.45f, 0.90f}}},
      {"2 full fit", {{0.20f, 0.75f, 0.25f}}},
      {"3 from neighbours", {{0.95f, 0.60f, 0.10f}}},
      {"4 from weak samples", {{0.70f, 0.30f, 0.80f}}},
  };
  return legend;
}

const std::vector<LegendEntry> &quality_legend() {
  static const std::vector<LegendEntry> legend = {
      {"0 poor", {{0.85f, 0.15f, 0.10f}}},
      {"1 fair", {{0.95f, 0.85f, 0.20f}}},
      {"2 good", {{0.15f, 0.70f, 0.25f}}},
  };
  return legend;
}

std::array<float, 3> quality_color(float q) {
  const auto &stops = quality_legend();
  const float t = std::isfinite(q) ? std::min(std::max(q, 0.0f), 2.0f) : 0.0f;
  const int i = t >= 1.0f ? 1 : 0;
  const float f = t - float(i);
  std::array<float, 3> out;
  for (size_t k = 0; k < 3; ++k) out[k] = stops[size_t(i)].rgb[k] * (1 - f) + stops[size_t(i) + 1].rgb[k] * f;
  return out;
}

} // namespace vbrdf
