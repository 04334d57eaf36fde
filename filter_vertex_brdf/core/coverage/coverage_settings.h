#pragma once
// The settings of a coverage run (run/coverage_run.h): which samples count, how needs are weighted
// and where the suggestions go. Here, below the run, because the needs (suggest_learning.h) read
// them too.
#include <string>

#include "base/output_file.h"
#include "coverage/coverage.h"
#include "fit/fit_backends.h"  // VisibilityChoice
#include "model/defaults.h"
#include "samples/samples.h"
#include "visibility/visibility.h"

namespace vbrdf {

struct CoverageSettings {
  // Coverage asks for well-lit samples (T_d kCoverageDiffuseThreshold) and counts highlights on R.E
  // (kHighlight): it fits no lobe, so its samples take the R.E cosine and no footprints.
  CoverageSettings() {
    gather.diffuse_threshold = kCoverageDiffuseThreshold;
    gather.lobe = LobeForm::PhongRE;
  }
  GatherSettings gather;            // T_s and T_d classify samples and drive the suggestions
  VisibilitySettings visibility;
  VisibilityChoice visibility_choice = VisibilityChoice::Auto;
  LightSuggestionSettings suggest;  // its thresholds are replaced by gather's
  int min_diffuse = 1;              // diffuse samples a vertex needs to count as diffusely covered
  int min_specular = kDefaultMinSpecularSamples;  // specular samples it needs to count as specularly covered
  int viewpoint_raster = -1;        // suggestions for the viewpoint of this raster; -1: the last raster
  // With a fit (CoverageInput::dq/sq): a covered vertex whose DQ (SQ) is below this still needs
  // diffuse (specular) samples, weighted (poor - q) / poor; uncovered vertices weigh 1.
  float poor_dq = 1.5f;
  float poor_sq = 1.5f;
  float tolerance_deg = 0;          // suggestions robust to this light placement error (0: exact)
  float failure_cone_deg = 20;      // suggest_light_learning: learn from failed predictions (0: off)
  // Learn from the previous suggestion file (same path): when photos were added to the viewpoint
  // since, its recommended light counts as followed, i.e. as a light whose promises are checked
  // (suggest_light_learning), together with the lights followed before. Needs write_files.
  bool learn_from_previous = true;
  std::string light_file;           // "" = the default rule (light_file.h resolve_light_file); .json / .dome: light_source.h
  float dome_radius = 0;            // as FitSettings: the .lp's directions as point lights on a dome
  float light_unit_scale = 0;       // as FitSettings: mesh units per unit of the light file's positions
  std::string suggestion_file;      // "" = <project folder>/<project name>_next_light.txt
  // An existing suggestion file (and its vertex list): replaced, the log saying so (the default:
  // each run replaces the last one and learns from it), or the run refused before any work.
  OverwritePolicy overwrite = OverwritePolicy::Replace;
  bool write_files = true;          // false: nothing is written (result only)
};

} // namespace vbrdf
