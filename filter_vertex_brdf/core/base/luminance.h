#pragma once
// Luminance of linear Rec. 709 / sRGB primaries (the photos' and the model's colour space): one set
// of weights for the whole core.
namespace vbrdf {

constexpr float kLuminanceWeights[3] = {0.2126f, 0.7152f, 0.0722f};
constexpr double kLuminanceWeightsDouble[3] = {0.2126, 0.7152, 0.0722};

// In float (per pixel: registration's luminance images).
inline float luminance(const float rgb[3]) {
  return kLuminanceWeights[0] * rgb[0] + kLuminanceWeights[1] * rgb[1] + kLuminanceWeights[2] * rgb[2];
}

// In double, with the weights as doubles (calibration's patch means, the light check's sums).
inline double luminance_double(const float rgb[3]) {
  return kLuminanceWeightsDouble[0] * rgb[0] + kLuminanceWeightsDouble[1] * rgb[1] + kLuminanceWeightsDouble[2] * rgb[2];
}

} // namespace vbrdf
