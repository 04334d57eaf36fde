#pragma once
// Samples corrected by the colour calibration (calibration/color_chart.h, color_plan.h): the
// calibration measures photos and knows nothing of samples; this is where the two meet, so that
// the calibration stays below the samples stage.
#include <cstddef>

#include "calibration/color_chart.h"
#include "calibration/color_plan.h"
#include "samples/samples.h"

namespace vbrdf {

// Corrects samples in place; Sample::raster is the photo index given to calibrate_colors().
void apply_color_calibration(const ColorCalibration &cal, Sample *samples, size_t count);

// In place: corrected = M(rgb / exposure) for every sample of a corrected viewpoint. Negative
// results (a matrix applied to noise in dark pixels) are no light, and NaN is none: both become 0.
void correct_samples(const ColorPlan &plan, SampleChunk &chunk);

} // namespace vbrdf
