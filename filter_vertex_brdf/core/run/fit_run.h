#pragma once
// The whole filter without MeshLab: project -> lights -> colour calibration (per viewpoint, from a
// ColorChecker in the photos) -> visibility -> samples (colour-corrected) -> diffuse colour and
// reflectance fit (per vertex chunk) -> outputs. The plugin and the command-line tool both call this; they only differ in how they
// obtain the mesh, the rasters and the GL context.
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "calibration/color_chart.h"
#include "calibration/color_plan.h"  // ColorCorrectionChoice: Off, Auto (where a chart is found), Required
#include "samples/diffuse_color.h"
#include "fit/albedo_deconvolution.h"
#include "fit/fit_backends.h"  // VisibilityChoice, FitBackendChoice, ReflectanceFitter, their factories
#include "fit/neighbour_fill.h"
#include "fit/reflectance_fit.h"
#include "fit/materials.h"
#include "fit/photo_shadows.h"
#include "fit/residual_alignment.h"
#include "fit/shading_normals.h"
#include "base/mesh_view.h"
#include "base/output_file.h"
#include "model/defaults.h"
#include "io/output_ply.h"
#include "io/vertex_quality.h"  // QualityOutput
#include "samples/samples.h"
#include "inputs/viewpoints.h"
#include "registration/registration.h"
#include "visibility/visibility.h"

namespace vbrdf {

// Every default is the product's (model/defaults.h: the lobe, T_s, T_d, the diffuse form); the
// run copies reflectance.lobe into gather.lobe.
struct FitSettings {
  GatherSettings gather;
  VisibilitySettings visibility;
  VisibilityChoice visibility_choice = VisibilityChoice::Auto;
  bool fit_reflectance = true;         // false: basic diffuse colour only (no k_d/k_s/alpha)
  ReflectanceFitOptions reflectance;               // its specular_threshold is taken from gather
  DiffuseTermChoice diffuse_choice = kFitDiffuseChoice;
  FitBackendChoice fit_backend = FitBackendChoice::Auto;
  QualityOutput quality = QualityOutput::DQ;  // what goes into vertex quality
  ColorCorrectionChoice color_correction = ColorCorrectionChoice::Auto;
  // Centres of the chart's corner patches (dark skin, bluish green, black, white; x y each, image
  // pixels) in the first photo of a viewpoint: empty = detect; 8 numbers = the same for every
  // viewpoint; 8 per viewpoint = one group each, viewpoints in order of their first raster.
  std::vector<float> chart_corners;
  ExposureMode exposure = ExposureMode::Auto;  // per-photo normalisation by the chart's neutrals
  std::string light_file;   // "" = the default rule (light_file.h resolve_light_file); .lp, .json or .dome (light_source.h)
  float dome_radius = 0;     // > 0: the .lp's directions are point lights this far from the mesh's centre
  float light_unit_scale = 0;  // mesh units per unit of the light file's positions (0: .json 1, .dome required)
  std::string output_ply;   // "" = <project folder>/<project name>_brdf.ply
  // An existing output PLY / report: replaced (and the log says so) or the run refused before any
  // work (base/output_file.h). Replace by default: re-running a script into the same file is the
  // normal loop, and the inputs themselves can never be outputs.
  OverwritePolicy overwrite = OverwritePolicy::Replace;
  // Vertices no photo sees keep "no model" unless within this many edges of a modelled vertex
  // (neighbour_fill.h); 0 = off. Seen vertices without a usable sample are always filled.
  int fill_unseen_rings = 0;
  // Material stage (materials.h): materials found from the data, a lobe per material
  // from the pooled samples, every vertex of a glossy material with a specular term where the
  // held-out photos show it helps. CPU, after either fit back end. Keeps the usable (and grazing)
  // samples in memory (28 bytes each) until the stage ran. On by default.
  bool materials = true;
  MaterialOptions material_options;
  // Samples far darker than their vertex's model although the mesh lets the light reach them
  // (photo_shadows.h): left out, the vertex refitted. On by default; off for comparisons.
  PhotoShadowSettings photo_shadows;
  // The diffuse reflectance deconvolved through the photos' pixel footprints where they straddle an
  // albedo edge (fit/albedo_deconvolution.h): each vertex's own albedo instead of the footprint's
  // blend of its neighbours' (sharp material boundaries and painted lines). The result's
  // diffuse_deconvolved = 1 marks those vertices; the relighting evaluation predicts photos there
  // through the same footprints. reflectance fit only. On by default.
  bool deconvolve_albedo = true;
  DeconvolutionSettings deconvolution;
  // Each viewpoint's camera measured against its photos and corrected where it is off by more than
  // the threshold (registration/registration.h); the corrected cameras go into
  // <ply stem>_registered.mlp beside the result. Off: the cameras as given.
  RegistrationSettings registration;
  // A viewpoint whose camera the registration corrected is checked and refined by the fitted
  // model's residual (fit/residual_alignment.h): the correction is refused where the given camera
  // explains the photos better, else its shift is refined to where the residual is least.
  ResidualAlignmentSettings registration_residual;
  // Each vertex's shading normal refined from its samples, jointly with its reflectance
  // (fit/shading_normals.h): fit with the mesh's normals, refine, shade the samples again, fit
  // again. Visibility and shadows keep the mesh. The PLY's nx ny nz are the refined normals
  // (mesh_nx ny nz keep the mesh's). reflectance fit only; vertices the samples do not determine keep
  // the mesh normal.
  ShadingNormalSettings shading_normals;
};

struct FitInput {
  MeshView mesh;
  std::string mesh_name;               // for messages
  std::string mesh_path;               // the mesh file (never overwritten; may be empty)
  std::vector<uint8_t> mesh_colors;    // RGBA8 per vertex (current colours, kept where unseen)
  std::vector<Raster> rasters;
  std::string project_path;            // the .mlp, used for default paths (may be empty)
  // "Only on selection": per vertex, 0 = leave out (no sample is taken: it reads as seen by no
  // photo, keeps its input colour, fit_status 0 unless fillUnseenRings reaches it). Empty: all.
  std::vector<uint8_t> vertex_mask;
};



// Checks everything that can be checked before any work (inputs/input_check.h, as coverage does):
// non-empty mesh with normals, a selection of one entry per vertex (or none), at least one raster,
// every raster with a valid, registered shot and an existing photo. Throws InputError with a
// message naming the item and the fix.
void validate_input(const FitInput &input);

struct FitResult {
  RegistrationResult registration;        // per viewpoint: measured, corrected or why not (empty when off)
  // The shading normals (3 per vertex, unit): the mesh's where the photos do not determine them.
  // Empty when refinement is off or did not run (no reflectance fit): the mesh's normals throughout.
  std::vector<float> shading_normals;
  std::vector<float> normal_moved;        // per vertex: degrees from the mesh normal, -1 not determined
  ShadingNormalCounts shading_normal_counts;
  std::string shading_normal_note;        // the report's summary (per viewpoint: median and p95 degrees)
  std::string registered_project;         // the .mlp with the corrected cameras ("" when none was corrected)
  std::vector<DiffuseEstimate> diffuse;   // per vertex
  std::vector<VertexFit> fits;            // per vertex (empty when fit_reflectance is off)
  std::vector<float> quality;             // per vertex, as chosen by FitSettings::quality
  std::vector<uint8_t> colors_rgba;       // display colours: sRGB of rho where valid, else the input colour
  std::vector<VertexAttribute> attributes;// what goes into the PLY
  GatherStats gather;
  std::string visibility_backend;         // name of the back end that ran
  std::string depth_passes;               // camera passes run, sizes of the depth maps (pass_size.h)
  std::string fit_backend;                // name of the fit back end ("" when not fitted)
  size_t fit_full = 0, fit_diffuse_only = 0, fit_none = 0, fit_converged = 0, fit_iterations = 0;
  size_t fit_weak = 0, fit_neighbours = 0;  // fit_status 4 and 3
  size_t rim_samples_demoted = 0;           // rim samples left out: their vertex has clean ones
  size_t photo_shadow_samples = 0, photo_shadow_vertices = 0;  // photo_shadows.h: flagged, refitted
  NeighbourFillStats fill;
  // Per vertex, 1 where k_d C was deconvolved through the footprints (FitSettings::deconvolve_albedo);
  // empty when the stage did not run.
  std::vector<uint8_t> albedo_deconvolved;
  DeconvolutionStats deconvolution;
  MaterialResult materials;               // material stage (FitSettings::materials); label empty when off
  DiffuseForms diffuse_forms;             // the forms fitted, per vertex where they vary (FitSettings::diffuse_choice)
  std::string diffuse_choice_note;        // how it was decided (report line; diffuse_choice.h for Auto)
  double seconds_fit = 0;
  std::string light_file;                 // the light file used (.lp, .json or .dome)
  std::string light_model;                // describe_lights: directional / point lights and their distances
  std::string light_agreement;            // the photo whose light agrees least with it (samples/light_check.h)
  std::vector<ColorCalibration> colors;   // per viewpoint (rasters_by_viewpoint order); empty when Off
  size_t color_viewpoints_corrected = 0;
  std::string output_ply;                 // where the PLY was written
  std::string report;                     // human-readable report (also written beside the PLY)
  std::vector<std::string> warnings;      // "WARNING: ..." lines: first in the report, logged when found
  std::string normals_source;             // where the normals come from (inputs/mesh_file.h)
  std::string output_note;                // "new file" / "replaces the existing file (N bytes)"
  std::string memory_note;                // a photo larger than the photo memory: how it was handled
  size_t vertices_unseen = 0, vertices_no_diffuse = 0, vertices_coloured = 0, vertices_from_mixed = 0;
  double seconds_visibility = 0, seconds_gather = 0, seconds_output = 0, seconds_registration = 0,
         seconds_normals = 0;  // shading normals: solve and re-shading (their refit counts in seconds_fit)
  // The stages around those (the report's second time line): colour chart search and correction
  // plan (in a thread of its own during the visibility passes, so not on the wall clock's path
  // unless it outlasts them), photo content checks, the diffuse-form pilot, the material stage, the neighbour fill and the albedo deconvolution.
  double seconds_colors = 0, seconds_photo_checks = 0, seconds_pilot = 0, seconds_materials = 0, seconds_fill = 0,
         seconds_deconvolution = 0;
};

// Runs the pipeline and writes the PLY and the report (<ply stem>_report.txt). Nothing is
// written if any stage fails; the two files are committed together under a lock on their folder
// (base/output_file.h), so concurrent runs leave one run's complete pair. `fitter` may be null when settings.fit_reflectance is false.
// Throws InputError / ProcessingError.
FitResult run_fit(const FitInput &input, const FitSettings &settings, VisibilityBackend &visibility,
                  ReflectanceFitter *fitter, const ProgressFn &progress, const LogFn &log);

// Default output path for a project: <folder>/<name>_brdf.ply ("vertex_brdf.ply" in the
// current folder when no project path is known).
std::string default_output_path(const std::string &project_path);

// The project with the corrected cameras written beside a result PLY: <ply stem>_registered.mlp.
std::string registered_project_path(const std::string &output_ply);

} // namespace vbrdf
