#pragma once
// The load path of a reference run: a sequence of loads (one per trajectory sample to solve)
// driven through FiniteStrainSolver with automatic cut-back. A load that does not converge is
// retried from the last converged load in halved increments (bisection of the interval between the
// last converged load and the target, tool position and load factor interpolated linearly), up to
// a bounded number of cut-backs; then the path stops with LoadPathError, the solver left at the
// last converged state (issue 3, "a step that does not converge is cut back automatically").
//
// Plain data + Eigen: no deal.II in this header.

#include "reference/finite_strain_solver.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace kerf::reference {

/// Settings of the load path.
struct LoadPathSettings {
  int max_cutbacks = 6; ///< failed attempts allowed per target before the path stops (>= 0)
};

/// One target of the path: the load and the trajectory sample it stands for.
struct LoadTarget {
  LoadState load;
  std::size_t sample = 0; ///< trajectory sample index (for messages and reports)
  double time = 0.0;      ///< trajectory time of the sample [s]
};

/// What solving one target took.
struct LoadStepReport {
  std::size_t sample = 0;
  double time = 0.0; ///< [s]
  bool converged = false;
  int newton_iterations = 0; ///< summed over every attempt, the failed ones included
  int increments = 0;        ///< converged sub-increments (1 without cut-back)
  int cutbacks = 0;          ///< failed attempts that halved the increment
  Eigen::Vector3d tool_force = Eigen::Vector3d::Zero();       ///< contact resultant, body on tool [N]
  Eigen::Vector3d support_reaction = Eigen::Vector3d::Zero(); ///< body on all Dirichlet DOFs [N]
  double final_residual = 0.0; ///< |R_free| at convergence [N]
  double seconds = 0.0;        ///< wall time of all attempts [s]
  EquilibriumReport equilibrium; ///< the solver's report of the last converged increment
};

/// The path stopped: the cut-backs of one target were exhausted. what() names the sample index
/// and time, the residual history of the last attempt and that the last converged state is kept.
class LoadPathError : public std::runtime_error {
public:
  LoadPathError(const std::string& what, std::size_t sample, double time)
      : std::runtime_error(what), m_sample(sample), m_time(time) {}
  [[nodiscard]] std::size_t sample() const { return m_sample; }
  [[nodiscard]] double time() const { return m_time; }

private:
  std::size_t m_sample;
  double m_time;
};

/// Drives a FiniteStrainSolver along loads with cut-back (see file comment). Holds the last
/// converged load and the solver state there (FiniteStrainSolver::state()).
class LoadPath {
public:
  /// `start` is the load at which the solver's current state is in equilibrium (for a fresh
  /// solver: zero load factor and the tool's first position). Throws std::invalid_argument on a
  /// negative max_cutbacks.
  LoadPath(FiniteStrainSolver& solver, const LoadState& start, const LoadPathSettings& settings = {});

  /// Solves `target` from the last converged load. Attempt the whole increment; on failure halve
  /// it (from the last converged sub-load: load(f) = last + f (target − last), f = ½, ¼, …) and
  /// continue towards the target from each converged sub-load with the increment that worked.
  /// After `max_cutbacks` failures throws LoadPathError and leaves the solver at the last
  /// converged state.
  LoadStepReport advance(const LoadTarget& target);

  /// Solves every target in order (see advance); the reports of the converged ones.
  std::vector<LoadStepReport> run(const std::vector<LoadTarget>& targets);

  /// The last load at which the solver converged.
  [[nodiscard]] const LoadState& last_converged_load() const { return m_last; }
  /// The solver state (FiniteStrainSolver::state()) at the last converged load.
  [[nodiscard]] const std::vector<double>& last_converged_state() const { return m_state; }

private:
  FiniteStrainSolver& m_solver;
  LoadPathSettings m_settings;
  LoadState m_last;
  std::vector<double> m_state;
};

/// Linear interpolation of two loads: a + f (b − a) in load factor and tool position.
LoadState interpolate(const LoadState& a, const LoadState& b, double f);

} // namespace kerf::reference
