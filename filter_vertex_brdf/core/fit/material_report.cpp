#include "fit/material_report.h"

#include <algorithm>
#include <sstream>

#include "base/vec3.h"

namespace vbrdf {
namespace material_stage {

namespace {

// How K and the priors were chosen: the held-out error of every K relative to the best.
void write_choice(std::ostringstream &rep, const MaterialResult &R, const MaterialReportFacts &f,
                  const MaterialOptions &mo) {
  rep << "materials: chosen by held-out error (every 4th photo left out, fitted on the others";
  if (R.folds > 1)
    rep << "; " << f.photos << " photos (fewer than " << mo.pool_folds_below << "): summed over " << size_t(R.folds)
        << " such splits, until at least " << mo.min_heldout_photos << " photos were held out";
  rep << "): ";
  for (size_t k = 0; k < R.heldout_error.size(); ++k)
    rep << (k ? ", " : "") << "K=" << k + 1 << " " << fixed(R.heldout_error[k] / std::max(f.best_error, 1e-300), 4);
  rep << " (relative to the best); smallest K within " << fixed(100 * mo.choose_tolerance, 1) << " % of the best: "
      << f.k_within_tolerance;
  if (f.merged)
    rep << ", " << f.merged << " of whose materials had another's lobe (both diffuse, or k_s and alpha within "
        << fixed(100 * mo.twin_lobe_tolerance, 0) << " %): merged, K = " << f.k_merged;
  rep << "; k_s prior strength " << R.chosen_prior << ", per-vertex alpha "
      << (R.chosen_alpha_prior < 0 ? std::string("= the material's") : "prior strength " + fixed(R.chosen_alpha_prior, 3))
      << "\n";
}

// Whether a glossy material's lobe was given to its vertices without one, and the held-out figures
// that decided it.
void write_giving(std::ostringstream &rep, const GivingTest &g, size_t folds, const MaterialOptions &mo) {
  rep << "; its lobe given to the vertices without one of their own? on " << g.vertices << " such vertices of the subsample";
  if (folds > 1) rep << " (each counted once per split that judges it)";
  if (g.unjudged) rep << " (" << g.unjudged << " more left out: the split's training or held-out photos do not see them)";
  rep << ", " << g.samples << " held-out samples (grazing ones included): mean CIEDE2000 " << fixed(g.mean_with(), 3)
      << " with it, " << fixed(g.mean_without(), 3) << " without (per vertex " << fixed(g.mean_difference(), 3)
      << " +- " << fixed(g.standard_error(), 3) << "): ";
  if (g.gives(mo))
    rep << "given";
  else
    rep << "NOT given (not " << fixed(100 * mo.min_giving_gain, 1) << " % lower by " << fixed(mo.giving_confidence, 1)
        << " standard errors: they keep their own fit)";
}

// One line per material: its members, its pooled lobe, and diffuse or given.
void write_material(std::ostringstream &rep, int m, const Material &mat, const MaterialReportFacts &f,
                    const MaterialOptions &mo, LobeForm lobe, size_t folds) {
  const LobeFit &lf = f.lobes[size_t(m)];
  rep << "  material " << m << ": " << mat.vertices << " vertices (" << mat.evidence_vertices
      << " with specular information of their own), " << mat.samples << " samples, " << mat.highlight_samples
      << " highlight samples; pooled lobe k_s " << fixed(lf.ks, 4) << ", alpha (" << lobe_form_label(lobe) << ") "
      << fixed(lf.alpha, 1) << " (within 1 % of the best energy for alpha " << fixed(lf.alpha_lo, 1) << ".."
      << fixed(lf.alpha_hi, 1) << "), the lobe lowers the pooled energy by " << fixed(100 * mat.lobe_gain, 2)
      << " %; median k_d " << fixed(mat.median_kd, 4);
  if (mat.diffuse)
    rep << "; DIFFUSE (k_s below " << fixed(100 * mo.diffuse_ks_fraction, 1) << " % of k_d, alpha <= "
        << fixed(mo.min_lobe_alpha, 1) << ", or the lobe lowers the energy by less than "
        << fixed(100 * mo.min_lobe_gain, 1) << " %)"
        << (f.any_glossy ? ": k_s = 0, specular stages skipped for its vertices" : "");
  const GivingTest &g = f.giving[size_t(m)];
  if (!mat.diffuse && (g.vertices || g.unjudged)) write_giving(rep, g, folds, mo);
  rep << "\n";
}

} // namespace

std::string material_report(const MaterialResult &R, const MaterialReportFacts &f, const MaterialOptions &mo,
                            LobeForm lobe) {
  if (f.eligible_vertices == 0) return "materials: no vertex with samples: stage skipped\n";
  std::ostringstream rep;
  write_choice(rep, R, f, mo);
  for (int m = 1; m <= R.chosen_k; ++m) write_material(rep, m, R.materials[size_t(m) - 1], f, mo, lobe, size_t(R.folds));
  if (!f.any_glossy)
    rep << "  no glossy material among the " << R.chosen_k << " found: every vertex keeps its own fit (its own "
        << "highlights, if any, are the only specular evidence)\n";
  rep << "  vertices given a lobe that had none: " << R.vertices_changed_to_specular
      << "; vertices set diffuse (in a diffuse material): " << R.vertices_set_diffuse << "; samples kept "
      << fixed(double(R.bytes_kept) / (1 << 20), 1) << " MB; " << fixed(R.seconds, 2) << " s (CPU, double; choosing K on "
      << f.selection_vertices << " vertices " << fixed(f.seconds_choice, 2) << " s)\n";
  return rep.str();
}

} // namespace material_stage
} // namespace vbrdf
