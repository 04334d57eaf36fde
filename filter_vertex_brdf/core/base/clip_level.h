#pragma once
// Where a photo's value counts as clipped: the two levels of the core, each named once.
namespace vbrdf {

// The default 'Saturation level': a channel at or above this fraction of the maximum code value
// counts as clipped (photo decoding, the fit's and relighting's samples, the sphere filter).
constexpr float kSaturationLevel = 0.99f;

// A linear value (after decoding, full scale 1) at or above which calibration treats a pixel as
// clipped: chart patches and the sphere's highlight blobs. Calibration's own test, independent of
// the 'Saturation level' parameter.
constexpr float kClippedLinearValue = 0.995f;

} // namespace vbrdf
