#pragma once
// The filter parameters that two or more Vertex BRDF filters share: each one is declared (name,
// label, tooltip, default) and read back with its range check once, here, and every filter adds
// and reads it through these functions, so a default, a range or a tooltip cannot drift between
// filters. Parameters of one filter only stay in that filter's file. utf8() and canonical_path()
// are in meshlab_bridge.h.
//
// Names are what .mlx scripts refer to: never rename one. Readers throw vbrdf::InputError
// ("Parameter '<name>' ...") for a value out of range; they never return NaN.
//
// Where the filters could differ, one rule holds in all of them (docs/architecture.md#filter-parameters-one-owner-each):
// - minSpecularSamples: 2 (the fit's) in coverage too, so that "fully covered" means what the fit
//   needs for a reflectance fit rather than a diffuse-only one.
// - shadowMapSize: 0 = automatic (from the mesh's edge lengths) in every filter, coverage included.
// - viewpointRaster -1: MeshLab's current raster (the last one loaded or imported, unless another
//   was selected), in coverage as in the sphere filter.
// Two defaults differ on purpose and say why: diffuseThreshold (fit 0.2, coverage 0.5: coverage
// asks the photographer for well-lit samples) and outputLightFile (the sphere filter writes
// <project>_sphere.lp, sphere lights only; the import writes <project>_lights.lp, the existing .lp
// merged with the new lights).
#include <functional>
#include <string>
#include <vector>

#include "meshlab_host.h"

#include "core/calibration/color_chart.h"
#include "core/inputs/photo.h"
#include "core/run/fit_run.h"
#include "core/samples/samples.h"
#include "core/calibration/sphere_lights.h"
#include "core/visibility/visibility.h"
#include "meshlab_bridge.h"

namespace vbrdf_plugin {

// Throws vbrdf::InputError("Parameter '<param>' <what>") unless `ok`.
void require(bool ok, const char *param, const std::string &what);

// "x1 y1 ... x4 y4" (spaces, commas or semicolons between numbers), 8 per viewpoint; "" = none.
// Throws InputError naming `param` for a word that is no finite number or a count not a multiple
// of 8.
std::vector<float> parse_corners(const QString &text, const char *param);

// --- File paths ---------------------------------------------------------------------------------
// MeshLab 2020.09's file fields (RichOpenFile, RichSaveFile) drop a typed path: their widget
// (IOFileWidget in meshlab/rich_parameter_gui/richparameterwidgets.cpp) hands back only the name the
// "..." browser returned, never the text in its line edit, and it shows no tooltip. Every path
// parameter is therefore a string field: what the user types or pastes is what the filter gets.
// The tooltip says so ("type or paste the path").
void add_path(RichParameterList &params, const char *name, const QString &label, const QString &tooltip);
// The path as given ("" when empty; not resolved). Reads the string the dialog produces and also
// a file value (RichOpenFile/RichSaveFile), which an .mlx script may hold.
std::string path(const RichParameterList &params, const char *name);

// `message` with every quoted parameter name ('lightFile') replaced by its dialog label and the
// name ('Light file (.lp, .json, .dome)' [lightFile]), so that messages name fields as the user
// sees them in the dialog and scripts can still find the name.
std::string with_labels(const std::string &message, const RichParameterList &params);

namespace shared {

extern const char *const kLightFile;              // "lightFile"
extern const char *const kDomeRadius;             // "domeRadius"
extern const char *const kLightUnitScale;         // "lightUnitScale"
extern const char *const kSpecularThreshold;      // "specularThreshold"
extern const char *const kDiffuseThreshold;       // "diffuseThreshold"
extern const char *const kPhotoEncoding;          // "photoEncoding"
extern const char *const kSaturationLevel;        // "saturationLevel"
extern const char *const kVisibilityBackend;      // "visibilityBackend"
extern const char *const kDepthTolerance;         // "depthTolerance"
extern const char *const kShadowMapSize;          // "shadowMapSize"
extern const char *const kMemoryBudgetMB;         // "memoryBudgetMB"
extern const char *const kMinSpecularSamples;     // "minSpecularSamples"
extern const char *const kViewpointRaster;        // "viewpointRaster"
extern const char *const kSphereCenterX;          // "sphereCenterX"
extern const char *const kSphereCenterY;          // "sphereCenterY"
extern const char *const kSphereRadius;           // "sphereRadius"
extern const char *const kOutputLightFile;        // "outputLightFile"
extern const char *const kColorCorrection;        // "colorCorrection"
extern const char *const kChartCorners;           // "chartCorners"
extern const char *const kExposureNormalisation;  // "exposureNormalisation"

// Every default comes from the core's table (core/model/defaults.h), which the core's settings
// structs read too.

// --- Light file (.lp) ---------------------------------------------------------------------------
// "" = the default light-file rule (vbrdf::resolve_light_file). Returned as given: the
// filter resolves it against the project folder.
void add_light_file(RichParameterList &params);
std::string light_file(const RichParameterList &params);
// domeRadius and lightUnitScale (fit, coverage, relight: wherever lightFile is read with its
// positions), right after lightFile. Both >= 0 (0 = not given); InputError otherwise.
void add_light_placement(RichParameterList &params);
void read_light_placement(const RichParameterList &params, float &dome_radius, float &unit_scale);

// --- Sample classification and photos (fit, coverage) -------------------------------------------
void add_specular_threshold(RichParameterList &params);
enum class DiffuseThresholdUse { Fit, Coverage };  // picks the default and the tooltip's last words
void add_diffuse_threshold(RichParameterList &params, DiffuseThresholdUse use);
// photoEncoding also in relight and the sphere filter.
void add_photo_encoding(RichParameterList &params);
vbrdf::PhotoEncoding photo_encoding(const RichParameterList &params);
// photoEncoding, saturationLevel, visibilityBackend, depthTolerance, shadowMapSize, memoryBudgetMB,
// in this order (the fit's and the coverage's dialogs end with them).
void add_photo_and_visibility(RichParameterList &params);
// specularThreshold, diffuseThreshold, photoEncoding, saturationLevel and memoryBudgetMB into
// `gather` (its other fields are kept).
void read_gather(const RichParameterList &params, vbrdf::GatherSettings &gather);
// visibilityBackend, depthTolerance and shadowMapSize.
void read_visibility(const RichParameterList &params, vbrdf::VisibilityChoice &choice,
                     vbrdf::VisibilitySettings &visibility);

// shadowMapSize alone (relight): 0 = automatic, else [64, 16384].
void add_shadow_map_size(RichParameterList &params);
int shadow_map_size(const RichParameterList &params);

// --- Coverage and fit ---------------------------------------------------------------------------
void add_min_specular_samples(RichParameterList &params);
int min_specular_samples(const RichParameterList &params);  // in [1, 1000]

// --- Vertex quality (fit, load result attributes) ----------------------------------------------
extern const char *const kQualityOutput;  // "qualityOutput"
void add_quality_output(RichParameterList &params);
vbrdf::QualityOutput quality_output(const RichParameterList &params);

// --- Only on selection (fit, coverage) ----------------------------------------------------------
extern const char *const kOnlySelected;  // "onlySelectedVertices", labelled as MeshLab's colour projection
void add_only_selected(RichParameterList &params);
bool only_selected(const RichParameterList &params);
// The selection as a vertex mask (per array vertex); logs how many vertices take part. Throws
// InputError naming the field when no vertex is selected.
std::vector<uint8_t> selection_mask(const MeshModel &mesh, const MeshArrays &arrays,
                                    const std::function<void(const std::string &)> &log);
// Logs how many rasters are hidden and so left out (nothing when none is).
void log_hidden_rasters(size_t hidden, size_t used, const std::function<void(const std::string &)> &log);

// --- Viewpoint (coverage, sphere) ---------------------------------------------------------------
// -1 = MeshLab's current raster (else the last one), or a raster index from 0.
void add_viewpoint_raster(RichParameterList &params);
int viewpoint_raster(const RichParameterList &params);  // >= -1 (the upper bound needs the document)
// The raster index `param` (from viewpoint_raster) names in `document`: -1 = the current raster,
// else the last one. Throws InputError when the document has no raster or `param` is too large.
size_t chosen_raster(MeshDocument &document, int param);

// --- Mirror sphere (sphere, import) -------------------------------------------------------------
// sphereCenterX, sphereCenterY, sphereRadius (pixels): radius 0 = find the sphere automatically.
void add_sphere_outline(RichParameterList &params);
// The given outline; r == 0 when the sphere is to be found. Throws InputError for a negative or
// non-finite value.
vbrdf::SphereCircle sphere_outline(const RichParameterList &params);
// The same check for another outline's three parameters (the sphere filter's second sphere).
vbrdf::SphereCircle sphere_outline(const RichParameterList &params, const char *x, const char *y, const char *r);

enum class OutputLightFileUse { Sphere, Import };  // default name: <project>_sphere.lp, _lights.lp
void add_output_light_file(RichParameterList &params, OutputLightFileUse use);
std::string output_light_file(const RichParameterList &params);  // as given ("" = the default)
// The default output .lp beside `project` (or in the working folder for an unsaved project).
std::string default_output_light_file(const std::string &project, OutputLightFileUse use);

// --- Colour correction (fit, relight) -----------------------------------------------------------
// colorCorrection, chartCorners, exposureNormalisation, in this order.
void add_color_correction(RichParameterList &params);
vbrdf::ColorCorrectionChoice color_correction(const RichParameterList &params);
std::vector<float> chart_corners(const RichParameterList &params);  // parse_corners
vbrdf::ExposureMode exposure_normalisation(const RichParameterList &params);

} // namespace shared
} // namespace vbrdf_plugin
