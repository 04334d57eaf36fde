#pragma once
// The held-out splits on which the fit makes its choices: the diffuse form's pilot (diffuse_choice.h)
// and the material stage's K, priors and giving test (materials.h). Fold k holds out the photos whose
// raster index % 4 == kHeldOutFoldOrder[k] and trains on the others. Folds are taken in turn until at
// least kMinHeldOutPhotos photos were held out once: one fold from 32 photos on, two for 16-31, three
// or four below 16. One fold of a few photos leaves two or three lights to decide on: on the Seitz
// cat (9 photos, sRGB) a coat map 6 % better at its fold's two lights was 19 % worse at three others;
// on synth_basic at 8 photos the material stage's choices on one fold relit 0.919, on four 0.813.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vbrdf {

constexpr int kHeldOutFolds = 4;
constexpr int kHeldOutFoldOrder[kHeldOutFolds] = {3, 1, 2, 0};  // fold 0 (index % 4 == 3) alone from 32 photos on
constexpr size_t kMinHeldOutPhotos = 8;

// Whether fold k (0 .. kHeldOutFolds - 1, in the order taken) holds out the photo of raster index r.
inline bool held_out_in_fold(size_t raster, int k) { return int(raster % kHeldOutFolds) == kHeldOutFoldOrder[k]; }

// For a capture of `photos` photos with raster indices 0 .. photos - 1: how many folds are taken
// (1 .. kHeldOutFolds) until at least `min_held` photos were held out.
int heldout_fold_count(size_t photos, size_t min_held = kMinHeldOutPhotos);

// For photos with the raster indices that `present` marks (present[r] != 0; any size): the folds k
// taken in turn until at least `min_held` of them were held out, skipping those that hold out none
// or all of them (nothing to score, or nothing to fit). Always at least one fold: {0} when every
// fold would be skipped (fewer than two photos).
std::vector<int> heldout_folds(const std::vector<uint8_t> &present, size_t min_held = kMinHeldOutPhotos);

} // namespace vbrdf
