#pragma once
// The samples the material stage (materials.h) works on: the fit's usable samples of every vertex,
// kept while the chunks stream (28 bytes each; the report states the memory), and apart from them
// the lit samples the fits leave out as grazing (N.L < T_d, no highlight): the stage fits nothing
// to them, but a lobe it gives is also seen there when the model is relit (the giving test scores them).
#include <cstdint>
#include <vector>

#include "fit/reflectance_fit.h"
#include "samples/samples.h"

namespace vbrdf {

// The fit's usable samples of every vertex, kept while the chunks stream.
class MaterialSampleStore {
public:
  explicit MaterialSampleStore(size_t vertex_count = 0);
  // Keeps the usable samples of the chunk's vertices; `fits` are the chunk's fits (their status
  // picks the strict or the weak sample rules). Call once per chunk, before or after the fit.
  void add_chunk(const SampleChunk &chunk, const VertexFit *fits, const ReflectanceFitOptions &o);
  struct Entry {
    float rgb[3];
    float d, s, w;      // N.L, the lobe's cosine (R.E or N.H), weight (resolution weight included)
    uint16_t raster;
    uint16_t flags;     // SampleFlag bits of the sample | its Sample::resolution << 10
    float v;            // Sample::footprint (the GGX lobe through the photo's pixel footprint)
  };
  size_t vertex_count() const { return begin_.size(); }
  uint64_t first(size_t v) const { return begin_[v]; }  // index range [first, last) into entries()
  uint64_t last(size_t v) const { return end_[v]; }
  const std::vector<Entry> &entries() const { return data_; }
  // The grazing samples of vertex v: [grazing_first(v), grazing_last(v)) into grazing_entries().
  uint64_t grazing_first(size_t v) const { return grazing_begin_[v]; }
  uint64_t grazing_last(size_t v) const { return grazing_end_[v]; }
  const std::vector<Entry> &grazing_entries() const { return grazing_; }
  size_t bytes() const {
    return (data_.capacity() + grazing_.capacity()) * sizeof(Entry) +
           2 * (begin_.capacity() + grazing_begin_.capacity()) * sizeof(uint64_t);
  }
  // Raw samples (for quality metrics) in Sample form, of vertex v.
  std::vector<Sample> as_samples(size_t v) const;

private:
  std::vector<uint64_t> begin_, end_, grazing_begin_, grazing_end_;
  std::vector<Entry> data_, grazing_;
};

} // namespace vbrdf
