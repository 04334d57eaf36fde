#include "fit/heldout_folds.h"

#include <algorithm>

namespace vbrdf {

int heldout_fold_count(size_t photos, size_t min_held) {
  int folds = 0;
  size_t held = 0;
  while (folds < kHeldOutFolds && (folds == 0 || held < min_held)) {
    const size_t f = size_t(kHeldOutFoldOrder[folds++]);
    held += photos > f ? (photos - f + kHeldOutFolds - 1) / kHeldOutFolds : 0;
  }
  return folds;
}

std::vector<int> heldout_folds(const std::vector<uint8_t> &present, size_t min_held) {
  const size_t photos = size_t(std::count_if(present.begin(), present.end(), [](uint8_t p) { return p != 0; }));
  std::vector<int> folds;
  size_t held_total = 0;
  for (int k = 0; k < kHeldOutFolds && (folds.empty() || held_total < min_held); ++k) {
    size_t held = 0;
    for (size_t r = 0; r < present.size(); ++r) held += present[r] && held_out_in_fold(r, k);
    if (held == 0 || held == photos) continue;
    folds.push_back(k);
    held_total += held;
  }
  if (folds.empty()) folds.push_back(0);
  return folds;
}

} // namespace vbrdf
