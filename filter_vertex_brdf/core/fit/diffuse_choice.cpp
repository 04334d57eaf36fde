#include "fit/diffuse_choice.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <utility>

#include "base/mesh_adjacency.h"
#include "base/number_format.h"
#include "base/vec3.h"
#include "inputs/camera.h"
#include "samples/reshade.h"

#include <vcg/space/index/kdtree/kdtree.h>

namespace vbrdf {
namespace {

constexpr size_t kMinPhotosSeen = 4;
constexpr size_t kMinPilotVertices = 50;
constexpr size_t kVoteNeighbours = 9;       // majority over the nearest labelled pilot vertices
constexpr double kMinLabelShare = 0.05;     // a coat map needs each label on >= 5 % of the pilot

enum MapLabel : int8_t { kUnlabelled = -1, kBare = 0, kCoated = 1 };

std::string folds_note(size_t photos) {
  const int folds = heldout_fold_count(photos);
  return folds > 1 ? ", " + std::to_string(folds) + " folds in turn" : std::string();
}

// Every k-th vertex seen by at least kMinPhotosSeen photos (k for about `target` of them).
std::vector<uint8_t> pilot_mask(const VisibilityMasks &masks, size_t target, size_t &count) {
  std::vector<uint32_t> seen(masks.vertex_count, 0);
  for (size_t r = 0; r < masks.raster_count; ++r)
    for (size_t v = 0; v < masks.vertex_count; ++v) seen[v] += masks.is_seen(r, v);
  std::vector<uint8_t> eligible(masks.vertex_count, 0);
  for (size_t v = 0; v < seen.size(); ++v) eligible[v] = seen[v] >= kMinPhotosSeen;
  return every_kth_vertex(eligible, target, count);
}

// The vertex's fit on `train`, with its shading normal refined as the product's fit refines it
// (fit/shading_normals.h) when normals.enabled: refine, shade again, fit again. One round, not the
// fit's normals.rounds: the normal solve fits the reflectance at each trial normal, so its first
// round does nearly all of the work (bunny_two_materials_dir32 smoothed: 0.424 against 0.422
// relit with three) at a third of the pilot's added time. `normal` (unit) starts at the mesh
// normal and ends at the one the fit was made with.
VertexFit fit_pilot_vertex(std::vector<Sample> &train, const float position[3], const float mesh_normal[3],
                           const float *centres, const std::vector<LightSource> &lights, DiffuseForm form,
                           const GatherSettings &gather, const ReflectanceFitOptions &phong,
                           const ShadingNormalSettings &normals, float normal[3]) {
  VertexFit fit;
  fit_vertex_cpu(train.data(), train.size(), phong, fit);
  if (!normals.enabled || !has_model(fit)) return fit;
  float moved[3] = {normal[0], normal[1], normal[2]};
  if (!refine_vertex_normal(train.data(), train.size(), position, mesh_normal, centres, lights, fit, form, phong.lobe,
                            normals, moved))
    return fit;
  reshade_vertex(train.data(), train.size(), moved, position, centres, lights, form, gather);
  VertexFit refitted;
  fit_vertex_cpu(train.data(), train.size(), phong, refitted);
  if (!has_model(refitted)) return fit;  // keep the model and the normal it was fitted with
  for (int k = 0; k < 3; ++k) normal[k] = moved[k];
  return refitted;
}

// Per pilot vertex: held-out error sum and count under one form.
struct PilotVertex {
  uint32_t vertex = 0;
  double error = 0;
  uint32_t samples = 0;
};

std::vector<PilotVertex> score_form(const MeshView &mesh, const std::vector<Raster> &rasters,
                                    const std::vector<LightSource> &lights, const VisibilityMasks &pilot,
                                    GatherSettings gather, DiffuseForm form, const ReflectanceFitOptions &phong,
                                    PhotoCache &photos, const std::function<void(SampleChunk &)> &prepare,
                                    const ShadingNormalSettings &normals) {
  gather.diffuse = DiffuseForms::everywhere(form);
  std::vector<float> centres(3 * rasters.size());
  for (size_t r = 0; r < rasters.size(); ++r) camera_centre(rasters[r].shot, &centres[3 * r]);
  gather.resolution_weights = false;
  const int folds = heldout_fold_count(rasters.size());
  std::vector<PilotVertex> out;
  gather_samples(mesh, rasters, lights, pilot, gather, photos, [&](SampleChunk &chunk) {
    if (prepare) prepare(chunk);
    // The pilot vertices are scattered over the chunk: each is fitted on its own (in parallel),
    // then the modelled ones are kept in vertex order.
    std::vector<uint32_t> pilot_in_chunk;
    for (uint32_t i = 0; i < chunk.vertex_count; ++i)
      if (chunk.offsets[i + 1] > chunk.offsets[i]) pilot_in_chunk.push_back(i);
    std::vector<PilotVertex> scored(pilot_in_chunk.size());
    std::vector<uint8_t> modelled(pilot_in_chunk.size(), 0);
#pragma omp parallel
    {
      std::vector<Sample> train;
#pragma omp for schedule(dynamic, 16)
      for (long long n = 0; n < (long long)pilot_in_chunk.size(); ++n) {
        const uint32_t i = pilot_in_chunk[size_t(n)];
        const Sample *begin = chunk.samples.data() + chunk.offsets[i], *end = chunk.samples.data() + chunk.offsets[i + 1];
        PilotVertex &p = scored[size_t(n)];
        p.vertex = chunk.first_vertex + i;
        const float *position = mesh.positions + 3 * size_t(p.vertex), *mesh_normal = mesh.normals + 3 * size_t(p.vertex);
        for (int k = 0; k < folds; ++k) {
          train.clear();
          for (const Sample *s = begin; s != end; ++s)
            if (!held_out_in_fold(s->raster, k)) train.push_back(*s);
          float normal[3] = {mesh_normal[0], mesh_normal[1], mesh_normal[2]};
          normalize3(normal);
          const VertexFit fit =
              fit_pilot_vertex(train, position, mesh_normal, centres.data(), lights, form, gather, phong, normals, normal);
          if (!has_model(fit)) continue;
          modelled[size_t(n)] = 1;
          for (const Sample *s = begin; s != end; ++s) {
            // The same samples are scored under every form (as gathered); each is predicted with
            // the normal its fit was made with.
            if (!held_out_in_fold(s->raster, k) || !is_scorable_sample(*s)) continue;
            Sample held = *s;
            if (normals.enabled) reshade_vertex(&held, 1, normal, position, centres.data(), lights, form, gather);
            float predicted[3];
            evaluate_reflectance(fit, held.d, held.lobe_cos, phong.lobe, predicted, held.footprint);
            for (int c = 0; c < 3; ++c) p.error += std::fabs(double(predicted[c]) - double(held.rgb[c])) / 3.0;
            ++p.samples;
          }
        }
      }
    }
    for (size_t n = 0; n < scored.size(); ++n)
      if (modelled[n]) out.push_back(scored[n]);
  });
  return out;
}

// The coat map's label of each pilot vertex: coated where its kVoteNeighbours nearest other pilot
// vertices (3-D distance, vcglib kd-tree; itself left out, so that the map's held-out score is not
// its own choice) together predict their held-out photos better coated than Lambertian.
std::vector<std::pair<uint32_t, MapLabel>> vote_labels(const MeshView &mesh, const std::vector<uint32_t> &vertex,
                                                       const std::vector<double> &coated_gain) {
  std::vector<vcg::Point3f> points(vertex.size());
  for (size_t i = 0; i < vertex.size(); ++i) {
    const float *q = mesh.positions + 3 * size_t(vertex[i]);
    points[i] = vcg::Point3f(q[0], q[1], q[2]);
  }
  vcg::KdTree<float> tree(vcg::ConstDataWrapper<vcg::Point3f>(points.data(), int(points.size())));
  const int k = int(std::min(kVoteNeighbours + 1, vertex.size()));
  std::vector<std::pair<uint32_t, MapLabel>> labelled(vertex.size());
  vcg::KdTree<float>::PriorityQueue queue;
  for (size_t i = 0; i < vertex.size(); ++i) {
    tree.doQueryK(points[i], k, queue);
    double gain = 0;
    for (int j = 0; j < queue.getNofElements(); ++j)
      if (size_t(queue.getIndex(j)) != i) gain += coated_gain[size_t(queue.getIndex(j))];
    labelled[i] = {vertex[i], gain > 0 ? kCoated : kBare};
  }
  return labelled;
}

// Every vertex takes the label of the nearest labelled one over the mesh's edges (breadth first
// from all of them at once); vertices no label reaches take `fallback`.
std::vector<uint8_t> spread_over_mesh(const MeshView &mesh, const std::vector<std::pair<uint32_t, MapLabel>> &labelled,
                                      DiffuseForm fallback) {
  const MeshAdjacency adj = build_mesh_adjacency(mesh);
  std::vector<int8_t> label(mesh.vertex_count, kUnlabelled);
  std::deque<uint32_t> front;
  for (const auto &l : labelled)
    if (label[l.first] == kUnlabelled) label[l.first] = l.second, front.push_back(l.first);
  while (!front.empty()) {
    const uint32_t v = front.front();
    front.pop_front();
    for (uint32_t k = adj.offsets[v]; k < adj.offsets[v + 1]; ++k) {
      const uint32_t u = adj.neighbours[k];
      if (label[u] == kUnlabelled) label[u] = label[v], front.push_back(u);
    }
  }
  std::vector<uint8_t> coated(mesh.vertex_count);
  for (size_t v = 0; v < coated.size(); ++v)
    coated[v] = label[v] == kUnlabelled ? uint8_t(fallback == DiffuseForm::Coated) : uint8_t(label[v] == kCoated);
  return coated;
}

std::string format_error(double e) { return three_significant(e); }

} // namespace

DiffuseChoice choose_diffuse_forms(const MeshView &mesh, const std::vector<Raster> &rasters,
                                   const std::vector<LightSource> &lights, const VisibilityMasks &masks,
                                   const GatherSettings &gather, const ReflectanceFitOptions &phong, PhotoCache &photos,
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
  const std::vector<PilotVertex> lambert =
      score_form(mesh, rasters, lights, pilot, gather, DiffuseForm::Lambert, phong, photos, prepare, options.normals);
  const std::vector<PilotVertex> coated =
      score_form(mesh, rasters, lights, pilot, gather, DiffuseForm::Coated, phong, photos, prepare, options.normals);
  choice.piloted = true;

  // Per-vertex errors side by side (both lists are in vertex order; a vertex modelled under one
  // form only is left out of every candidate's score).
  std::vector<std::pair<const PilotVertex *, const PilotVertex *>> both;
  for (size_t i = 0, j = 0; i < lambert.size() && j < coated.size();) {
    if (lambert[i].vertex < coated[j].vertex) ++i;
    else if (coated[j].vertex < lambert[i].vertex) ++j;
    else {
      if (lambert[i].samples == coated[j].samples && lambert[i].samples > 0) both.push_back({&lambert[i], &coated[j]});
      ++i, ++j;
    }
  }
  double sum[2] = {0, 0};
  for (const auto &b : both) sum[0] += b.first->error, sum[1] += b.second->error, choice.scored_samples += b.first->samples;
  const double n = double(std::max<size_t>(choice.scored_samples, 1));
  choice.heldout_error[0] = sum[0] / n, choice.heldout_error[1] = sum[1] / n;
  const bool scored = choice.scored_samples > 0;
  const DiffuseForm uniform = scored && choice.heldout_error[1] < (1.0 - options.margin) * choice.heldout_error[0]
                                  ? DiffuseForm::Coated
                                  : DiffuseForm::Lambert;
  choice.forms = DiffuseForms::everywhere(uniform);

  // The coat map.
  std::string map_note = "no coat map (";
  std::vector<uint32_t> pilot_vertex;
  std::vector<double> coated_gain;
  for (const auto &b : both) pilot_vertex.push_back(b.first->vertex), coated_gain.push_back(b.first->error - b.second->error);
  const std::vector<std::pair<uint32_t, MapLabel>> labelled =
      pilot_vertex.size() > kVoteNeighbours ? vote_labels(mesh, pilot_vertex, coated_gain)
                                            : std::vector<std::pair<uint32_t, MapLabel>>();
  size_t glossy = 0;
  for (const auto &l : labelled) glossy += l.second == kCoated;
  const double share = labelled.empty() ? 0.0 : double(glossy) / double(labelled.size());
  if (scored && share >= kMinLabelShare && share <= 1.0 - kMinLabelShare) {
    auto map = std::make_shared<std::vector<uint8_t>>(spread_over_mesh(mesh, labelled, uniform));
    double map_sum = 0;  // each pilot vertex under its own (leave-one-out) label
    for (size_t i = 0; i < both.size(); ++i) map_sum += labelled[i].second == kCoated ? both[i].second->error : both[i].first->error;
    choice.heldout_error[2] = map_sum / n;
    const double reference = choice.heldout_error[uniform == DiffuseForm::Coated ? 1 : 0];
    if (choice.heldout_error[2] < (1.0 - options.map_margin) * reference) choice.forms = DiffuseForms{uniform, map};
    map_note = "coat map " + format_error(choice.heldout_error[2]) + ", coated on " + std::to_string(glossy) + " of " +
               std::to_string(labelled.size()) + " pilot vertices; it must be " + format_error(100 * options.map_margin) +
               " % lower than the uniform choice)";
  } else {
    map_note += labelled.empty() ? "too few scored pilot vertices)"
                                 : "the pilot vertices' neighbourhoods favour coated on " + std::to_string(glossy) +
                                       " of " + std::to_string(labelled.size()) + ": one form)";
  }
  choice.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  choice.note = describe_diffuse_forms(choice.forms) + " (Auto: pilot fit of " + std::to_string(choice.pilot_vertices) +
                " vertices, every 4th photo held out" + folds_note(rasters.size()) + ", " + std::to_string(choice.scored_samples) +
                " held-out samples: mean absolute error lambert " + format_error(choice.heldout_error[0]) +
                ", coated " + format_error(choice.heldout_error[1]) + " (coated must be " +
                format_error(100 * options.margin) + " % lower), " + map_note + ")";
  return choice;
}

} // namespace vbrdf
