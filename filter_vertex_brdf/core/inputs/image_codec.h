#pragma once
// Reading and writing image files. The default implementation (image_codec.cpp) is OpenCV's
// imgcodecs; the build for PyMeshLab links a Qt implementation instead
// (plugin/meshlab_2025/image_codec_qt.cpp), because imgcodecs pulls shared libraries that clash
// with the ones PyMeshLab's wheel carries (docs/pymeshlab.md#image-decoding).
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace vbrdf {

// The file's pixels as decoded, as cv::imread(path, cv::IMREAD_UNCHANGED) gives them: 8- or
// 16-bit codes, 1, 3 or 4 channels in B, G, R(, A) order, no EXIF rotation. Empty when the file
// cannot be decoded.
cv::Mat read_image_unchanged(const std::string &path);

// `image` (8-bit, 1, 3 or 4 channels in OpenCV's B, G, R(, A) order) as PNG file bytes. False when
// it cannot be encoded.
bool encode_png(const cv::Mat &image, std::vector<uint8_t> &bytes);

} // namespace vbrdf
