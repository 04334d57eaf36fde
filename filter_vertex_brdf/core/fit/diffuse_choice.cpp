#include "fit/diffuse_choice.h"

#include <chrono>
#include <cmath>
#include <cstdio>

namespace vbrdf {
namespace {

constexpr int kFolds = 4;          // every 4th photo held out
constexpr int kHeldOutFold = 3;
constexpr size_t kMinPhotosSeen = 4;
constexpr size_t kMinPilotVertices = 50;

bool held_out(const Sample &s) { return s.raster % kFolds == kHeldOutFold; }

bool scorable(const Sample &s) {
  return !(s.flags & (kShadowed | kSaturated | kMixedPixel | kNotSeen)) && s.d > 0 && std::isfinite(s.d) &&
         std::isfinite(s.lobe_cos) && std::isfinite(s.rgb[0]) && std::isfinite(s.rgb[1]) && std::isfinite(s.rgb[2]);
}

// Every k-th vertex seen by at least kMinPhotosSeen photos (k for about `target` of them).
std::vector<uint8_t> pilot_mask(const VisibilityMasks &masks, size_t target, size_t &count) {
  std::vector<uint32_t> seen(masks.vertex_count, 0);
  for (size_t r = 0; r < masks.raster_count; ++r)
    for (size_t v = 0; v < masks.vertex_count; ++v) seen[v] += masks.is_seen(r, v);
  size_t eligible = 0;
  for (uint32_t s : seen) eligible += s >= kMinPhotosSeen;
  const size_t step = std::max<size_t>(1, eligible / std::max<size_t>(1, target));
  std::vector<uint8_t> mask(masks.vertex_count, 0);
  count = 0;
  for (size_t v = 0, k = 0; v < masks.vertex_count; ++v)
    if (seen[v] >= kMinPhotosSeen && k++ % step == 0) mask[v] = 1, ++count;
  return mask;
}

struct FormScore {
  double error = 0;
  size_t samples = 0;
};

// Fits each pilot vertex on the training photos and scores it on the held-out ones.
FormScore score_form(const MeshView &mesh, const std::vector<Raster> &rasters, const std::vector<LightSource> &lights,
                     const VisibilityMasks &pilot, GatherSettings gather, DiffuseForm form, const PhongFitOptions &phong,
                     PhotoCache &photos, const std::function<void(SampleChunk &)> &prepare) {
  gather.diffuse = form;
  gather.resolution_weights = false;
  FormScore score;
  std::vector<Sample> train;
  gather_samples(mesh, rasters, lights, pilot, gather, photos, [&](SampleChunk &chunk) {
    if (prepare) prepare(chunk);
    for (uint32_t i = 0; i < chunk.vertex_count; ++i) {
      const Sample *begin = chunk.samples.data() + chunk.offsets[i], *end = chunk.samples.data() + chunk.offsets[i + 1];
      if (begin == end) continue;
      train.clear();
      for (const Sample *s = begin; s != end; ++s)
        if (!held_out(*s)) train.push_back(*s);
      VertexFit fit;
      fit_vertex_cpu(train.data(), train.size(), phong, fit);
      if (!has_model(fit)) continue;
      for (const Sample *s = begin; s != end; ++s) {
        if (!held_out(*s) || !scorable(*s)) continue;
        float predicted[3];
        evaluate_phong(fit, s->d, s->lobe_cos, predicted);
        for (int c = 0; c < 3; ++c) score.error += std::fabs(double(predicted[c]) - double(s->rgb[c])) / 3.0;
        ++score.samples;
      }
    }
  });
  return score;
}

std::string format_error(double e) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", e);
  return text;
}

} // namespace

DiffuseChoice choose_diffuse_form(const MeshView &mesh, const std::vector<Raster> &rasters,
                                  const std::vector<LightSource> &lights, const VisibilityMasks &masks,
                                  const GatherSettings &gather, const PhongFitOptions &phong, PhotoCache &photos,
                                  const std::function<void(SampleChunk &)> &prepare,
                                  const DiffuseChoiceOptions &options) {
  const auto start = std::chrono::steady_clock::now();
  DiffuseChoice choice;
  size_t seeing = 0;
  for (uint32_t c : masks.seen_count) seeing += c > 0;
  if (seeing < kMinPhotosSeen) {
    choice.note = "lambert (Auto: fewer than 4 photos see the mesh, no pilot fit)";
    return choice;
  }
  VisibilityMasks pilot = masks;
  const std::vector<uint8_t> mask = pilot_mask(masks, options.pilot_vertices, choice.pilot_vertices);
  if (choice.pilot_vertices < kMinPilotVertices) {
    choice.note = "lambert (Auto: fewer than 50 vertices seen by 4 photos, no pilot fit)";
    return choice;
  }
  restrict_to_vertices(pilot, mask);
  const FormScore lambert = score_form(mesh, rasters, lights, pilot, gather, DiffuseForm::Lambert, phong, photos, prepare);
  const FormScore coated = score_form(mesh, rasters, lights, pilot, gather, DiffuseForm::Coated, phong, photos, prepare);
  choice.piloted = true;
  choice.scored_samples = lambert.samples;
  choice.heldout_error[0] = lambert.samples ? lambert.error / double(lambert.samples) : 0.0;
  choice.heldout_error[1] = coated.samples ? coated.error / double(coated.samples) : 0.0;
  const bool coat = lambert.samples > 0 && coated.samples > 0 &&
                    choice.heldout_error[1] < (1.0 - options.margin) * choice.heldout_error[0];
  choice.form = coat ? DiffuseForm::Coated : DiffuseForm::Lambert;
  choice.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  choice.note = std::string(diffuse_form_name(choice.form)) + " (Auto: pilot fit of " +
                std::to_string(choice.pilot_vertices) + " vertices, every 4th photo held out, " +
                std::to_string(choice.scored_samples) + " held-out samples: mean absolute error lambert " +
                format_error(choice.heldout_error[0]) + ", coated " + format_error(choice.heldout_error[1]) +
                "; coated must be " + format_error(100 * options.margin) + " % lower)";
  return choice;
}

} // namespace vbrdf
