#pragma once
// A visibility back end that remembers its last camera pass. The fit asks for the same pass twice
// when the registration measures a camera and the depth passes then run at that same camera (the
// corrections wait for the residual check: run/fit_run.cpp); the second answer is the first's codes.
#include <cstdint>
#include <vector>

#include "visibility/visibility.h"

namespace vbrdf {

class CameraPassCache : public VisibilityBackend {
public:
  CameraPassCache(VisibilityBackend &inner, size_t vertex_count) : inner_(inner), vertex_count_(vertex_count) {}
  const char *name() const override { return inner_.name(); }
  // The inner pass, or the last one's codes when `shot` is the last pass's (same_shot).
  void camera_pass(const Shot &shot, uint8_t *out) override;
  void light_pass(const LightSource &light, uint8_t *out, const uint64_t *only = nullptr) override {
    inner_.light_pass(light, out, only);
  }
  PassSizes last_pass_sizes() const override { return inner_.last_pass_sizes(); }
  size_t reused() const { return reused_; }

private:
  VisibilityBackend &inner_;
  size_t vertex_count_;
  bool cached_ = false;
  Shot shot_;
  std::vector<uint8_t> codes_;
  size_t reused_ = 0;
};

} // namespace vbrdf
