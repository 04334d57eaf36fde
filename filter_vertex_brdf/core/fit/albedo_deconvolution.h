#pragma once
// The surface's own diffuse reflectance from the fit's, which is what the photos' samples show: a
// footprint-weighted mean over the neighbouring vertices (samples/footprint_weights.h). Where the
// albedo steps within a few pixels (a material boundary, a painted line) the fit's colour is a
// blend of both sides; the deconvolution recovers the vertex's own:
//
//   minimise  sum_rows share_k |sum_u W(k, u) x_u - b_{v(k)}|^2  +  lambda sum_u |x_u - b_u|^2
//
// per colour channel, b the fit's reflectance (k_d C), over the vertices whose footprint spans an
// edge (footprint_spans_an_edge); every other vertex is held at b. The rows of one vertex have
// shares summing to 1, so lambda weighs the prior against one vertex's data. Conjugate gradients
// (Eigen, diagonal preconditioner) on the normal equations W^T S W + lambda I, symmetric positive
// definite for lambda > 0 (never singular, whatever W).
//
// The footprint model (the photo shows a blend of the vertices' values, linear over each
// triangle) holds for albedo defined at the mesh's resolution; it does not where the albedo is a
// texture finer than the mesh (the sample at a vertex is then the texture near it, not a blend
// with neighbours three pixels away). A vertex whose footprints the solution does not reproduce
// (misfit_tolerance) keeps the fit's colour and is held; the others are solved again. So the
// result reproduces the photos through the footprints (the relighting evaluation predicts a photo
// through the same weights, tools/relight.h) and changes only where the model explains the data.
//
// Safeguards: lambda is clamped to [1e-3, 1e6] (large returns b); each solved value is clamped to
// the range of b over its footprint's vertices (a step's value lies between its sides: no ringing,
// no negative or brighter-than-observed albedo); a non-finite solution or failed solve keeps b
// everywhere (solved = false); vertices without a row keep b; no edge: nothing is solved.
#include <cstdint>
#include <string>
#include <vector>

#include "samples/footprint_weights.h"

namespace vbrdf {

struct DeconvolutionSettings {
  float lambda = 0.02f;        // the prior's weight against one vertex's data
  int max_iterations = 200;    // conjugate-gradient iterations
  float tolerance = 1e-5f;     // relative residual at which CG stops
  // Only vertices whose footprint spans an albedo edge are deconvolved (footprint_spans_an_edge);
  // the rest keep the fit's colour, exactly.
  float edge_contrast = 0.5f;
  // A vertex whose footprints the solution does not reproduce to this fraction of the footprint's
  // brightest colour keeps the fit's colour (the footprint model does not hold there), and the
  // rest are solved again, up to max_rounds solves.
  float misfit_tolerance = 0.01f;
  int max_rounds = 4;
};

// True when the fit's colours b over row k's vertices span an albedo edge (spans_albedo_edge).
bool footprint_spans_an_edge(const FootprintRows &rows, size_t k, const float *b, float edge_contrast);

struct DeconvolutionStats {
  size_t edge_vertices = 0;                    // candidates: footprints spanning an edge
  size_t rows = 0, written = 0;                // kept: their rows, and the vertices written
  int iterations = 0, rounds = 0;              // CG iterations (summed over rounds), solves
  // How well the kept result reproduces the fit's colours through the footprints: RMS over their
  // rows of row_misfit (the largest channel's |sum_u W x_u - b_v| over the footprint's brightest b).
  double reblur_rms = 0;
  bool solved = false;                         // false: b kept (no rows, or a failed solve)
  std::string note;                            // one line for the log and report
};

// x (3 per vertex, vertex_count vertices): b deconvolved through `rows` at the vertices with
// write[v] != 0 (null: all) whose footprint spans an edge (footprint_spans_an_edge); elsewhere x = b
// exactly (those vertices are held, their share of each sample moved to the data side).
// `deconvolved` (optional, vertex_count entries): 1 where x was solved for, else 0. `b` and `x` may
// not alias.
DeconvolutionStats deconvolve_albedo(const FootprintRows &rows, size_t vertex_count, const float *b,
                                     const uint8_t *write, const DeconvolutionSettings &settings, float *x,
                                     uint8_t *deconvolved = nullptr);

} // namespace vbrdf
