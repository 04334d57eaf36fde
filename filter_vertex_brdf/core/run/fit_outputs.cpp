#include "run/fit_outputs.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "base/file_util.h"
#include "base/vec3.h"
#include "inputs/photo.h"
#include "io/result_schema.h"
#include "io/vertex_quality.h"

namespace vbrdf {

namespace {

uint8_t srgb_byte(float linear) { return uint8_t(std::lround(255.0f * linear_to_srgb(linear))); }

int bit(uint16_t flag) {
  int i = 0;
  while (flag > 1) flag >>= 1, ++i;
  return i;
}

std::string color_report(const FitResult &r, const FitSettings &settings) {
  if (settings.color_correction == ColorCorrectionChoice::Off) return "colour correction: off\n";
  std::ostringstream rep;
  for (size_t v = 0; v < r.colors.size(); ++v) {
    const ColorCalibration &c = r.colors[v];
    rep << "colour correction, viewpoint " << v + 1 << " (" << c.divisor.size() << " photos): ";
    if (!c.corrected) {
      rep << (c.patches.empty() ? "no chart found" : "chart not usable") << ": colours uncorrected\n";
      continue;
    }
    const double heldout = std::min({c.fit.heldout_matrix, c.fit.heldout_curve_matrix, c.fit.heldout_polynomial});
    const std::string exposure = c.exposure_normalised
                                     ? "normalised per photo (light intensity varies)"
                                     : "one for all photos (divisor " + fixed(c.divisor.at(0), 4) + ")";
    rep << correction_model_name(c.correction.model) << " from " << (c.chart.detected ? "the detected" : "the given")
        << " chart, " << c.fit.patches << " patches, CIEDE2000 " << fixed(c.fit.before) << " -> " << fixed(c.fit.after)
        << " (held-out " << fixed(heldout) << "); exposure " << exposure
        << "; samples corrected in linear space before the fit\n";
  }
  return rep.str();
}

// Linear diffuse reflectance shown and written: the fitted k_d C where the reflectance fit has samples,
// else the basic estimate (mixed-pixel fallback included), else nothing.
bool displayed_reflectance(const FitResult &r, size_t v, float rho[3]) {
  if (!r.fits.empty() && r.fits[v].status != kFitNone) {
    for (int c = 0; c < 3; ++c) rho[c] = r.fits[v].kd * r.fits[v].color[c];
    return true;
  }
  for (int c = 0; c < 3; ++c) rho[c] = r.diffuse[v].valid ? r.diffuse[v].rgb[c] : 0.0f;
  return r.diffuse[v].valid;
}

} // namespace

std::string report_path_for(const std::string &ply) { return strip_extension(ply) + "_report.txt"; }

std::string output_report_line(const FitResult &r) {
  return "output: " + r.output_ply + " (" + r.output_note + "; written in " + fixed(r.seconds_output) + " s)\n";
}

namespace {

// The report's line for "only on selection" ("" when every vertex took part).
std::string only_on_selection(const FitInput &input) {
  if (input.vertex_mask.empty()) return "";
  const size_t kept =
      size_t(std::count_if(input.vertex_mask.begin(), input.vertex_mask.end(), [](uint8_t m) { return m != 0; }));
  return "only on selection: " + std::to_string(kept) + " of " + std::to_string(input.vertex_mask.size()) +
         " vertices fitted (the others are left out, as if no photo saw them)\n";
}

} // namespace

void build_outputs(const FitInput &input, const FitSettings &settings, FitResult &r) {
  const size_t n = input.mesh.vertex_count;
  r.colors_rgba.assign(4 * n, 0);
  r.quality.assign(n, 0.0f);
  std::vector<VertexRecord> records(n);
  for (size_t v = 0; v < n; ++v) {
    const DiffuseEstimate &e = r.diffuse[v];
    VertexRecord &rec = records[v];
    float rho[3];
    const bool coloured = displayed_reflectance(r, v, rho);
    for (int c = 0; c < 3; ++c) rec.diffuse[c] = rho[c];
    rec.n_visible = e.n_seen, rec.n_diffuse = e.n_diffuse, rec.n_specular = e.n_specular;
    // coloured = 2: the colour comes only from pixels at a silhouette or contact (own-surface texels
    // of a straddling footprint, or mixed pixels): lower confidence than clean pixels.
    const bool mixed = e.from_mixed_pixels || e.from_rim_pixels;
    const bool from_neighbours = !r.fits.empty() && r.fits[v].status == kFitFromNeighbours;
    rec.coloured = coloured ? (from_neighbours ? 3.0f : mixed ? 2.0f : 1.0f) : 0.0f;
    if (v < r.materials.label.size()) rec.material = float(r.materials.label[v]);
    if (!r.fits.empty()) {
      const VertexFit &f = r.fits[v];
      rec.fit = f;
      rec.lobe_form = float(uint8_t(settings.reflectance.lobe));
      rec.diffuse_form = float(uint8_t(r.diffuse_forms.at(v)));
      rec.diffuse_deconvolved = v < r.albedo_deconvolved.size() ? float(r.albedo_deconvolved[v]) : 0.0f;
      for (int k = 0; k < 3; ++k) rec.mesh_normal[k] = input.mesh.normals[3 * v + size_t(k)];
      rec.normal_moved = v < r.normal_moved.size() ? r.normal_moved[v] : -1.0f;
      r.quality[v] = vertex_quality(f, settings.quality);
      r.fit_full += f.status == kFitFull, r.fit_diffuse_only += f.status == kFitDiffuseOnly, r.fit_none += f.status == kFitNone;
      r.fit_weak += f.status == kFitFromWeakSamples, r.fit_neighbours += f.status == kFitFromNeighbours;
      r.fit_converged += f.status == kFitFull && f.converged, r.fit_iterations += f.iterations;
    }
    if (coloured) {
      for (int c = 0; c < 3; ++c) r.colors_rgba[4 * v + size_t(c)] = srgb_byte(rho[c]);
      r.colors_rgba[4 * v + 3] = 255;
      ++r.vertices_coloured;
      r.vertices_from_mixed += mixed;
    } else {
      // Never silently painted: the input colour stays (MeshLab's default white when none).
      for (int c = 0; c < 4; ++c)
        r.colors_rgba[4 * v + size_t(c)] = input.mesh_colors.size() == 4 * n ? input.mesh_colors[4 * v + size_t(c)] : 255;
      if (e.n_seen == 0) ++r.vertices_unseen; else ++r.vertices_no_diffuse;
    }
  }
  if (!r.fits.empty()) neutral_quality_for_unmodelled(r.fits, r.quality);
  r.attributes = result_attributes(records, !r.fits.empty());  // by name, in the schema's file order
}

namespace {
std::string shading_normal_report(const FitSettings &settings, const FitResult &r) {
  if (!settings.fit_reflectance) return "";
  if (!settings.shading_normals.enabled) return "shading normals: the mesh's (refinement off)\n";
  return "shading normals: " + r.shading_normal_note + "\n";
}

// One line per viewpoint: measured misregistration before and after, or why it was not measured.
std::string registration_report(const FitSettings &settings, const FitResult &r) {
  if (!settings.registration.enabled) return "registration: off (cameras as given)\n";
  std::string s = "registration (each viewpoint's camera measured against its photos; corrected above " +
                  fixed(settings.registration.threshold_px) + " px):\n";
  for (const ViewpointRegistration &v : r.registration.viewpoints)
    s += "  " + describe_registration(v, settings.registration) + "\n";
  s += r.registered_project.empty() ? std::string("  no camera corrected: no registered project written\n")
                                    : "  corrected cameras: " + r.registered_project + " (the input project is unchanged)\n";
  return s;
}
} // namespace

std::string build_report(const FitInput &input, const FitSettings &settings, const FitResult &r) {
  const MeshView &mesh = input.mesh;
  const size_t n = mesh.vertex_count;
  const GatherStats &g = r.gather;
  std::ostringstream rep;
  rep << "filter_vertex_brdf report\n";
  for (const std::string &w : r.warnings) rep << w << "\n";
  rep << "mesh: " << input.mesh_name << " (" << n << " vertices, " << mesh.index_count / 3 << " triangles)\n"
      << only_on_selection(input)
      << r.normals_source << "\n"
      << (r.memory_note.empty() ? std::string() : r.memory_note + "\n")
      << "photos: " << input.rasters.size() << ", lights: " << r.light_file << " (" << r.light_model << ")\n"
      << registration_report(settings, r)
      << shading_normal_report(settings, r)
      << "lights against the photos (predicted irradiance vs brightness): "
      << (r.light_agreement.empty() ? std::string("too few samples to tell") : r.light_agreement) << "\n"
      << "visibility back end: " << r.visibility_backend << "\n"
      << (r.depth_passes.empty() ? std::string() : "depth passes: " + r.depth_passes + "\n")
      << color_report(r, settings)
      << "thresholds: T_s (R.E) = " << settings.gather.specular_threshold
      << ", T_d (N.L) = " << settings.gather.diffuse_threshold << "\n"
      << "vertices coloured: " << r.vertices_coloured << " (" << percent(r.vertices_coloured, n) << ")\n"
      << "  of which from mixed pixels only (silhouette/border/contact; coloured = 2): " << r.vertices_from_mixed << "\n"
      << "vertices seen but without a usable sample (kept their colour): " << r.vertices_no_diffuse << "\n"
      << "vertices seen by no photo (skipped, kept their colour; need another viewpoint): " << r.vertices_unseen << "\n"
      << "vertex-photo pairs: " << g.pairs << ", samples stored (seen): " << g.stored << "\n";
  const std::pair<uint16_t, const char *> flag_names[] = {
      {kOffImage, "off image / behind camera"}, {kBackFacing, "back-facing"}, {kOccluded, "occluded"},
      {kAttachedShadow, "facing away from the light"}, {kCastShadow, "in cast shadow"},
      {kSaturated, "saturated (not used)"},
      {kMixedPixel, "mixed pixel at a silhouette/contact, no own-surface texel (used only where nothing else is: fit_status 4)"},
      {kRimFootprint, "rim footprint: colour from its own-surface texels (used where the vertex has < 2 clean samples)"},
      {kGrazing, "grazing light (N.L < T_d)"}, {kHighlight, "highlight (R.E > T_s)"}};
  for (const auto &f : flag_names)
    rep << "  " << f.second << ": " << g.flag_counts[bit(f.first)] << " (" << percent(g.flag_counts[bit(f.first)], g.pairs) << ")\n";
  rep << "  rim samples left out because their vertex has >= 2 clean samples: " << r.rim_samples_demoted << "\n";
  if (settings.fit_reflectance)
    rep << "  in a shadow the photo shows but the mesh does not cast (darker than "
        << settings.photo_shadows.darker_than << " x the diffuse part of the vertex's model; left out, vertex fitted again): "
        << (settings.photo_shadows.enabled ? std::to_string(r.photo_shadow_samples) + " samples, " +
                                                 std::to_string(r.photo_shadow_vertices) + " vertices"
                                           : std::string("off"))
        << "\n";
  if (settings.fit_reflectance)
    rep << "specular lobe: " << lobe_form_name(settings.reflectance.lobe) << " (shininess applies to "
        << lobe_form_label(settings.reflectance.lobe) << "; per-vertex lobe_form = " << int(settings.reflectance.lobe)
        << "); diffuse term: " << r.diffuse_choice_note << " (per-vertex diffuse_form: 0 lambert, 1 coated)"
        << "; samples weighted by photo resolution: " << (settings.gather.resolution_weights ? "on" : "off")
        << (settings.reflectance.lobe != LobeForm::GgxNH ? std::string()
            : settings.gather.footprint ? std::string("; the lobe seen through each photo's pixel footprint (shininess is "
                                                      "the surface's own; a renderer filters it per pixel)")
                                        : std::string("; the lobe at the vertex alone (no pixel footprint)"))
        << "\n";
  if (settings.fit_reflectance)
    rep << "albedo deconvolution: "
        << (!settings.deconvolve_albedo ? std::string("off (k_d C as the photos' pixel footprints blend it)")
                                        : r.deconvolution.note + " (per-vertex diffuse_deconvolved = 1: predict a photo "
                                                                 "through its footprint)")
        << "\n";
  if (!r.fits.empty()) {
    rep << "Reflectance fit back end: " << r.fit_backend << "\n"
        << "  full fits (k_d, k_s, alpha, C): " << r.fit_full << "\n"
        << "  diffuse-only (k_s = 0; k_s/alpha stages skipped: fewer than " << settings.reflectance.min_specular_samples
        << " clean highlight samples and fewer than " << settings.reflectance.min_lobe_samples
        << " samples with R.E > " << settings.reflectance.lobe_threshold << ", or no specular term): " << r.fit_diffuse_only << "\n"
        << "  from weak samples only (grazing N.L < T_d and/or mixed pixels; fit_status 4): " << r.fit_weak << "\n"
        << "  from neighbours (no usable sample of their own; fit_status 3): " << r.fit_neighbours << "\n"
        << "  no model (sentinels: k_d = k_s = shininess = 0; unseen, or no modelled neighbour): " << r.fit_none << "\n"
        << "  converged before the cap of " << settings.reflectance.max_iterations << " iterations: " << r.fit_converged
        << " of " << r.fit_full << " full fits; alpha iterations run: " << r.fit_iterations << " of at most "
        << uint64_t(r.fit_full + r.fit_diffuse_only) * uint64_t(std::max(0, settings.reflectance.max_iterations)) << "\n";
    rep << (settings.materials ? r.materials.report : "materials: off (per-vertex lobes only)\n");
  } else {
    rep << "Reflectance fit: off (basic diffuse colour only)\n";
  }
  // What skipping saved, estimated from the measured rates (the skipped work was never run).
  const double per_pair = r.seconds_gather > 0 && g.stored ? (r.seconds_gather - r.seconds_fit) / double(g.stored) : 0;
  rep << "skipped work (estimated saving): " << g.rasters_skipped << " raster x chunk pairs not read; "
      << (g.pairs - g.stored) << " vertex-photo pairs not sampled (not seen), ~"
      << fixed(per_pair * double(g.pairs - g.stored), 2) << " s";
  if (!r.fits.empty()) {
    const uint64_t fitted = r.fit_full + r.fit_diffuse_only;
    const uint64_t cap_work = fitted * uint64_t(std::max(0, settings.reflectance.max_iterations));
    // Cost model: set-up of a vertex ~ 2 iterations (tests/benchmark/FIT_PERFORMANCE.md).
    const double per_iteration = r.seconds_fit / double(std::max<uint64_t>(1, r.fit_iterations + 2 * fitted));
    rep << "; " << (cap_work - std::min<uint64_t>(cap_work, r.fit_iterations))
        << " shininess iterations not run (diffuse-only or converged vertices), ~"
        << fixed(per_iteration * double(cap_work - std::min<uint64_t>(cap_work, r.fit_iterations)), 2) << " s";
  }
  rep << "\n";
  rep << "time: visibility " << fixed(r.seconds_visibility) << " s, samples "
      << fixed(r.seconds_gather - r.seconds_fit - r.seconds_normals) << " s, fit " << fixed(r.seconds_fit)
      << " s, shading normals " << fixed(r.seconds_normals) << " s (" << g.chunks << " chunk(s), " << g.photo_loads << " photo decodes, "
      << g.host_photo_reads << " photos read from MeshLab's images, "
      << g.rasters_skipped << " raster x chunk pairs skipped)\n";
  rep << "time, other stages: registration " << fixed(r.seconds_registration) << " s, colour chart search and correction " << fixed(r.seconds_colors)
      << " s (beside the visibility passes), photo checks "
      << fixed(r.seconds_photo_checks) << " s, diffuse-form pilot " << fixed(r.seconds_pilot) << " s, materials "
      << fixed(r.seconds_materials) << " s, neighbour fill " << fixed(r.seconds_fill) << " s, albedo deconvolution "
      << fixed(r.seconds_deconvolution) << " s\n";
  return rep.str();
}

} // namespace vbrdf
