#include "inputs/image_codec.h"

#include <opencv2/imgcodecs.hpp>

namespace vbrdf {

cv::Mat read_image_unchanged(const std::string &path) { return cv::imread(path, cv::IMREAD_UNCHANGED); }

bool encode_png(const cv::Mat &image, std::vector<uint8_t> &bytes) {
  return !image.empty() && cv::imencode(".png", image, bytes);
}

} // namespace vbrdf
