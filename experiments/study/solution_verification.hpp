#pragma once
// Solution verification of the reference: from one quantity solved on three systematically refined
// meshes, the observed order of convergence, the Richardson-extrapolated value and Roache's grid
// convergence index (GCI) as the relative uncertainty of the finest solution.
//
// The procedure is Celik et al. 2008, "Procedure for estimation and reporting of uncertainty due to
// discretization in CFD applications", J. Fluids Eng. 130(7) 078001 (the ASME editorial policy),
// Eqs. 1-6 and Table 1. With element sizes h1 < h2 < h3 (finest first) and the quantity φ1, φ2, φ3
// on them:
//
//   r21 = h2 / h1,  r32 = h3 / h2,  ε21 = φ2 - φ1,  ε32 = φ3 - φ2,  s = sign(ε32 / ε21)
//   p = |ln|ε32 / ε21| + q(p)| / ln r21,  q(p) = ln((r21^p - s) / (r32^p - s))     (Eqs. 3a-c)
//   φ_ext = (r21^p φ1 - φ2) / (r21^p - 1)                                          (Eq. 4)
//   e_a = |(φ1 - φ2) / φ1|,  e_ext = |(φ_ext - φ1) / φ_ext|                         (Eq. 5)
//   GCI_fine = Fs e_a / (r21^p - 1),  Fs = 1.25 for three grids                      (Eq. 6)
//
// p is found by fixed-point iteration from q = 0 (exact in one step for a constant ratio r21 = r32).
// s < 0 (ε32/ε21 < 0) is oscillatory convergence: the paper computes p, φ_ext and the GCI with
// s = -1 all the same, and says so; so does this file (`oscillatory`). Where the procedure does
// not apply — ε21 or ε32 zero, φ1 zero, the differences growing under refinement (the iteration's
// argument negative before the absolute value: divergence), or no fixed point — the result says
// why (`unusable`) and claims no uncertainty.
//
// Plain data in, plain data out: no profiles, no scenes.

#include <optional>
#include <string>
#include <vector>

namespace kerf {

/// One quantity on three meshes, finest first: element sizes h1 < h2 < h3 [any unit] and the
/// quantity on each.
struct GridTriplet {
  double h1 = 0.0, h2 = 0.0, h3 = 0.0;
  double phi1 = 0.0, phi2 = 0.0, phi3 = 0.0;
};

/// Roache's safety factor for a three-grid study with an observed order (Celik et al. 2008, Eq. 6).
inline constexpr double gci_safety_factor = 1.25;

/// Celik et al. 2008's results for one GridTriplet.
struct GridConvergence {
  GridTriplet grids;                      ///< the input
  double r21 = 0.0, r32 = 0.0;            ///< refinement ratios h2/h1, h3/h2 (> 1)
  bool oscillatory = false;               ///< ε32/ε21 < 0: computed with s = -1, reported as such
  std::optional<double> observed_order;   ///< p; empty when unusable
  std::optional<double> extrapolated;     ///< φ_ext^21, Richardson-extrapolated value
  double approximate_relative_error = 0;  ///< e_a^21 = |φ1 - φ2| / |φ1| (0 when φ1 = 0)
  std::optional<double> extrapolated_relative_error; ///< e_ext^21 = |φ_ext - φ1| / |φ_ext|
  std::optional<double> gci_fine;         ///< GCI_fine^21, relative to |φ1|
  int iterations = 0;                     ///< fixed-point iterations for p
  std::string unusable;                   ///< why no GCI (empty when gci_fine is set)

  [[nodiscard]] bool usable() const { return gci_fine.has_value(); }
};

/// Celik et al. 2008's procedure on `grids` (h1 < h2 < h3, finite φ). Throws std::invalid_argument
/// for sizes that are not strictly increasing and positive, or a non-finite φ.
GridConvergence grid_convergence(const GridTriplet& grids, double safety_factor = gci_safety_factor);

/// The discretisation error of a whole profile (a function of the trajectory, not one number),
/// from the norms of the differences between successive levels, finest first:
///
///   e21 = ‖f2 − f1‖,  e32 = ‖f3 − f2‖   (any norm over the samples; the study's: RMS over them)
///
/// With the error ‖f_h − f‖ ≈ C h^p, f2 − f1 ≈ C h1^p (r21^p − 1) and f3 − f2 ≈ C h1^p r21^p
/// (r32^p − 1), so the observed order p solves
///
///   e32 / e21 = r21^p (r32^p − 1) / (r21^p − 1)        (r^p for a constant ratio r)
///
/// and the uncertainty of the finest profile in that norm is Roache's GCI in absolute form,
/// U = Fs e21 / (r21^q − 1) with q = min(p, p_formal): an observed order above the method's formal
/// order is not trusted (Roache 1998, "Verification and Validation in Computational Science and
/// Engineering": where the observed order exceeds the formal one, the GCI takes the formal order). Unlike the
/// GCI of one trajectory-wide number (the RMS of |F|, whose levels may agree by coincidence while
/// their profiles differ sample by sample), a norm of differences cannot cancel: it is zero only
/// where the levels agree everywhere, and it is the scale of a model's RMS force error.
/// Unusable, with the reason, when e21 = 0 (no difference to extrapolate from) or e32 <= e21
/// (the differences do not shrink: no asymptotic range, no order).
struct DifferenceConvergence {
  double r21 = 0.0, r32 = 0.0;          ///< refinement ratios h2/h1, h3/h2
  double e21 = 0.0, e32 = 0.0;          ///< norms of the level differences (input)
  double formal_order = 0.0;            ///< p_formal, the cap of the order used
  std::optional<double> observed_order; ///< p; empty when unusable
  std::optional<double> order_used;     ///< q = min(p, p_formal)
  std::optional<double> uncertainty;    ///< U = Fs e21 / (r21^q − 1), in the unit of e
  std::string unusable;                 ///< why no uncertainty (empty when `uncertainty` is set)

  [[nodiscard]] bool usable() const { return uncertainty.has_value(); }
};

/// The estimate above for element sizes h1 < h2 < h3 and the difference norms e21, e32 (>= 0).
/// Throws std::invalid_argument for sizes not strictly increasing and positive, a negative or
/// non-finite norm, or a formal order <= 0.
DifferenceConvergence difference_convergence(double h1, double h2, double h3, double e21, double e32, double formal_order,
                                             double safety_factor = gci_safety_factor);

/// The half-width U_k of the uncertainty band of the finest solution at each sample k of a profile,
/// from the finest (`fine`) and the next coarser (`medium`) level at the same samples:
///
///   U_k = Fs |f1,k - f2,k| / (r21^p - 1)
///
/// the GCI_fine of Eq. 6 in absolute form, sample by sample, with one observed order p for all
/// samples: the order of the trajectory-wide quantity (the RMS force). Celik et al. 2008 draw
/// their profile's error bars the same way (Fig. 1: local GCI with the average order p_ave)
/// because a local order is meaningless where the level differences cross zero. Throws
/// std::invalid_argument for sizes that differ, r21 <= 1 or p <= 0.
std::vector<double> gci_band_half_width(const std::vector<double>& fine, const std::vector<double>& medium, double r21,
                                        double observed_order, double safety_factor = gci_safety_factor);

} // namespace kerf
