#pragma once
// The material stage's account for the fit report and log (materials.h): how K and the priors were
// chosen, each material's pooled lobe and whether it was given, and what changed. Text only: the
// stage hands over the facts, this file words them.
#include <cstddef>
#include <string>
#include <vector>

#include "fit/materials.h"
#include "fit/material_lobes.h"
#include "fit/material_solve.h"
#include "model/lobe.h"

namespace vbrdf {
namespace material_stage {

// What the report says beyond MaterialResult, as the stage found it.
struct MaterialReportFacts {
  size_t eligible_vertices = 0;   // 0: the stage was skipped (no vertex with samples)
  size_t photos = 0;              // photos with kept samples
  double best_error = 0;          // the lowest held-out error over K
  int k_within_tolerance = 0;     // the smallest K within MaterialOptions::choose_tolerance of the best
  int merged = 0;                 // of its materials merged as twins
  int k_merged = 0;               // K after the merge
  bool any_glossy = false;        // a glossy material was found (else every vertex keeps its fit)
  std::vector<GivingTest> giving; // per label (index 0 unused): the giving test, summed over the folds
  std::vector<LobeFit> lobes;     // per label (index 0 unused): the pooled lobe as fitted
  size_t selection_vertices = 0;  // vertices K was chosen on
  double seconds_choice = 0;
};

// The report's lines, each ending in '\n'.
std::string material_report(const MaterialResult &R, const MaterialReportFacts &facts, const MaterialOptions &mo,
                            LobeForm lobe);

} // namespace material_stage
} // namespace vbrdf
