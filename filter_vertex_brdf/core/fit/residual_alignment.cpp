#include "fit/residual_alignment.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "registration/registration.h"

namespace vbrdf {
namespace {

constexpr size_t kMinPhotosSeen = 4;

double bounded(double v, double lo, double hi) { return std::min(std::max(v, lo), hi); }  // C++14: no std::clamp

// The masks kept for the viewpoint's rasters and the pilot vertices only (see the contract).
VisibilityMasks pilot_masks(const VisibilityMasks &masks, const std::vector<size_t> &viewpoint, size_t target,
                            size_t &count) {
  VisibilityMasks pilot = masks;
  const size_t words = masks.words();
  std::vector<uint8_t> in_viewpoint(masks.raster_count, 0);
  for (size_t r : viewpoint) in_viewpoint[r] = 1;
  for (size_t r = 0; r < masks.raster_count; ++r)
    if (!in_viewpoint[r])
      for (size_t w = 0; w < words; ++w)
        pilot.seen[r * words + w] = pilot.lit[r * words + w] = pilot.mixed[r * words + w] = 0;
  std::vector<uint32_t> seen(masks.vertex_count, 0);
  std::vector<uint8_t> rim(masks.vertex_count, 0);
  for (size_t r : viewpoint)
    for (size_t v = 0; v < masks.vertex_count; ++v) {
      seen[v] += masks.is_seen(r, v);
      rim[v] |= uint8_t(masks.is_mixed(r, v));
    }
  std::vector<uint8_t> eligible(masks.vertex_count, 0);
  for (size_t v = 0; v < masks.vertex_count; ++v) eligible[v] = seen[v] >= kMinPhotosSeen && !rim[v];
  restrict_to_vertices(pilot, every_kth_vertex(eligible, target, count));
  return pilot;
}

// E(x, y) = a + b x + c y + d x^2 + e x y + f y^2 by least squares; false when not convex.
bool quadratic_minimum(const std::vector<double> &xs, const std::vector<double> &ys, const std::vector<double> &es,
                       double &mx, double &my) {
  Eigen::MatrixXd A(xs.size(), 6);
  Eigen::VectorXd b(xs.size());
  for (size_t i = 0; i < xs.size(); ++i) {
    A.row(Eigen::Index(i)) << 1, xs[i], ys[i], xs[i] * xs[i], xs[i] * ys[i], ys[i] * ys[i];
    b(Eigen::Index(i)) = es[i];
  }
  const Eigen::VectorXd q = A.colPivHouseholderQr().solve(b);
  Eigen::Matrix2d H;
  H << 2 * q(3), q(4), q(4), 2 * q(5);
  // Convex only: Sylvester's criterion on the Hessian.
  if (!(H(0, 0) > 0 && H.determinant() > 0)) return false;
  const Eigen::Vector2d m = H.ldlt().solve(Eigen::Vector2d(-q(1), -q(2)));
  if (!m.allFinite()) return false;
  mx = m(0), my = m(1);
  return true;
}

} // namespace

Shot rolled_shot(const Shot &shot, double roll) {
  ImageWarp w;
  w.roll = roll;
  return warped_shot(shot, w);
}

Shot shifted_shot(const Shot &shot, double dx, double dy) {
  // warp_point moves the principal point by (f tan(yaw), -f tan(pitch)) (image_alignment.h).
  const double f = focal_pixels(shot);
  ImageWarp w;
  w.yaw = std::atan(dx / f);
  w.pitch = -std::atan(dy / f);
  return warped_shot(shot, w);
}

ViewpointResidual::ViewpointResidual(const MeshView &mesh, const std::vector<Raster> &rasters,
                                     const std::vector<size_t> &viewpoint, const std::vector<LightSource> &lights,
                                     const VisibilityMasks &masks, const GatherSettings &gather,
                                     const ReflectanceFitOptions &fit, PhotoCache &photos,
                                     const std::function<void(SampleChunk &)> &prepare, size_t pilot_vertices,
                                     double trimmed_share)
    : mesh_(mesh), rasters_(rasters), viewpoint_(viewpoint), lights_(lights), pilot_count_(0),
      pilot_(pilot_masks(masks, viewpoint, pilot_vertices, pilot_count_)), gather_(gather), fit_(fit),
      photos_(photos), prepare_(prepare), trimmed_share_(std::min(std::max(trimmed_share, 0.05), 1.0)) {
  gather_.resolution_weights = false;  // one camera: every photo resolves a vertex alike
}

double ViewpointResidual::at(const Shot &shot) {
  for (size_t r : viewpoint_) rasters_[r].shot = shot;
  std::vector<float> errors;
  gather_samples(mesh_, rasters_, lights_, pilot_, gather_, photos_, [&](SampleChunk &chunk) {
    if (prepare_) prepare_(chunk);
    std::vector<std::vector<float>> per_vertex(chunk.vertex_count);
#pragma omp parallel for schedule(dynamic, 16)
    for (long long i = 0; i < (long long)chunk.vertex_count; ++i) {
      const Sample *begin = chunk.samples.data() + chunk.offsets[size_t(i)];
      const Sample *end = chunk.samples.data() + chunk.offsets[size_t(i) + 1];
      if (begin == end) continue;
      VertexFit fit;
      fit_vertex_cpu(begin, size_t(end - begin), fit_, fit);
      if (!has_model(fit)) continue;
      for (const Sample *s = begin; s != end; ++s) {
        if (!is_scorable_sample(*s)) continue;
        float predicted[3];
        evaluate_reflectance(fit, s->d, s->lobe_cos, fit_.lobe, predicted, s->footprint);
        double e = 0;
        for (int c = 0; c < 3; ++c) e += std::fabs(double(predicted[c]) - double(s->rgb[c])) / 3.0;
        if (std::isfinite(e)) per_vertex[size_t(i)].push_back(float(e));
      }
    }
    for (const auto &v : per_vertex) errors.insert(errors.end(), v.begin(), v.end());
  });
  if (errors.empty()) return std::numeric_limits<double>::infinity();
  // The trimmed mean: the share of the samples the model explains best (see the contract).
  const size_t n = std::max<size_t>(1, size_t(std::ceil(trimmed_share_ * double(errors.size()))));
  if (n < errors.size()) std::nth_element(errors.begin(), errors.begin() + long(n), errors.end());
  double sum = 0;
  for (size_t k = 0; k < n; ++k) sum += errors[k];
  return sum / double(n);
}

ResidualShift refine_shift_by_residual(ViewpointResidual &residual, const Shot &start,
                                       const ResidualAlignmentSettings &settings, double start_residual) {
  ResidualShift out;
  const double h = settings.step_px, reach = settings.max_shift_px;
  double cx = 0, cy = 0, centre_residual = std::isnan(start_residual) ? residual.at(start) : start_residual;
  out.residual_start = out.residual_end = centre_residual;
  double best_x = 0, best_y = 0, best = centre_residual;
  for (int round = 0; round < settings.max_rounds; ++round) {
    std::vector<double> xs, ys, es;
    double grid_best = centre_residual, grid_x = cx, grid_y = cy;
    for (int j = -1; j <= 1; ++j)
      for (int i = -1; i <= 1; ++i) {
        const double x = cx + i * h, y = cy + j * h;
        const double e = (i == 0 && j == 0) ? centre_residual : residual.at(shifted_shot(start, x, y));
        if (!std::isfinite(e)) continue;
        xs.push_back(x - cx), ys.push_back(y - cy), es.push_back(e);
        if (e < grid_best) grid_best = e, grid_x = x, grid_y = y;
      }
    double mx = 0, my = 0;
    if (xs.size() >= 6 && quadratic_minimum(xs, ys, es, mx, my) && std::fabs(mx) <= 1.5 * h &&
        std::fabs(my) <= 1.5 * h) {
      const double x = bounded(cx + mx, -reach, reach), y = bounded(cy + my, -reach, reach);
      const double e = residual.at(shifted_shot(start, x, y));
      if (e < best) best = e, best_x = x, best_y = y;
      if (grid_best < best) best = grid_best, best_x = grid_x, best_y = grid_y;
      break;
    }
    if (grid_best < best) best = grid_best, best_x = grid_x, best_y = grid_y;
    // Not bracketed: a new grid about the best point, within reach.
    const double nx = bounded(grid_x, -reach, reach), ny = bounded(grid_y, -reach, reach);
    if (nx == cx && ny == cy) break;
    centre_residual = (nx == grid_x && ny == grid_y) ? grid_best : residual.at(shifted_shot(start, nx, ny));
    cx = nx, cy = ny;
  }
  if (!(best < out.residual_start)) return out;
  if (std::hypot(best_x, best_y) > settings.trusted_shift_px) {
    out.beyond_trust = true, out.found_dx = best_x, out.found_dy = best_y;
    return out;
  }
  out.dx = out.found_dx = best_x, out.dy = out.found_dy = best_y, out.residual_end = best, out.moved = true;
  return out;
}

double ViewpointResidual::rms_radius(const Shot &shot) const {
  double c[2];
  principal_point(shot, c);
  double sum = 0;
  size_t n = 0;
  for (size_t v = 0; v < pilot_.vertex_count; ++v) {
    if (!pilot_.is_seen(viewpoint_.front(), v)) continue;
    const ImagePoint p = project_to_image(shot, mesh_.positions + 3 * v);
    if (!p.in_front) continue;
    sum += (p.x - c[0]) * (p.x - c[0]) + (p.y - c[1]) * (p.y - c[1]);
    ++n;
  }
  return n ? std::sqrt(sum / double(n)) : 0.0;
}

ResidualRoll refine_roll_by_residual(ViewpointResidual &residual, const Shot &start,
                                     const ResidualAlignmentSettings &settings, double start_residual) {
  ResidualRoll out;
  out.residual_start = out.residual_end = std::isnan(start_residual) ? residual.at(start) : start_residual;
  const double radius = residual.rms_radius(start);
  if (!(radius > 1.0) || !std::isfinite(out.residual_start)) return out;  // a point-like view: no roll to read
  const double delta = settings.step_px / radius;
  const double e0 = out.residual_start, ep = residual.at(rolled_shot(start, delta)),
               em = residual.at(rolled_shot(start, -delta));
  double best = e0, best_roll = 0;
  if (ep < best) best = ep, best_roll = delta;
  if (em < best) best = em, best_roll = -delta;
  const double curvature = em - 2 * e0 + ep;
  if (curvature > 0 && std::isfinite(curvature)) {
    const double t = delta * (em - ep) / (2 * curvature);
    if (std::fabs(t) <= 2 * delta && t != 0) {
      const double e = residual.at(rolled_shot(start, t));
      if (e < best) best = e, best_roll = t;
    }
  }
  if (best < out.residual_start) out.roll = best_roll, out.residual_end = best, out.moved = true;
  return out;
}

} // namespace vbrdf
