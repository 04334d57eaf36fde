#pragma once
// Luminance of linear Rec. 709 / sRGB primaries (the photos' and the model's colour space).
namespace vbrdf {

constexpr float kLuminanceWeights[3] = {0.2126f, 0.7152f, 0.0722f};

inline float luminance(const float rgb[3]) {
  return kLuminanceWeights[0] * rgb[0] + kLuminanceWeights[1] * rgb[1] + kLuminanceWeights[2] * rgb[2];
}

} // namespace vbrdf
