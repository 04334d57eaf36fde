#include "fit/material_sums.h"

#include <algorithm>

namespace vbrdf {
namespace material_stage {

std::vector<Static> static_sums(const Context &c, int set) {
  std::vector<Static> out(c.n);
  const auto &E = c.store.entries();
  const float flank = lobe_threshold(c.o.lobe, c.mo.deciding_flank);
#pragma omp parallel for schedule(dynamic, 512) if (c.store.entries().size() > 200000)
  for (long long t = 0; t < (long long)c.verts.size(); ++t) {
    const size_t v = c.verts[size_t(t)];
    Static &S = out[v];
    for (uint64_t k = c.store.first(size_t(v)); k < c.store.last(size_t(v)); ++k) {
      const Entry &e = E[k];
      if (!c.in_set(e, set)) continue;
      S.a += double(e.w) * e.d * e.d;
      for (int ch = 0; ch < 3; ++ch) S.p[ch] += double(e.w) * e.d * e.rgb[ch], S.pp[ch] += double(e.w) * e.rgb[ch] * e.rgb[ch];
      ++S.n;
      S.n_high += (e.flags & kHighlight) != 0;
      S.n_flank += e.s > flank;
    }
  }
  return out;
}

const std::vector<std::vector<Lobe>> &lobe_sums_at(const Context &c, int set, const std::vector<int32_t> &label,
                                                   const std::vector<std::vector<double>> &alpha_of, size_t count,
                                                   std::vector<std::vector<Lobe>> &out) {
  if (out.size() < count) out.resize(count);
  for (size_t j = 0; j < count; ++j) out[j].resize(c.n);
  const auto &E = c.store.entries();
#pragma omp parallel if (c.store.entries().size() > 200000)
  {
    std::vector<LobeAt> lobe(count);
    std::vector<Lobe> sums(count);
#pragma omp for schedule(dynamic, 512)
    for (long long t = 0; t < (long long)c.verts.size(); ++t) {
      const size_t v = c.verts[size_t(t)];
      if (label[v] <= 0) continue;
      for (size_t j = 0; j < count; ++j) lobe[j] = LobeAt(alpha_of[size_t(label[v])][j], c.ggx), sums[j] = Lobe();
      for (uint64_t k = c.store.first(v); k < c.store.last(v); ++k) {
        const Entry &e = E[k];
        if (!c.in_set(e, set)) continue;
        const float key = (*c.lobe_keys)[k];
        for (size_t j = 0; j < count; ++j) {
          const double g = lobe[j](key, e.v);
          if (g != 0) add_to_lobe(sums[j], e, g);
        }
      }
      for (size_t j = 0; j < count; ++j) out[j][v] = sums[j];
    }
  }
  return out;
}

std::vector<Lobe> lobe_sums(const Context &c, int set, const std::vector<int32_t> &label, const std::vector<double> &alpha_of) {
  std::vector<std::vector<double>> alphas(alpha_of.size());
  for (size_t m = 0; m < alpha_of.size(); ++m) alphas[m] = {alpha_of[m]};
  std::vector<std::vector<Lobe>> out(1, std::vector<Lobe>(c.n));
  lobe_sums_at(c, set, label, alphas, 1, out);
  return std::move(out[0]);
}

double median_of(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

} // namespace material_stage
} // namespace vbrdf
