// Each filter's settings_from (parameters -> the core's settings) and the one declaration of every
// parameter the filters share (plugin/filter_parameters.h). The defaults are checked against the
// core's own defaults, and each parameter is moved off its default to see it land in its field.
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <QDomDocument>
#include <gtest/gtest.h>

#include "core/base/errors.h"
#include "core/relight/relight_render.h"
#include "coverage_filter.h"
#include "filter_parameters.h"
#include "fit_filter.h"
#include "import_photos_filter.h"
#include "meshlab_bridge.h"
#include "plugin_filters.h"
#include "relight_filter.h"
#include "sphere_filter.h"

namespace {

using namespace vbrdf_plugin;

RichParameterList defaults_of(const PluginFilter &filter) {
  RichParameterList params;
  MeshDocument document;
  filter.initParameters(document, params);
  return params;
}

// Expects `call` to throw vbrdf::InputError whose message names `param`.
template <typename F>
void expect_rejected(F call, const std::string &param) {
  try {
    call();
    ADD_FAILURE() << "no InputError for '" << param << "'";
  } catch (const vbrdf::InputError &e) {
    EXPECT_NE(std::string(e.what()).find("'" + param + "'"), std::string::npos) << e.what();
  }
}

// The whole declaration (type, default, label, tooltip, enum entries) as MeshLab saves it.
std::string declaration(const RichParameter &p) {
  QDomDocument doc;
  doc.appendChild(p.fillToXMLDocument(doc, true));
  return utf8(doc.toString());
}

// --- Fit ------------------------------------------------------------------------------------------

TEST(FitSettingsFrom, DefaultsAreTheCoresDefaults) {
  const vbrdf::FitSettings s = FitFilter::settings_from(defaults_of(FitFilter()));
  const vbrdf::FitSettings core;
  EXPECT_EQ(s.light_file, "");
  EXPECT_EQ(s.output_ply, "");
  EXPECT_EQ(s.overwrite, core.overwrite);  // on: replaced, and logged
  EXPECT_FLOAT_EQ(s.gather.specular_threshold, core.gather.specular_threshold);
  EXPECT_FLOAT_EQ(s.gather.diffuse_threshold, vbrdf::kFitDiffuseThreshold);
  EXPECT_FLOAT_EQ(s.gather.diffuse_threshold, core.gather.diffuse_threshold);
  EXPECT_FLOAT_EQ(s.gather.diffuse_threshold, vbrdf::GatherSettings().diffuse_threshold);
  EXPECT_EQ(s.gather.encoding, core.gather.encoding);
  EXPECT_FLOAT_EQ(s.gather.saturation_level, core.gather.saturation_level);
  EXPECT_EQ(s.gather.photo_cache_bytes, core.gather.photo_cache_bytes);
  EXPECT_EQ(s.visibility_choice, core.visibility_choice);
  EXPECT_FLOAT_EQ(s.visibility.depth_tolerance, core.visibility.depth_tolerance);
  EXPECT_EQ(s.visibility.shadow_map_size, 0);  // automatic
  EXPECT_EQ(s.fit_reflectance, core.fit_reflectance);
  EXPECT_EQ(s.fit_backend, core.fit_backend);
  EXPECT_FLOAT_EQ(s.reflectance.alpha_init, core.reflectance.alpha_init);
  EXPECT_EQ(s.reflectance.lobe, vbrdf::kDefaultLobe);
  EXPECT_EQ(s.reflectance.lobe, core.reflectance.lobe);
  EXPECT_EQ(s.reflectance.lobe, vbrdf::ReflectanceFitOptions().lobe);  // the core's structs on their own, too
  EXPECT_EQ(s.reflectance.lobe, vbrdf::GatherSettings().lobe);
  EXPECT_EQ(s.reflectance.lobe, vbrdf::RelightRenderSettings().lobe);
  EXPECT_EQ(s.diffuse_choice, vbrdf::kFitDiffuseChoice);
  EXPECT_EQ(s.reflectance.max_iterations, core.reflectance.max_iterations);
  EXPECT_EQ(s.reflectance.min_specular_samples, core.reflectance.min_specular_samples);
  EXPECT_EQ(s.fill_unseen_rings, core.fill_unseen_rings);
  EXPECT_EQ(s.materials, core.materials);
  EXPECT_EQ(s.deconvolve_albedo, core.deconvolve_albedo);
  EXPECT_EQ(s.quality, core.quality);
  EXPECT_EQ(s.color_correction, core.color_correction);
  EXPECT_TRUE(s.chart_corners.empty());
  EXPECT_EQ(s.exposure, core.exposure);
}

TEST(FitSettingsFrom, EveryParameterReachesItsField) {
  RichParameterList p = defaults_of(FitFilter());
  p.setValue("lightFile", StringValue("a.lp"));
  p.setValue("domeRadius", FloatValue(2.5f));
  p.setValue("lightUnitScale", FloatValue(10.0f));
  p.setValue("outputPly", StringValue("out.ply"));
  p.setValue("overwriteOutput", BoolValue(false));
  p.setValue("specularThreshold", FloatValue(0.8f));
  p.setValue("diffuseThreshold", FloatValue(0.3f));
  p.setValue("photoEncoding", EnumValue(2));
  p.setValue("saturationLevel", FloatValue(0.95f));
  p.setValue("visibilityBackend", EnumValue(2));
  p.setValue("depthTolerance", FloatValue(0.01f));
  p.setValue("shadowMapSize", IntValue(512));
  p.setValue("memoryBudgetMB", IntValue(100));
  p.setValue("fitReflectance", BoolValue(false));
  p.setValue("fitBackend", EnumValue(1));
  p.setValue("initialShininess", FloatValue(20.0f));
  p.setValue("specularLobe", EnumValue(0));
  p.setValue("diffuseTerm", EnumValue(1));
  p.setValue("findMaterials", BoolValue(true));
  p.setValue("sharpenAlbedoEdges", BoolValue(false));
  p.setValue("refineRegistration", BoolValue(true));
  p.setValue("refineNormals", BoolValue(false));
  p.setValue("maxIterations", IntValue(7));
  p.setValue("minSpecularSamples", IntValue(3));
  p.setValue("fillUnseenRings", IntValue(4));
  p.setValue("qualityOutput", EnumValue(2));
  p.setValue("colorCorrection", EnumValue(2));
  p.setValue("chartCorners", StringValue("1 2, 3 4; 5 6 7 8"));
  p.setValue("exposureNormalisation", EnumValue(2));
  const vbrdf::FitSettings s = FitFilter::settings_from(p);
  EXPECT_EQ(s.light_file, "a.lp");
  EXPECT_FLOAT_EQ(s.dome_radius, 2.5f);
  EXPECT_FLOAT_EQ(s.light_unit_scale, 10.0f);
  EXPECT_EQ(s.output_ply, "out.ply");
  EXPECT_TRUE(s.registration.enabled);
  EXPECT_FALSE(s.shading_normals.enabled);
  EXPECT_EQ(s.overwrite, vbrdf::OverwritePolicy::Refuse);
  EXPECT_FLOAT_EQ(s.gather.specular_threshold, 0.8f);
  EXPECT_FLOAT_EQ(s.gather.diffuse_threshold, 0.3f);
  EXPECT_EQ(s.gather.encoding, vbrdf::PhotoEncoding::Linear);
  EXPECT_FLOAT_EQ(s.gather.saturation_level, 0.95f);
  EXPECT_EQ(s.reflectance.lobe, vbrdf::LobeForm::PhongRE);
  EXPECT_EQ(s.diffuse_choice, vbrdf::DiffuseTermChoice::Lambert);
  EXPECT_TRUE(s.materials);
  EXPECT_FALSE(s.deconvolve_albedo);
  EXPECT_EQ(s.gather.photo_cache_bytes, size_t(100) << 20);
  EXPECT_EQ(s.visibility_choice, vbrdf::VisibilityChoice::CPU);
  EXPECT_FLOAT_EQ(s.visibility.depth_tolerance, 0.01f);
  EXPECT_EQ(s.visibility.shadow_map_size, 512);
  EXPECT_FALSE(s.fit_reflectance);
  EXPECT_EQ(s.fit_backend, vbrdf::FitBackendChoice::GPU);
  EXPECT_FLOAT_EQ(s.reflectance.alpha_init, 20.0f);
  EXPECT_EQ(s.reflectance.max_iterations, 7);
  EXPECT_EQ(s.reflectance.min_specular_samples, 3);
  EXPECT_EQ(s.fill_unseen_rings, 4);
  EXPECT_EQ(s.quality, vbrdf::QualityOutput::RMSE);
  EXPECT_EQ(s.color_correction, vbrdf::ColorCorrectionChoice::Required);
  EXPECT_EQ(s.chart_corners, (std::vector<float>{1, 2, 3, 4, 5, 6, 7, 8}));
  EXPECT_EQ(s.exposure, vbrdf::ExposureMode::On);
}

TEST(FitSettingsFrom, OutOfRangeValuesNameTheirParameter) {
  const RichParameterList defaults = defaults_of(FitFilter());
  auto rejects = [&](const char *name, const Value &bad) {
    RichParameterList p = defaults;
    p.setValue(name, bad);
    expect_rejected([&] { FitFilter::settings_from(p); }, name);
  };
  rejects("specularThreshold", FloatValue(0.0f));
  rejects("diffuseThreshold", FloatValue(1.0f));
  rejects("saturationLevel", FloatValue(1.5f));
  rejects("depthTolerance", FloatValue(std::nanf("")));
  rejects("shadowMapSize", IntValue(32));
  rejects("memoryBudgetMB", IntValue(8));
  rejects("initialShininess", FloatValue(0.5f));
  rejects("maxIterations", IntValue(-1));
  rejects("specularLobe", EnumValue(3));
  rejects("diffuseTerm", EnumValue(3));
  rejects("diffuseTerm", EnumValue(-1));
  rejects("domeRadius", FloatValue(-1.0f));
  rejects("lightUnitScale", FloatValue(std::nanf("")));
  rejects("minSpecularSamples", IntValue(0));
  rejects("fillUnseenRings", IntValue(-2));
  rejects("chartCorners", StringValue("1 2 3"));
  rejects("chartCorners", StringValue("1 2 3 4 5 6 7 x"));
}

// --- Coverage ---------------------------------------------------------------------------------------

TEST(CoverageSettingsFrom, DefaultsAgreeWithTheFit) {
  const vbrdf::CoverageSettings s = CoverageFilter::settings_from(defaults_of(CoverageFilter()));
  const vbrdf::FitSettings fit = FitFilter::settings_from(defaults_of(FitFilter()));
  // "Fully covered" means what the fit needs for a reflectance fit (the fit's minimum, not a lower one).
  EXPECT_EQ(s.min_specular, fit.reflectance.min_specular_samples);
  // 0 = automatic shadow map, in coverage as in the fit (and 0 is accepted there).
  EXPECT_EQ(s.visibility.shadow_map_size, fit.visibility.shadow_map_size);
  EXPECT_FLOAT_EQ(s.gather.specular_threshold, fit.gather.specular_threshold);
  EXPECT_FLOAT_EQ(s.gather.saturation_level, fit.gather.saturation_level);
  EXPECT_FLOAT_EQ(s.visibility.depth_tolerance, fit.visibility.depth_tolerance);
  EXPECT_EQ(s.gather.photo_cache_bytes, fit.gather.photo_cache_bytes);
  // Deliberately not the fit's: coverage asks for well-lit samples (the thesis's T_d).
  EXPECT_FLOAT_EQ(s.gather.diffuse_threshold, vbrdf::CoverageSettings().gather.diffuse_threshold);
  EXPECT_EQ(s.viewpoint_raster, -1);
  EXPECT_EQ(s.min_diffuse, vbrdf::CoverageSettings().min_diffuse);
  EXPECT_EQ(s.min_specular, vbrdf::CoverageSettings().min_specular);
  EXPECT_FLOAT_EQ(s.poor_dq, vbrdf::CoverageSettings().poor_dq);
  EXPECT_FLOAT_EQ(s.poor_sq, vbrdf::CoverageSettings().poor_sq);
  EXPECT_FLOAT_EQ(s.suggest.min_elevation_deg, vbrdf::CoverageSettings().suggest.min_elevation_deg);
}

TEST(CoverageSettingsFrom, TheImportRunsTheFiltersDefaults) {
  const vbrdf::CoverageSettings d = CoverageFilter::default_settings();
  const vbrdf::CoverageSettings s = CoverageFilter::settings_from(defaults_of(CoverageFilter()));
  EXPECT_EQ(d.min_specular, s.min_specular);
  EXPECT_EQ(d.min_diffuse, s.min_diffuse);
  EXPECT_EQ(d.visibility.shadow_map_size, s.visibility.shadow_map_size);
  EXPECT_FLOAT_EQ(d.gather.diffuse_threshold, s.gather.diffuse_threshold);
}

TEST(CoverageSettingsFrom, EveryParameterReachesItsField) {
  RichParameterList p = defaults_of(CoverageFilter());
  p.setValue("lightFile", StringValue("b.lp"));
  p.setValue("suggestionFile", StringValue("s.txt"));
  p.setValue("viewpointRaster", IntValue(3));
  p.setValue("specularThreshold", FloatValue(0.85f));
  p.setValue("diffuseThreshold", FloatValue(0.4f));
  p.setValue("minDiffuseSamples", IntValue(2));
  p.setValue("minSpecularSamples", IntValue(5));
  p.setValue("minLightElevation", FloatValue(12.0f));
  p.setValue("poorDiffuseQuality", FloatValue(1.2f));
  p.setValue("poorSpecularQuality", FloatValue(0.7f));
  p.setValue("colorByCoverage", BoolValue(false));
  p.setValue("selectNewViewVertices", BoolValue(false));
  p.setValue("useFitQuality", BoolValue(false));
  p.setValue("photoEncoding", EnumValue(1));
  p.setValue("saturationLevel", FloatValue(0.9f));
  p.setValue("visibilityBackend", EnumValue(1));
  p.setValue("depthTolerance", FloatValue(0.004f));
  p.setValue("shadowMapSize", IntValue(1024));
  p.setValue("memoryBudgetMB", IntValue(64));
  const vbrdf::CoverageSettings s = CoverageFilter::settings_from(p);
  EXPECT_EQ(s.light_file, "b.lp");
  EXPECT_EQ(s.suggestion_file, "s.txt");
  EXPECT_EQ(s.viewpoint_raster, 3);
  EXPECT_FLOAT_EQ(s.gather.specular_threshold, 0.85f);
  EXPECT_FLOAT_EQ(s.gather.diffuse_threshold, 0.4f);
  EXPECT_EQ(s.min_diffuse, 2);
  EXPECT_EQ(s.min_specular, 5);
  EXPECT_FLOAT_EQ(s.suggest.min_elevation_deg, 12.0f);
  EXPECT_FLOAT_EQ(s.poor_dq, 1.2f);
  EXPECT_FLOAT_EQ(s.poor_sq, 0.7f);
  EXPECT_EQ(s.gather.encoding, vbrdf::PhotoEncoding::SRGB);
  EXPECT_FLOAT_EQ(s.gather.saturation_level, 0.9f);
  EXPECT_EQ(s.visibility_choice, vbrdf::VisibilityChoice::GL);
  EXPECT_FLOAT_EQ(s.visibility.depth_tolerance, 0.004f);
  EXPECT_EQ(s.visibility.shadow_map_size, 1024);
  EXPECT_EQ(s.gather.photo_cache_bytes, size_t(64) << 20);
  const CoverageFilter::Display d = CoverageFilter::display_from(p);
  EXPECT_FALSE(d.color_by_class);
  EXPECT_FALSE(d.select_new_view);
  EXPECT_FALSE(d.use_fit_quality);
}

TEST(CoverageSettingsFrom, OutOfRangeValuesNameTheirParameter) {
  const RichParameterList defaults = defaults_of(CoverageFilter());
  auto rejects = [&](const char *name, const Value &bad) {
    RichParameterList p = defaults;
    p.setValue(name, bad);
    expect_rejected([&] { CoverageFilter::settings_from(p); }, name);
  };
  rejects("viewpointRaster", IntValue(-2));
  rejects("minSpecularSamples", IntValue(0));
  rejects("minDiffuseSamples", IntValue(0));
  rejects("minLightElevation", FloatValue(85.0f));
  rejects("poorDiffuseQuality", FloatValue(2.5f));
  rejects("shadowMapSize", IntValue(20000));
  rejects("diffuseThreshold", FloatValue(-0.1f));
}

// --- Relight ----------------------------------------------------------------------------------------

TEST(RelightSettingsFrom, DefaultsAndEveryParameter) {
  const RichParameterList defaults = defaults_of(RelightFilter());
  const RelightFilter::Settings d = RelightFilter::settings_from(defaults);
  EXPECT_TRUE(d.render_rasters);
  EXPECT_FALSE(d.novel_view);
  EXPECT_EQ(d.render.shadow_map_size, 0);
  EXPECT_EQ(d.output.color_correction, vbrdf::ColorCorrectionChoice::Auto);
  EXPECT_EQ(d.output.encoding, vbrdf::PhotoEncoding::Auto);
  EXPECT_FLOAT_EQ(d.output.heat_map_max_de, vbrdf::RelightOutputOptions().heat_map_max_de);

  RichParameterList p = defaults;
  p.setValue("fitResultPly", StringValue("fit.ply"));
  p.setValue("rasterProject", StringValue("held.mlp"));
  p.setValue("lightFile", StringValue("held.lp"));
  p.setValue("outputFolder", StringValue("out"));
  p.setValue("renderRasters", BoolValue(false));
  p.setValue("novelView", BoolValue(true));
  p.setValue("viewRaster", IntValue(2));
  p.setValue("orbitAzimuth", FloatValue(30.0f));
  p.setValue("orbitElevation", FloatValue(-20.0f));
  p.setValue("distanceScale", FloatValue(1.5f));
  p.setValue("novelLight", Point3fValue(vcg::Point3f(0.0f, 3.0f, 4.0f)));
  p.setValue("heatMapMax", FloatValue(5.0f));
  p.setValue("photoEncoding", EnumValue(1));
  p.setValue("colorCorrection", EnumValue(0));
  p.setValue("chartCorners", StringValue("1 2 3 4 5 6 7 8"));
  p.setValue("exposureNormalisation", EnumValue(1));
  p.setValue("shadowMapSize", IntValue(256));
  const RelightFilter::Settings s = RelightFilter::settings_from(p);
  EXPECT_EQ(s.fit_result_ply, "fit.ply");
  EXPECT_EQ(s.raster_project, "held.mlp");
  EXPECT_EQ(s.light_file, "held.lp");
  EXPECT_EQ(s.output_folder, "out");
  EXPECT_FALSE(s.render_rasters);
  EXPECT_TRUE(s.novel_view);
  EXPECT_EQ(s.view_raster, 2);
  EXPECT_FLOAT_EQ(s.azimuth, 30.0f);
  EXPECT_FLOAT_EQ(s.elevation, -20.0f);
  EXPECT_FLOAT_EQ(s.distance_scale, 1.5f);
  EXPECT_NEAR(s.novel_light[0], 0.0f, 1e-6f);  // normalised
  EXPECT_NEAR(s.novel_light[1], 0.6f, 1e-6f);
  EXPECT_NEAR(s.novel_light[2], 0.8f, 1e-6f);
  EXPECT_FLOAT_EQ(s.output.heat_map_max_de, 5.0f);
  EXPECT_EQ(s.output.encoding, vbrdf::PhotoEncoding::SRGB);
  EXPECT_EQ(s.output.color_correction, vbrdf::ColorCorrectionChoice::Off);
  EXPECT_EQ(s.output.chart_corners.size(), 8u);
  EXPECT_EQ(s.output.exposure, vbrdf::ExposureMode::Off);
  EXPECT_EQ(s.render.shadow_map_size, 256);
}

TEST(RelightSettingsFrom, RejectsNothingToRenderAndBadValues) {
  const RichParameterList defaults = defaults_of(RelightFilter());
  RichParameterList none = defaults;
  none.setValue("renderRasters", BoolValue(false));
  expect_rejected([&] { RelightFilter::settings_from(none); }, "renderRasters");
  RichParameterList zero_light = defaults;
  zero_light.setValue("novelLight", Point3fValue(vcg::Point3f(0.0f, 0.0f, 0.0f)));
  expect_rejected([&] { RelightFilter::settings_from(zero_light); }, "novelLight");
  RichParameterList shadow = defaults;
  shadow.setValue("shadowMapSize", IntValue(-1));
  expect_rejected([&] { RelightFilter::settings_from(shadow); }, "shadowMapSize");
}

// --- Sphere -----------------------------------------------------------------------------------------

TEST(SphereSettingsFrom, ManualOutlinesAndTheirChecks) {
  const RichParameterList defaults = defaults_of(SphereFilter());
  const SphereFilter::Settings d = SphereFilter::settings_from(defaults);
  EXPECT_EQ(d.viewpoint_raster, -1);
  EXPECT_TRUE(d.manual.empty());
  EXPECT_EQ(d.sphere_count, 1);
  EXPECT_EQ(d.output, "");

  RichParameterList p = defaults;
  p.setValue("sphereCenterX", FloatValue(100.0f));
  p.setValue("sphereCenterY", FloatValue(50.0f));
  p.setValue("sphereRadius", FloatValue(20.0f));
  p.setValue("sphere2CenterX", FloatValue(300.0f));
  p.setValue("sphere2CenterY", FloatValue(60.0f));
  p.setValue("sphere2Radius", FloatValue(25.0f));
  p.setValue("sphereCount", IntValue(2));
  p.setValue("sphereRadiusWorld", FloatValue(0.5f));
  p.setValue("photoEncoding", EnumValue(2));
  p.setValue("outputLightFile", StringValue("s.lp"));
  p.setValue("viewpointRaster", IntValue(4));
  const SphereFilter::Settings s = SphereFilter::settings_from(p);
  ASSERT_EQ(s.manual.size(), 2u);
  EXPECT_DOUBLE_EQ(s.manual[0].x, 100.0);
  EXPECT_DOUBLE_EQ(s.manual[0].y, 50.0);
  EXPECT_DOUBLE_EQ(s.manual[0].r, 20.0);
  EXPECT_DOUBLE_EQ(s.manual[1].x, 300.0);
  EXPECT_DOUBLE_EQ(s.manual[1].r, 25.0);
  EXPECT_EQ(s.sphere_count, 2);
  EXPECT_DOUBLE_EQ(s.radius_world, 0.5);
  EXPECT_EQ(s.encoding, vbrdf::PhotoEncoding::Linear);
  EXPECT_EQ(s.output, "s.lp");
  EXPECT_EQ(s.viewpoint_raster, 4);

  RichParameterList second_only = defaults;
  second_only.setValue("sphere2Radius", FloatValue(25.0f));
  expect_rejected([&] { SphereFilter::settings_from(second_only); }, "sphereRadius");
  RichParameterList negative = defaults;
  negative.setValue("sphereRadius", FloatValue(-1.0f));
  expect_rejected([&] { SphereFilter::settings_from(negative); }, "sphereRadius");
  RichParameterList count = defaults;
  count.setValue("sphereCount", IntValue(5));
  expect_rejected([&] { SphereFilter::settings_from(count); }, "sphereCount");
}

// --- Import -----------------------------------------------------------------------------------------

TEST(ImportSettingsFrom, PhotoListSphereModeAndChecks) {
  const RichParameterList defaults = defaults_of(ImportPhotosFilter());
  const ImportPhotosFilter::Settings d = ImportPhotosFilter::settings_from(defaults);
  EXPECT_TRUE(d.photo_files.empty());
  EXPECT_FALSE(d.lights_from_sphere);
  EXPECT_EQ(d.reference_raster, -1);
  EXPECT_TRUE(d.update_coverage);
  EXPECT_EQ(d.sphere.r, 0.0);

  RichParameterList p = defaults;
  p.setValue("photoFiles", StringValue(" a.png; b.png\nc.png ;"));
  p.setValue("photoFolder", StringValue(" photos "));
  p.setValue("referenceRaster", IntValue(1));
  p.setValue("lightSource", EnumValue(1));
  p.setValue("lightFile", StringValue("old.lp"));
  p.setValue("sphereCenterX", FloatValue(10.0f));
  p.setValue("sphereCenterY", FloatValue(11.0f));
  p.setValue("sphereRadius", FloatValue(12.0f));
  p.setValue("outputLightFile", StringValue("new.lp"));
  p.setValue("updateCoverage", BoolValue(false));
  const ImportPhotosFilter::Settings s = ImportPhotosFilter::settings_from(p);
  EXPECT_EQ(s.photo_files, (std::vector<std::string>{"a.png", "b.png", "c.png"}));
  EXPECT_EQ(s.photo_folder, "photos");
  EXPECT_EQ(s.reference_raster, 1);
  EXPECT_TRUE(s.lights_from_sphere);
  EXPECT_EQ(s.light_file, "old.lp");
  EXPECT_DOUBLE_EQ(s.sphere.x, 10.0);
  EXPECT_DOUBLE_EQ(s.sphere.y, 11.0);
  EXPECT_DOUBLE_EQ(s.sphere.r, 12.0);
  EXPECT_EQ(s.output_light_file, "new.lp");
  EXPECT_FALSE(s.update_coverage);

  RichParameterList negative = defaults;
  negative.setValue("sphereRadius", FloatValue(-3.0f));
  expect_rejected([&] { ImportPhotosFilter::settings_from(negative); }, "sphereRadius");
  RichParameterList reference = defaults;
  reference.setValue("referenceRaster", IntValue(-5));
  expect_rejected([&] { ImportPhotosFilter::settings_from(reference); }, "referenceRaster");
}

// --- One declaration per shared parameter ----------------------------------------------------------

TEST(SharedParameters, EveryFilterDeclaresASharedNameIdentically) {
  // name -> (filter, declaration)
  std::map<std::string, std::vector<std::pair<std::string, std::string>>> seen;
  std::map<std::string, std::vector<std::string>> types_and_labels;
  for (const auto &f : make_plugin_filters()) {
    const RichParameterList params = defaults_of(*f);
    for (const RichParameter &p : params) {
      seen[utf8(p.name())].push_back({utf8(f->name()), declaration(p)});
      types_and_labels[utf8(p.name())].push_back(utf8(p.stringType() + " " + p.fieldDescription()));
    }
  }
  const std::set<std::string> shared_names = {
      shared::kLightFile,         shared::kSpecularThreshold, shared::kDiffuseThreshold,
      shared::kPhotoEncoding,     shared::kSaturationLevel,   shared::kVisibilityBackend,
      shared::kDepthTolerance,    shared::kShadowMapSize,     shared::kMemoryBudgetMB,
      shared::kMinSpecularSamples, shared::kViewpointRaster,  shared::kSphereCenterX,
      shared::kSphereCenterY,     shared::kSphereRadius,      shared::kOutputLightFile,
      shared::kColorCorrection,   shared::kChartCorners,      shared::kExposureNormalisation,
      shared::kDomeRadius,        shared::kLightUnitScale,   shared::kOnlySelected,
      shared::kQualityOutput};
  // Their default (and the tooltip's last words) differ on purpose: filter_parameters.h says why.
  const std::set<std::string> deliberate = {shared::kDiffuseThreshold, shared::kOutputLightFile};
  for (const auto &kv : seen) {
    if (kv.second.size() < 2) continue;
    EXPECT_TRUE(shared_names.count(kv.first)) << kv.first << " is declared by " << kv.second.size()
                                               << " filters but is not in filter_parameters.h";
    if (deliberate.count(kv.first)) {
      for (const std::string &t : types_and_labels[kv.first]) EXPECT_EQ(t, types_and_labels[kv.first][0]) << kv.first;
      continue;
    }
    for (const auto &decl : kv.second)
      EXPECT_EQ(decl.second, kv.second[0].second)
          << kv.first << ": " << decl.first << " and " << kv.second[0].first << " declare it differently";
  }
  for (const std::string &name : shared_names)
    EXPECT_GE(seen[name].size(), 2u) << name << " is in filter_parameters.h but used by one filter only";
}

TEST(SharedParameters, ParseCornersAcceptsSeparatorsAndRejectsOthers) {
  EXPECT_EQ(parse_corners("", "chartCorners"), std::vector<float>());
  EXPECT_EQ(parse_corners("1,2;3 4  5,6;7 8", "chartCorners"), (std::vector<float>{1, 2, 3, 4, 5, 6, 7, 8}));
  expect_rejected([] { parse_corners("1 2 3 4 5 6 7 inf", "chartCorners"); }, "chartCorners");
  expect_rejected([] { parse_corners("1 2 3 4 5 6 7 8 9", "chartCorners"); }, "chartCorners");
}

TEST(SharedParameters, DefaultOutputLightFileSitsBesideTheProject) {
  EXPECT_EQ(shared::default_output_light_file("/data/scan/project.mlp", shared::OutputLightFileUse::Sphere),
            "/data/scan/project_sphere.lp");
  EXPECT_EQ(shared::default_output_light_file("/data/scan/project.mlp", shared::OutputLightFileUse::Import),
            "/data/scan/project_lights.lp");
}

// --- Typed paths -----------------------------------------------------------------------------------
// MeshLab 2020.09's file widgets return only a path picked with "...", so a typed path would be
// lost. Every path parameter is therefore a string field; the dialog's line edit
// (LineEditWidget::collectWidgetValue) hands the typed text over as a StringValue, which is what
// these tests feed in.

TEST(TypedPaths, NoFilterDeclaresAFileFieldThatDropsTypedText) {
  size_t paths = 0;
  for (const auto &f : make_plugin_filters())
    for (const RichParameter &p : defaults_of(*f)) {
      EXPECT_FALSE(p.value().isFileName()) << utf8(f->name()) << ": '" << utf8(p.name())
                                           << "' is a MeshLab file field, which ignores a typed path";
      EXPECT_FALSE(p.toolTip().isEmpty()) << utf8(f->name()) << ": '" << utf8(p.name()) << "' has no tooltip";
      if (p.toolTip().contains("Type or paste the path")) ++paths;
    }
  EXPECT_GE(paths, 8u);  // lightFile x3, outputPly, suggestionFile, outputLightFile x2, fitResultPly, rasterProject
}

TEST(TypedPaths, ATypedPathReachesEveryFiltersSettings) {
  RichParameterList fit = defaults_of(FitFilter());
  fit.setValue("lightFile", StringValue("  typed/lights.lp "));  // as typed, stray blanks included
  fit.setValue("outputPly", StringValue("/tmp/typed out.ply"));
  const vbrdf::FitSettings f = FitFilter::settings_from(fit);
  EXPECT_EQ(f.light_file, "typed/lights.lp");
  EXPECT_EQ(f.output_ply, "/tmp/typed out.ply");

  RichParameterList coverage = defaults_of(CoverageFilter());
  coverage.setValue("suggestionFile", StringValue("typed_next.txt"));
  EXPECT_EQ(CoverageFilter::settings_from(coverage).suggestion_file, "typed_next.txt");

  RichParameterList relight = defaults_of(RelightFilter());
  relight.setValue("fitResultPly", StringValue("typed.ply"));
  relight.setValue("rasterProject", StringValue("held/typed.mlp"));
  const RelightFilter::Settings r = RelightFilter::settings_from(relight);
  EXPECT_EQ(r.fit_result_ply, "typed.ply");
  EXPECT_EQ(r.raster_project, "held/typed.mlp");
}

TEST(TypedPaths, AScriptWrittenWithFileFieldsStillWorks) {
  // What meshlabserver builds from an older .mlx: the script's own parameter types, then the
  // filter's defaults for whatever the script does not list.
  QDomDocument doc;
  doc.setContent(QString("<Param name='lightFile' type='RichOpenFile' value='old.lp' exts_cardinality='1' "
                         "ext_val0='Light files (*.lp)' description='Light file' tooltip='t'/>"));
  RichParameterList script;
  script.pushFromQDomElement(doc.documentElement());
  ASSERT_TRUE(script.getParameterByName("lightFile").value().isFileName());
  for (const RichParameter &p : defaults_of(FitFilter()))
    if (!script.hasParameter(p.name())) script.addParam(p);
  EXPECT_EQ(FitFilter::settings_from(script).light_file, "old.lp");
}

TEST(TypedPaths, MessagesNameFieldsByTheirDialogLabels) {
  const RichParameterList fit = defaults_of(FitFilter());
  const std::string message = with_labels("Parameter 'maxIterations' must be in [0, 10000]; see 'lightFile'.", fit);
  EXPECT_EQ(message, "Parameter 'Max iterations' [maxIterations] must be in [0, 10000]; see 'Light file (.lp, .json, "
                     ".dome)' [lightFile].");
  EXPECT_EQ(with_labels("nothing quoted", fit), "nothing quoted");
}

} // namespace
