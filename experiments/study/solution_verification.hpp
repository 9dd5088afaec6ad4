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
