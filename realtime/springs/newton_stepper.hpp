#pragma once
// NewtonStepper: the network's implicit Euler step and its quasi-static equilibrium, both solved
// by Newton's method on the free degrees of freedom with a sparse LDLᵀ factorisation that is
// kept while it still converges (modified Newton) and refreshed when it does not, with a
// backtracking line search on the residual so that a step far from the solution never diverges.

#include "realtime/springs/lattice_forces.hpp"
#include "realtime/springs/network_system.hpp"
#include "realtime/springs/spring_network.hpp"

#include <vector>

namespace kerf {

/// What one `advance` did.
struct NewtonReport {
  int iterations = 0;
  int factorisations = 0;
  bool converged = false;
  double residual = 0.0; ///< final max-norm of the residual [N]
};

class NewtonStepper {
public:
  /// Linearly implicit Euler: the residual after the step is checked on every 8th call.
  static constexpr int linearised_check_interval = 8;
  /// Backward Euler and quasi-static: refreshes of the kept factorisation within one `advance`
  /// (besides the one a new dt or a tear needs). Where even a fresh factorisation converges
  /// slowly (a snap-through of the cells crushed under a blade, whose tangent is indefinite
  /// while K_T is projected) refreshing at every iteration multiplied a sample's cost up to
  /// 8 x (potato_rect_cut at 8³: 46 ms CPU, one refresh each: 8.5 ms) without converging.
  static constexpr int max_refreshes = 1;

  enum class Mode {
    /// Backward Euler: M (x − xₙ − h vₙ)/h² = f(x, (x − xₙ)/h), v = (x − xₙ)/h.
    implicit_euler,
    /// Static equilibrium f(x, 0) = 0 per call (inertia and damping left out), v = 0.
    quasi_static,
    /// Linearly implicit (linearised backward) Euler, Baraff & Witkin, "Large steps in cloth
    /// simulation", SIGGRAPH 1998, §4: backward Euler's equation linearised at the predictor
    /// x* = xₙ + h vₙ and solved once, x = x* − A⁻¹ r(x*), v = (x − xₙ)/h, with A the kept
    /// factorisation (refreshed when dt changes, after a tear, and at the next call's x* when a
    /// check finds it stale: every `linearised_check_interval`-th call also evaluates the
    /// residual after the step, and a step that reduced it by less than 4 x (modified Newton's
    /// criterion) marks it so; with a stale A a mode grows from sample to sample). One force
    /// evaluation and one pair of triangular solves per call (a second evaluation on check
    /// calls); otherwise the residual after the step is not evaluated, and the report is
    /// `converged` whenever the new state is finite (its `residual` is the predictor's, or after
    /// the step on check calls). At the predictor the velocity is vₙ, so the inertia term of
    /// the residual vanishes and r(x*) = −f(x*, vₙ): while the network is untorn the step takes
    /// f in single precision straight from the lattice into the single-precision solve and back
    /// (x ← x* + A⁻¹ f, v ← vₙ + A⁻¹ f / h), without the per-node force arrays; `forces()` then
    /// holds the forces of the last check call (after a tear: those at the predictor).
    linearly_implicit_euler
  };

  /// Builds the system's pattern for `net` (allocates). `max_iterations` >= 1 per advance;
  /// `relative_tolerance` ε > 0: converged when the residual's max-norm is <= ε k₁ h [N] (the
  /// force of an edge spring stretched by ε of its length).
  /// `tear_ready`: the system's pattern has room for vertex splits (NetworkSystem::rebuild), so
  /// that `retopologise` can follow a tear without allocating.
  NewtonStepper(const SpringNetwork& net, Mode mode, int max_iterations, double relative_tolerance = 1e-9,
                bool tear_ready = false);

  /// Re-analyses after the network's cells, nodes or constraints changed (a tear). Allocates.
  void rebuild(const SpringNetwork& net);
  /// After vertex splits on a tear-ready stepper: binds the copies to the kept pattern and marks
  /// the factorisation stale (the next `advance` refactorises). Allocation-free; false if the
  /// splits do not fit (then call `rebuild`).
  bool retopologise(const SpringNetwork& net) noexcept;

  /// Advances (x, v) by dt [s]. On entry the free axes hold the state at tₙ and the fixed axes
  /// their prescribed end-of-step positions and velocities. The Jacobian A = M/h² + (1 + τ/h) K_T (implicit) or K_T + 10⁻⁸ (‖K‖/‖M‖) M (quasi-static; the
  /// small mass term only regularises floating pieces and leaves the solution unchanged) is
  /// factorised on the first call, when dt changes, and (at most `max_refreshes` times per
  /// call) when an iteration reduces the residual by less than a factor 4, or when no step
  /// length of the line search (1, 1/2, …, 1/32 of the Newton step) lowers the residual.
  /// Allocation-free.
  NewtonReport advance(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double dt) noexcept;

  /// The internal forces at the state the last `advance` returned (at its velocities, or at
  /// zero velocity quasi-statically) [N], 3 x capacity: the residual's own evaluation, so the
  /// caller need not recompute them. Linearly implicit: the forces at the predictor x*.
  [[nodiscard]] const Eigen::Matrix3Xd& forces() const { return m_f; }

private:
  bool refactor(const SpringNetwork& net, const Eigen::Matrix3Xd& x, double dt) noexcept;
  double residual(const SpringNetwork& net, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double dt,
                  LatticeForces::ForcePrecision precision = LatticeForces::ForcePrecision::double_precision) noexcept;
  /// The linearly implicit step while the network is untorn (see Mode::linearly_implicit_euler).
  NewtonReport advance_linearised_on_lattice(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double dt) noexcept;
  /// The free entries (3 p + i with a dof) in node order, their dofs and node masses, from the
  /// system's numbering (after rebuild and after binding splits). Allocation-free.
  void bind_free_entries(const SpringNetwork& net) noexcept;

  Mode m_mode;
  int m_max_iterations;
  NetworkSystem m_system;
  LatticeForces m_forces;
  double m_tolerance_ratio;
  bool m_tear_ready = false;
  double m_factor_dt = -1.0;
  double m_static_regularisation = 0.0;
  bool m_refresh_pending = false; ///< linearly implicit: the last check found the kept factorisation stale
  int m_calls_since_check = 0;    ///< linearly implicit: calls since the residual after the step was last checked
  Eigen::Matrix3Xd m_x0, m_v0, m_f, m_zero, m_x_before;
  Eigen::VectorXd m_r, m_dx;
  int m_free_count = 0;
  std::vector<int> m_free_entry, m_free_dof; ///< per free entry: 3 p + i, and its dof
  std::vector<double> m_free_mass;           ///< per free entry: the node's mass [kg]
  std::vector<int> m_free_lattice;           ///< per free entry: its LatticeForces::lattice_entry (while untorn)
};

} // namespace kerf
