#pragma once
// The downhill simplex minimiser of Nelder & Mead (1965), with the standard coefficients and the
// tie-breaking and shrink rules of Lagarias, Reeds, Wright & Wright, "Convergence properties of the
// Nelder–Mead simplex method in low dimensions", SIAM J. Optim. 9 (1998) 112–147.
//
// Calibration uses it because its objective — the normalised RMS force error of a fast model
// against a target profile — is only piecewise smooth in the parameters: a rupture that moves by
// one servo sample, a voxel advanced one step earlier, a mode switch, each make a jump. A
// derivative-based method (Levenberg–Marquardt) would need finite-difference Jacobians across
// those jumps; the simplex needs function values only, and the models have 1 to 3 free
// parameters, where it is efficient.

#include <Eigen/Core>

#include <functional>

namespace kerf {

struct NelderMeadSettings {
  int max_evaluations = 300;   ///< objective evaluations at most
  /// Converged when every vertex lies within this (∞-norm) of the best one and the values differ by
  /// less than `value_tolerance` (Lagarias et al. §2's termination on both).
  double step_tolerance = 1e-6;
  double value_tolerance = 1e-12;
  double initial_step = 0.25;  ///< the initial simplex: x0 + initial_step e_k, k = 1..n
};

struct NelderMeadResult {
  Eigen::VectorXd x;           ///< the best vertex
  double value = 0.0;          ///< f(x)
  int evaluations = 0;
  bool converged = false;      ///< false: stopped at max_evaluations
};

/// Minimises `f` from `x0`. Reflection ρ = 1, expansion χ = 2, contraction γ = 1/2, shrink
/// σ = 1/2 (Lagarias et al. 1998, Eq. 2.1). A non-finite f is treated as +∞ (the simplex moves
/// away from it). Throws std::invalid_argument for an empty x0 or non-positive settings.
NelderMeadResult nelder_mead(const std::function<double(const Eigen::VectorXd&)>& f, const Eigen::VectorXd& x0,
                             const NelderMeadSettings& settings = {});

} // namespace kerf
