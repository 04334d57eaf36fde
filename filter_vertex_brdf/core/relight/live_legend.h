#pragma once
// The false colours of the live view (live_relight.h) and their legend: one table that the shader
// receives as uniforms and the render plugin's legend shows, so the two cannot disagree.
#include <array>
#include <vector>

namespace vbrdf {

struct LegendEntry {
  const char *label;
  std::array<float, 3> rgb;  // display colour (sRGB, 0..1)
};

// fit_status codes 0..4 (reflectance_fit.h FitStatus), indexed by the code.
const std::vector<LegendEntry> &fit_status_legend();

// DQ and SQ (0..2, higher is better): the colour stops at 0, 1 and 2; values between stops are
// interpolated linearly, values outside are clamped.
const std::vector<LegendEntry> &quality_legend();

// The colour of quality value q (as the shader computes it).
std::array<float, 3> quality_color(float q);

} // namespace vbrdf
