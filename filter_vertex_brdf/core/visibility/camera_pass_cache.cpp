#include "visibility/camera_pass_cache.h"

#include <algorithm>

namespace vbrdf {

void CameraPassCache::camera_pass(const Shot &shot, uint8_t *out) {
  if (cached_ && same_shot(shot_, shot)) {
    std::copy(codes_.begin(), codes_.end(), out);
    ++reused_;
    return;
  }
  inner_.camera_pass(shot, out);
  codes_.assign(out, out + vertex_count_);
  shot_ = shot;
  cached_ = true;
}

} // namespace vbrdf
