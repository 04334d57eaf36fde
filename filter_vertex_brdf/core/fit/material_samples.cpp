#include "fit/material_samples.h"

#include <algorithm>
#include <cmath>

namespace vbrdf {

MaterialSampleStore::MaterialSampleStore(size_t vertex_count) : begin_(vertex_count, 0), end_(vertex_count, 0) {}

namespace {
// The fit's usable-sample rules (phong_fit_cpu.cpp usable_samples), strict or weak.
bool kept_sample(const Sample &s, bool weak) {
  if ((s.flags & (kShadowed | kSaturated | kNotSeen)) || !(s.d > 0)) return false;
  if ((s.flags & kMixedPixel) && !weak) return false;
  if ((s.flags & kGrazing) && !(s.flags & kHighlight) && !weak) return false;
  return std::isfinite(s.rgb[0]) && std::isfinite(s.rgb[1]) && std::isfinite(s.rgb[2]) && std::isfinite(s.lobe_cos) &&
         std::isfinite(s.d);
}
} // namespace

void MaterialSampleStore::add_chunk(const SampleChunk &chunk, const VertexFit *fits, const PhongFitOptions &o) {
  // Counted first, so that the store grows once per chunk (geometrically) rather than by doubling
  // copies of tens of MB as entries are pushed.
  const uint32_t count = std::min<uint64_t>(chunk.vertex_count, begin_.size() - std::min<uint64_t>(begin_.size(), chunk.first_vertex));
  size_t kept = 0;
  for (uint32_t i = 0; i < count; ++i) {
    const bool weak = fits[i].status == kFitFromWeakSamples;
    for (uint32_t k = chunk.offsets[i]; k < chunk.offsets[i + 1]; ++k) kept += kept_sample(chunk.samples[k], weak);
  }
  if (data_.size() + kept > data_.capacity()) data_.reserve(std::max(data_.size() + kept, data_.capacity() + data_.capacity() / 2));
  for (uint32_t i = 0; i < count; ++i) {
    const size_t v = size_t(chunk.first_vertex) + i;
    const bool weak = fits[i].status == kFitFromWeakSamples;
    begin_[v] = data_.size();
    for (uint32_t k = chunk.offsets[i]; k < chunk.offsets[i + 1]; ++k) {
      const Sample &s = chunk.samples[k];
      if (!kept_sample(s, weak)) continue;
      const float w = s.d * resolution_weight(s) * ((s.flags & kMixedPixel) ? o.mixed_sample_weight : 1.0f);
      data_.push_back({{s.rgb[0], s.rgb[1], s.rgb[2]}, std::min(s.d, 1.0f), s.lobe_cos, w, s.raster,
                       uint16_t(s.flags | s.resolution << 10)});
    }
    end_[v] = data_.size();
  }
}

std::vector<Sample> MaterialSampleStore::as_samples(size_t v) const {
  std::vector<Sample> out;
  for (uint64_t k = begin_[v]; k < end_[v]; ++k) {
    const Entry &e = data_[k];
    Sample smp{{e.rgb[0], e.rgb[1], e.rgb[2]}, e.d, e.s, e.raster, 0, 0};
    smp.flags = e.flags & 0x3FFu;
    smp.resolution = uint16_t(e.flags >> 10);
    out.push_back(smp);
  }
  return out;
}

} // namespace vbrdf
