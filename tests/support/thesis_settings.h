#pragma once
// The thesis's model for the tests written against it: the R.E lobe, T_d 0.5 and one specular
// sample for specular coverage. The core's defaults are the product's (core/model/defaults.h); a
// test that exercises the thesis's model takes its settings from here, so that it keeps testing
// what it was written for.
#include "coverage/coverage_settings.h"
#include "fit/reflectance_fit.h"
#include "relight/relight_render.h"
#include "samples/samples.h"
#include "tools/relight.h"

namespace vbrdf {
namespace test {

constexpr LobeForm kThesisLobe = LobeForm::PhongRE;
constexpr float kThesisDiffuseThreshold = 0.5f;

inline ReflectanceFitOptions thesis_fit_options() {
  ReflectanceFitOptions o;
  o.lobe = kThesisLobe;
  return o;
}

inline GatherSettings thesis_gather_settings() {
  GatherSettings g;
  g.lobe = kThesisLobe;
  g.diffuse_threshold = kThesisDiffuseThreshold;
  return g;
}

inline RelightRenderSettings thesis_render_settings() {
  RelightRenderSettings r;
  r.lobe = kThesisLobe;
  return r;
}

inline RelightOptions thesis_relight_options() {
  RelightOptions o;
  o.gather = thesis_gather_settings();
  return o;
}

inline CoverageSettings thesis_coverage_settings() {
  CoverageSettings c;
  c.min_specular = 1;
  return c;
}

} // namespace test
} // namespace vbrdf
