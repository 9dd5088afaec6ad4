#pragma once
// The load path of a reference run: a sequence of loads (one per trajectory sample to solve)
// driven through FiniteStrainSolver with automatic cut-back. A load that does not converge is
// retried from the last converged load in halved increments (bisection of the time interval
// between the last converged load and the target), up to a bounded number of cut-backs; then the
// path stops with LoadPathError, the solver left at the last converged state. The loads between
// two targets are those of the motion (LoadPath's `motion`: the tool where the trajectory has it
// at that time), so a cut-back follows the trajectory, not the chord between the two targets;
// without a motion they are interpolated linearly.
// With the interface energy control (LoadPathSettings::interface_error_relative/absolute; the
// dynamic step with a cohesive interface) a converged increment whose time integration error at
// the cohesive law's kinks is too large is rejected the same way: the solver is restored to the
// last converged state and the increment halved.
//
// Plain data + Eigen: no deal.II in this header.

#include "reference/finite_strain_solver.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace kerf::reference {

/// Settings of the load path.
struct LoadPathSettings {
  int max_cutbacks = 6; ///< failed attempts allowed per target before the path stops (>= 0)
  /// Interface energy control of the dynamic step (0 and 0: off). A converged increment is
  /// rejected (and halved, as a failure is) when its kinks error e
  /// (CohesiveSummary::step_time_integration_error) exceeds
  ///   |e| > interface_error_relative × ΔD + interface_error_absolute,
  /// ΔD the increment's cohesive dissipation (CohesiveSummary::step_dissipation). Summed over a
  /// run, |Σ e| <= interface_error_relative × D + (accepted increments) × interface_error_absolute:
  /// the relative part bounds the kinks error by a fraction of the dissipation itself. Once the
  /// cut-backs of a target are used up the last converged increment is kept (no stop: the error
  /// stays reported), and LoadStepReport::interface_tolerance_exceeded says so.
  /// Step growth under the control: e/ΔD grows as h² (a point that crosses a kink within a step
  /// overshoots it by O(h) against a traction of O(h)), so an accepted increment with |e| below a
  /// quarter of its tolerance doubles the next one (in a target without Newton failures), and the
  /// increment in use at the end of a target carries over, as a time step, to the next target
  /// (LoadPath::interface_step) instead of restarting from the whole interval.
  double interface_error_relative = 0.0; ///< >= 0
  double interface_error_absolute = 0.0; ///< [J] >= 0
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
  int cutbacks = 0;          ///< failed or rejected attempts that halved the increment
  int interface_rejections = 0; ///< of the cut-backs, converged increments rejected by the interface energy control
  bool interface_tolerance_exceeded = false; ///< an increment was kept above the tolerance (cut-backs used up)
  double interface_error = 0.0; ///< Σ of the accepted increments' kinks errors e [J]
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

/// The load at time t [s]: the tool where its trajectory has it, and the load factor of t.
using LoadMotion = std::function<LoadState(double time)>;

/// Drives a FiniteStrainSolver along loads with cut-back (see file comment). Holds the last
/// converged load and the solver state there (FiniteStrainSolver::state()).
class LoadPath {
public:
  /// `start` is the load at which the solver's current state is in equilibrium (for a fresh
  /// solver: zero load factor and the tool's first position). `motion` gives the loads between
  /// two targets (empty: linear interpolation of the two). Throws std::invalid_argument on a
  /// negative max_cutbacks.
  LoadPath(FiniteStrainSolver& solver, const LoadState& start, const LoadPathSettings& settings = {},
           LoadMotion motion = {});

  /// Solves `target` from the last converged load. Attempt the whole increment; on failure halve
  /// it (from the last converged sub-load: the load at time t_last + f (t_target − t_last),
  /// f = ½, ¼, …, on the motion, or last + f (target − last) without one) and
  /// continue towards the target from each converged sub-load with the increment that worked.
  /// After `max_cutbacks` failures throws LoadPathError and leaves the solver at the last
  /// converged state. A converged increment that fails the interface energy control (see
  /// LoadPathSettings) is undone (FiniteStrainSolver::set_state of the last converged state) and
  /// halved like a failure, unless the cut-backs are used up.
  LoadStepReport advance(const LoadTarget& target);

  /// Solves every target in order (see advance); the reports of the converged ones.
  std::vector<LoadStepReport> run(const std::vector<LoadTarget>& targets);

  /// The last load at which the solver converged.
  [[nodiscard]] const LoadState& last_converged_load() const { return m_last; }
  /// The solver state (FiniteStrainSolver::state()) at the last converged load.
  [[nodiscard]] const std::vector<double>& last_converged_state() const { return m_state; }
  /// Under the interface energy control: the time step [s] the next target starts with (0: its
  /// whole interval). Travels with a checkpoint so that a resumed run steps as the uninterrupted one.
  [[nodiscard]] double interface_step() const { return m_interface_step; }
  void set_interface_step(double seconds) { m_interface_step = seconds > 0.0 ? seconds : 0.0; }

private:
  /// The load a fraction f of the way in time from `from` to `to` (on the motion when there is one).
  [[nodiscard]] LoadState between(const LoadState& from, const LoadState& to, double f) const;

  FiniteStrainSolver& m_solver;
  LoadPathSettings m_settings;
  LoadMotion m_motion;
  LoadState m_last;
  std::vector<double> m_state;
  double m_interface_step = 0.0;
};

/// Linear interpolation of two loads: a + f (b − a) in load factor and tool position.
LoadState interpolate(const LoadState& a, const LoadState& b, double f);

} // namespace kerf::reference
