#include "fit/material_samples.h"

#include <algorithm>
#include <cmath>

namespace vbrdf {

MaterialSampleStore::MaterialSampleStore(size_t vertex_count)
    : begin_(vertex_count, 0), end_(vertex_count, 0), grazing_begin_(vertex_count, 0), grazing_end_(vertex_count, 0) {}

namespace {
// The fit's usable-sample rules (reflectance_fit_cpu.cpp usable_samples), strict or weak.
bool kept_sample(const Sample &s, bool weak) {
  if ((s.flags & (kShadowed | kSaturated | kNotSeen)) || !(s.d > 0)) return false;
  if ((s.flags & kMixedPixel) && !weak) return false;
  if ((s.flags & kGrazing) && !(s.flags & kHighlight) && !weak) return false;
  return std::isfinite(s.rgb[0]) && std::isfinite(s.rgb[1]) && std::isfinite(s.rgb[2]) && std::isfinite(s.lobe_cos) &&
         std::isfinite(s.d);
}
// A lit sample the strict rules leave out only as grazing (N.L < T_d without a highlight).
bool grazing_sample(const Sample &s) {
  return (s.flags & kGrazing) && !(s.flags & (kHighlight | kShadowed | kSaturated | kNotSeen | kMixedPixel)) && s.d > 0 &&
         std::isfinite(s.rgb[0]) && std::isfinite(s.rgb[1]) && std::isfinite(s.rgb[2]) && std::isfinite(s.lobe_cos);
}
MaterialSampleStore::Entry entry_of(const Sample &s, float w) {
  return {{s.rgb[0], s.rgb[1], s.rgb[2]}, std::min(s.d, 1.0f), s.lobe_cos, w, s.raster, uint16_t(s.flags | s.resolution << 10),
          s.footprint};
}
} // namespace

void MaterialSampleStore::add_chunk(const SampleChunk &chunk, const VertexFit *fits, const ReflectanceFitOptions &o) {
  // Counted first, so that the store grows once per chunk (geometrically) rather than by doubling
  // copies of tens of MB as entries are pushed.
  const uint32_t count = std::min<uint64_t>(chunk.vertex_count, begin_.size() - std::min<uint64_t>(begin_.size(), chunk.first_vertex));
  // Each sample's fate is decided once: 0 dropped, 1 kept, 2 kept apart as grazing.
  std::vector<uint8_t> fate(count ? chunk.offsets[count] : 0, 0);
  size_t kept = 0, grazing = 0;
  for (uint32_t i = 0; i < count; ++i) {
    const bool weak = fits[i].status == kFitFromWeakSamples;
    for (uint32_t k = chunk.offsets[i]; k < chunk.offsets[i + 1]; ++k) {
      const Sample &s = chunk.samples[k];
      fate[k] = kept_sample(s, weak) ? 1 : grazing_sample(s) ? 2 : 0;
      kept += fate[k] == 1, grazing += fate[k] == 2;
    }
  }
  auto grow = [](std::vector<Entry> &d, size_t more) {
    if (d.size() + more > d.capacity()) d.reserve(std::max(d.size() + more, d.capacity() + d.capacity() / 2));
  };
  grow(data_, kept), grow(grazing_, grazing);
  for (uint32_t i = 0; i < count; ++i) {
    const size_t v = size_t(chunk.first_vertex) + i;
    begin_[v] = data_.size(), grazing_begin_[v] = grazing_.size();
    for (uint32_t k = chunk.offsets[i]; k < chunk.offsets[i + 1]; ++k) {
      const Sample &s = chunk.samples[k];
      if (fate[k] == 1)
        data_.push_back(entry_of(s, s.d * resolution_weight(s) * ((s.flags & kMixedPixel) ? o.mixed_sample_weight : 1.0f)));
      else if (fate[k] == 2)
        grazing_.push_back(entry_of(s, s.d * resolution_weight(s)));
    }
    end_[v] = data_.size(), grazing_end_[v] = grazing_.size();
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
