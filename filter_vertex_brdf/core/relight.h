#pragma once
// Relighting evaluation: predicts, with the fitted per-vertex Phong model, what photos taken
// under other lights (held out from the fit) show at every vertex, and scores the prediction in
// CIELAB (CIEDE2000) and PSNR over the samples that are seen, lit, unsaturated and clean.
#include <array>
#include <vector>

#include "camera.h"
#include "mesh_view.h"
#include "phong_fit.h"
#include "samples.h"

namespace vbrdf {

struct RelightStats {
  size_t samples = 0;       // compared vertex x photo pairs
  double mean_de2000 = 0;
  double median_de2000 = 0;
  double p95_de2000 = 0;
  double psnr_db = 0;       // over linear RGB in [0, 1]
  std::vector<double> per_raster_mean_de2000;  // one per raster (0 when it has no sample)
  std::vector<size_t> per_raster_samples;
};

// `fits` has one entry per vertex (kFitNone vertices are skipped). The samples of `rasters` are
// gathered exactly as for the fit (masks from the same visibility back end). Pairs whose sample is
// not usable (shadowed, saturated, mixed pixel, N.L <= 0) are skipped.
RelightStats evaluate_relighting(const MeshView &mesh, const std::vector<VertexFit> &fits,
                                 const std::vector<Raster> &rasters,
                                 const std::vector<std::array<float, 3>> &light_dirs_world, VisibilityBackend &visibility,
                                 const GatherSettings &settings);

} // namespace vbrdf
