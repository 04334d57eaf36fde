#pragma once
// Relighting evaluation: predicts, with the fitted per-vertex reflectance model, what photos taken
// under other lights (held out from the fit) show at every vertex, and scores the prediction in
// CIELAB (CIEDE2000) and PSNR over the whole visible surface, the protocol by which RTI tools are
// judged; optionally beside per-pixel PTM and RBF baselines fitted on the training photos
// (rti_baselines.h) and scored on exactly the same samples.
#include <array>
#include <cstdint>
#include <vector>


#include "inputs/camera.h"
#include "base/mesh_view.h"
#include "fit/reflectance_fit.h"
#include "relight/relight_render.h"
#include "samples/samples.h"

namespace vbrdf {

// CIEDE2000 over a set of samples (0 everywhere when samples == 0).
struct ErrorSummary {
  size_t samples = 0;
  double mean = 0;
  double median = 0;
  double p95 = 0;
};

struct RelightOptions {
  // Sampling of the held-out (and training) photos. own_surface_texels is forced to false: plain
  // bilinear over the whole footprint, contamination included (the RTI protocol).
  GatherSettings gather;
  // Optional (null = all vertices): one entry per vertex; only vertices with a non-zero entry are
  // scored (e.g. the ground truth's `visible`). A size other than the vertex count is an InputError.
  const std::vector<uint8_t> *vertex_filter = nullptr;
  // Optional (null = our shadow passes decide): per held-out raster and vertex (raster-major,
  // rasters x vertices entries), non-zero where the vertex is lit (e.g. the ground truth's
  // `heldout_lit`). Where given it replaces the shadow flags: lit samples are scored even where our
  // shadow map disagrees, unlit ones never are.
  const std::vector<uint8_t> *lit_filter = nullptr;
  // Optional (null = the vertex's model alone): per held-out raster, the model's image as that
  // camera records it (relight_render.h render_as_photographed). The product then predicts a
  // sample as the photo is sampled: bilinearly over the vertex's 2x2 pixel footprint, where the
  // pixels on the vertex's own surface (the camera pass's footprint mask) take the vertex's model
  // (evaluate_reflectance) and, at silhouettes and contacts, the others (background, another surface)
  // take that image. Inside a surface this is exactly the vertex's model.
  const std::vector<cv::Mat> *rendered = nullptr;
  // Optional (null = none): one flag per vertex, non-zero where the fit's k_d C is the vertex's own
  // reflectance deconvolved from the photos' pixel footprints (the result's diffuse_deconvolved,
  // fit/albedo_deconvolution.h). There the product predicts the held-out photo as its camera
  // records it: the diffuse reflectance seen through the footprint (samples/footprint_weights.h:
  // the weighted mean of the neighbouring vertices' k_d C), the lobe and shading the vertex's own.
  const std::vector<uint8_t> *diffuse_deconvolved = nullptr;
  // Optional baselines (both null = off): the training rasters and their lights (the baselines,
  // per-pixel RTI, use one direction per photo: LightSource::direction, as RTI tools do).
  // For each held-out raster the training rasters of the same viewpoint (same_shot) are used; the
  // vertex's samples there (plain bilinear, shadowed kept, saturated dropped) fit PTM and RBF.
  const std::vector<Raster> *training_rasters = nullptr;
  const std::vector<LightSource> *training_lights = nullptr;
  float rbf_ridge = 1e-3f;
  // Optional (null = not kept): every scored sample, appended in vertex order (for tools that
  // locate the error: vbrdf_eval --samples-csv).
  std::vector<struct ScoredSample> *per_sample = nullptr;
};

// One scored held-out sample, as RelightOptions::per_sample keeps it. de_ptm / de_rbf are -1
// where the baselines did not score it.
struct ScoredSample {
  uint32_t vertex;
  uint16_t raster;
  uint8_t fit_status;
  bool mixed;
  float d;                    // the diffuse factor (N.L for Lambert)
  float observed[3], predicted[3];
  float de, de_ptm, de_rbf;
};

struct RelightStats {
  // Whole surface: every held-out sample that is seen, lit (no kShadowed flag, N.L > 0) and
  // unsaturated, at every scored vertex; mixed pixels included. Vertices without a model
  // (kFitNone) are predicted as evaluate_reflectance gives them (black): what a user relighting the PLY sees.
  size_t samples = 0;       // compared vertex x photo pairs
  double mean_de2000 = 0;
  double median_de2000 = 0;
  double p95_de2000 = 0;
  double psnr_db = 0;       // over linear RGB in [0, 1] (prediction clamped to 1)
  std::vector<double> per_raster_mean_de2000;  // one per held-out raster (0 when it has no sample)
  std::vector<size_t> per_raster_samples;

  // The former measure, labelled: "clean pixels, modelled vertices only" (samples without the
  // kMixedPixel flag, of vertices whose status is not kFitNone).
  ErrorSummary clean_modelled;
  // Whole-surface samples whose vertex has no model (status kFitNone), and their share.
  size_t unmodelled_samples = 0;
  double unmodelled_share = 0;
  // Scored vertices (passing the filter) with at least one stored (seen) sample in any gathered
  // photo (held-out, and training when the baselines are on), and those of them without a model.
  size_t seen_vertices = 0;
  size_t seen_unmodelled_vertices = 0;

  // Baselines (when RelightOptions gives training rasters). The three summaries are over one
  // sample set: the whole-surface samples for which the vertex has at least one usable training
  // sample in the held-out photo's viewpoint. Samples without training data are excluded from all
  // three (not predicted black) and counted in baseline_excluded.
  bool has_baselines = false;
  ErrorSummary product_on_baseline_set;
  ErrorSummary ptm;
  ErrorSummary rbf;
  // The same three, split by the held-out sample's footprint: clean (on one surface) and mixed
  // (straddling a silhouette or contact: the photo mixes surfaces, every method is scored on it).
  ErrorSummary product_clean_footprint, rbf_clean_footprint, product_mixed_footprint, rbf_mixed_footprint;
  size_t baseline_excluded = 0;
  std::vector<float> rbf_sigma_per_raster;  // sigma used for each held-out raster (0: no training viewpoint)
};

// `fits` has one entry per vertex; `rasters` / `lights` are the held-out photos. The product
// predicts evaluate_reflectance times the light's irradiance at the vertex (light_irradiance_at: point
// lights fall off with distance; directional ones give their intensity, 1). Any
// status other than kFitNone counts as modelled. Visibility comes from `visibility` (built for
// `mesh`); held-out and training photos are gathered in one pass. Throws InputError on size
// mismatches (fits, lights, filter, training lights). All outputs are finite.
RelightStats evaluate_relighting(const MeshView &mesh, const std::vector<VertexFit> &fits,
                                 const std::vector<Raster> &rasters,
                                 const std::vector<LightSource> &lights, VisibilityBackend &visibility,
                                 const RelightOptions &options = RelightOptions());

} // namespace vbrdf
