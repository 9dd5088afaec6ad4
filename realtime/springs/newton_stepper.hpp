#pragma once
// NewtonStepper: the network's implicit Euler step and its quasi-static equilibrium, both solved
// by Newton's method on the free degrees of freedom with a sparse Cholesky factorisation that is
// kept across samples (modified Newton), with a line search so that a step far from the
// solution never diverges. For implicit Euler (the servo's default for a blade) the factor is
// refreshed off the servo thread (FactorRefresh) and kept exact across vertex splits by a
// low-rank correction (SplitCorrection): `advance` does not factorise (docs/spring-network.md §2,
// "The kept factor and its refresh"); the linearly implicit and quasi-static steps refactorise
// on the calling thread.

#include "realtime/springs/factor_refresh.hpp"
#include "realtime/springs/lattice_forces.hpp"
#include "realtime/springs/network_system.hpp"
#include "realtime/springs/split_correction.hpp"
#include "realtime/springs/spring_network.hpp"

#include <array>
#include <memory>
#include <vector>

namespace kerf {

/// What one `advance` did.
struct NewtonReport {
  int iterations = 0;
  int factorisations = 0; ///< numeric factorisations on the calling thread (the first, a quasi-static refresh, a rebuild)
  int refreshes = 0;      ///< fresh factors adopted from the worker at the start of this call
  int take_up_corrections = 0; ///< splits a collected factor was corrected for in this call (FactorRefreshPolicy)
  bool converged = false;
  /// Implicit Euler: no step was accepted, and the call held the state (x = xₙ, v = 0) instead
  /// of returning the predictor xₙ + h vₙ (not converged).
  bool held = false;
  double residual = 0.0; ///< final max-norm of the residual [N]
};

/// How implicit Euler takes up a factor computed off the servo thread.
struct FactorRefreshPolicy {
  /// Calls between starting a refresh and collecting its factor; at that call the stepper waits
  /// for the worker if it has not finished, so that a run is the same whatever the machine's
  /// load (a study, a test). Negative: adopt at the first call after the worker has finished,
  /// never waiting (the live rig: not reproducible from run to run).
  int delay = 16;
  /// Anderson acceleration depth of the kept-factor iteration (0: plain modified Newton).
  int anderson_depth = 4;
  /// A factor collected with splits made since its snapshot is corrected for at most this many
  /// of them per call (the kept factor, already corrected for them, serving meanwhile) and taken
  /// up at the call that corrects it for the last: the corrections of a burst of splits (each
  /// ~9 forward substitutions) are spread over the calls instead of falling on one. 0: all at
  /// the adopting call.
  int corrections_per_call = 2;
};

class NewtonStepper {
public:
  /// Linearly implicit Euler: the residual after the step is checked on every 8th call.
  static constexpr int linearised_check_interval = 8;
  /// Backward Euler: a call that needed more kept-factor iterations than this (or did not
  /// converge) asks for a fresh factor.
  static constexpr int refresh_after_iterations = 2;

  enum class Mode {
    /// Backward Euler: M (x − xₙ − h vₙ)/h² = f(x, (x − xₙ)/h), v = (x − xₙ)/h.
    implicit_euler,
    /// Static equilibrium f(x, 0) = 0 per call (inertia and damping left out), v = 0. Factorises
    /// on the calling thread (for comparison with the reference, not for the servo).
    quasi_static,
    /// Linearly implicit (linearised backward) Euler, Baraff & Witkin, "Large steps in cloth
    /// simulation", SIGGRAPH 1998, §4: backward Euler's equation linearised at the predictor
    /// x* = xₙ + h vₙ and solved once, x = x* − A⁻¹ r(x*), v = (x − xₙ)/h, with A the kept
    /// factorisation (refactorised on the calling thread when dt changes, after a tear, and at
    /// the next predictor when a check finds it stale: every `linearised_check_interval`-th call
    /// also evaluates the residual after the step, and a step that reduced it by less than 4 x
    /// (modified Newton's criterion) marks it so; with a stale A a mode grows from sample to
    /// sample, and one solve per sample leaves no iteration to bridge it). One force evaluation
    /// and one pair of triangular solves per call (a second evaluation on check calls);
    /// otherwise the residual after the step is not evaluated, and the report is `converged`
    /// whenever the new state is finite (its `residual` is the predictor's, or after the step
    /// on check calls). At the predictor the velocity is vₙ, so the inertia term of the
    /// residual vanishes and r(x*) = −f(x*, vₙ): while the network is untorn the step takes f in
    /// single precision straight from the lattice into the single-precision solve and back
    /// (x ← x* + A⁻¹ f, v ← vₙ + A⁻¹ f / h), without the per-node force arrays; `forces()` then
    /// holds the forces of the last check call (after a tear: those at the predictor).
    linearly_implicit_euler
  };

  /// Builds the system's pattern for `net` (allocates; for implicit Euler also starts the
  /// refresh worker). `max_iterations` >= 1 per advance; `relative_tolerance` ε > 0: converged
  /// when the residual's max-norm is <= ε k₁ h [N] (the force of an edge spring stretched by ε of
  /// its length). `tear_ready`: the system's pattern has room for vertex splits
  /// (NetworkSystem::rebuild), so that `retopologise` can follow a tear without allocating.
  NewtonStepper(const SpringNetwork& net, Mode mode, int max_iterations, double relative_tolerance = 1e-9,
                bool tear_ready = false, FactorRefreshPolicy policy = {});

  /// Re-analyses after the network's cells, nodes or constraints changed (a tear that did not fit
  /// the pattern). Allocates; the next `advance` factorises.
  void rebuild(const SpringNetwork& net);
  /// Factorises the matrix of a step of `dt` at positions x on the calling thread (the exact
  /// tangent, or the projected one where that is not positive definite): the kept factor until
  /// the first refresh. Call before the first `advance` (a model's reset) so that `advance` never
  /// factorises; if not called, the first `advance` does it. Allocation-free.
  bool prime(const SpringNetwork& net, const Eigen::Matrix3Xd& x, double dt) noexcept;
  /// After vertex splits on a tear-ready stepper (x: the positions at the split): binds the
  /// copies to the kept pattern and, for implicit Euler, corrects the kept factor for them
  /// (SplitCorrection; the other modes refactorise at their next `advance`). Allocation-free;
  /// false if the splits do not fit (then call `rebuild`).
  bool retopologise(const SpringNetwork& net, const Eigen::Matrix3Xd& x) noexcept;

  /// Advances (x, v) by dt [s]. On entry the free axes hold the state at tₙ and the fixed axes
  /// their prescribed end-of-step positions and velocities. The Jacobian A = M/h² + (1 + τ/h) K
  /// (implicit) or K + 10⁻⁸ (‖K‖/‖M‖) M (quasi-static; the small mass term only regularises
  /// floating pieces and leaves the solution unchanged), K the exact tangent where A is positive
  /// definite with it, else the projected one (CellTangent). Implicit Euler iterates on the kept
  /// factor (with the pending splits' correction), accelerated by Anderson mixing, each step
  /// accepted when it lowers the residual's max-norm or satisfies Armijo's condition on the
  /// step's incremental potential, backtracking (1/2, …, 1/32) otherwise; a call that needs
  /// more than `refresh_after_iterations` iterations, does not converge, changes dt or follows a
  /// split asks for a fresh factor, adopted as `FactorRefreshPolicy` says. Quasi-static
  /// refactorises on the calling thread when an iteration reduces the residual by less than 4 x.
  /// Allocation-free.
  NewtonReport advance(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double dt) noexcept;

  /// The internal forces at the state the last `advance` returned (at its velocities, or at
  /// zero velocity quasi-statically) [N], 3 x capacity: the residual's own evaluation, so the
  /// caller need not recompute them. Linearly implicit: the forces at the predictor x*.
  [[nodiscard]] const Eigen::Matrix3Xd& forces() const { return m_f; }
  /// The tangent of the kept factor.
  [[nodiscard]] CellTangent factor_tangent() const { return m_kept.tangent; }

private:
  NetworkSystem& active() { return *m_systems[static_cast<std::size_t>(m_active)]; }
  /// Assembles and factorises the active system on the calling thread.
  bool refactor(const SpringNetwork& net, const Eigen::Matrix3Xd& x, double dt) noexcept;
  /// The room for vertex splits of a tear-ready stepper's systems.
  [[nodiscard]] NetworkSystem::SplitRoom split_room() const;
  [[nodiscard]] double mass_weight(double dt) const;
  [[nodiscard]] double stiffness_weight(const SpringNetwork& net, double dt) const;
  /// Starts a refresh at positions x (if none is running).
  void request_refresh(const SpringNetwork& net, const Eigen::Matrix3Xd& x, double dt) noexcept;
  /// Collects a finished refresh when the policy says so and starts taking it up (take_up; a
  /// take-up under way goes on at the start of the next call, not here).
  void collect_refresh(const SpringNetwork& net, NewtonReport& report) noexcept;
  /// The collected factor (m_fresh) corrected for up to `corrections_per_call` more of the
  /// splits made since its snapshot; once corrected for all, it becomes the kept factor (counted
  /// in `report`).
  void take_up(const SpringNetwork& net, NewtonReport& report) noexcept;
  /// A factor and what its correction needs: its matrix's dt, tangent, weights and positions
  /// (a copy made since at its original's place), its corrections, whether a split could not
  /// be corrected for.
  struct FactorState {
    double dt = -1.0; ///< negative: none
    CellTangent tangent = CellTangent::projected;
    double mass_weight = 0.0, stiffness_weight = 0.0;
    /// The positions the factor's matrix was assembled at; a copy made since sits at its
    /// original's place (its cells were the original's there). A split's correction takes the
    /// moved cells' stiffness at the matrix's own positions, so that the corrected matrix is
    /// the torn network's at one state.
    Eigen::Matrix3Xd x;
    SplitCorrection correction;
    bool uncorrected = false;
  };
  /// Corrects `factor` (of `system`) for split number `index` (recorded by `retopologise`), with
  /// the moved cells' stiffness at the factor's matrix's positions.
  bool correct_for_split(const SpringNetwork& net, long index, NetworkSystem& system, FactorState& factor) noexcept;
  double residual(const SpringNetwork& net, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double dt,
                  LatticeForces::ForcePrecision precision = LatticeForces::ForcePrecision::double_precision) noexcept;
  NewtonReport advance_linearised_on_lattice(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double dt) noexcept;
  NewtonReport advance_linearised(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double dt) noexcept;
  NewtonReport advance_implicit(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double dt) noexcept;
  /// Implicit Euler's call that accepted no step: x = xₙ and v = 0 on the free entries (not the
  /// predictor); returns the residual there, the forces evaluated at it.
  double hold(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double dt) noexcept;
  /// Implicit Euler's factor for a step of dt at x: the kept one (corrected for pending splits),
  /// a fresh one asked for of the refresh worker when dt changed or splits are pending (adopted
  /// when ready), or — never primed, or splits the correction could not take on coupled
  /// shadows — factorised here (counted in `report`). False when that factorisation failed.
  bool keep_factor_for(const SpringNetwork& net, const Eigen::Matrix3Xd& x, double dt, NewtonReport& report) noexcept;
  /// The mixing's history within one `advance`: differences held, the next column to write, and
  /// whether a previous iterate exists (a backtracking step restarts it).
  struct AndersonState {
    int history = 0, slot = 0;
    bool have_previous = false;
  };
  /// From the iterate m_u and its kept-factor step m_g: the next iterate m_u_next, Anderson-mixed
  /// over the history when it has one (then true), else m_u + m_g; records u and g for the next.
  bool anderson_mix(AndersonState& state) noexcept;
  NewtonReport advance_static(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double dt) noexcept;
  /// The free entries (3 p + i with a dof) in node order, their dofs and node masses, from the
  /// system's numbering (after rebuild and after binding splits). Allocation-free.
  void bind_free_entries(const SpringNetwork& net) noexcept;
  /// x's free entries from the iterate vector u (per free entry).
  void write_free(const Eigen::VectorXd& u, Eigen::Matrix3Xd& x) const noexcept;

  Mode m_mode;
  int m_max_iterations;
  FactorRefreshPolicy m_policy;
  std::array<std::unique_ptr<NetworkSystem>, 2> m_systems; ///< the kept factor's and the refresh's
  int m_active = 0;
  std::unique_ptr<FactorRefresh> m_refresh; ///< the worker (implicit Euler)
  LatticeForces m_forces;
  double m_tolerance_ratio;
  bool m_tear_ready = false;
  /// The kept factor (the active system's) and a collected one being taken up (the other
  /// system's, while `m_taking_up`), corrected up to split `m_fresh_next` − 1.
  FactorState m_kept, m_fresh;
  bool m_taking_up = false;
  long m_fresh_next = 0;
  // The running refresh: the call it started at, its dt and weights.
  long m_calls = 0;
  long m_job_call = 0;
  double m_job_dt = 0.0;
  double m_job_mass_weight = 0.0, m_job_stiffness_weight = 0.0;
  long m_splits = 0; ///< vertex splits bound so far
  /// The last splits (by index modulo the ring's size): original, copy, the original's mass before.
  struct RecordedSplit {
    long index = -1;
    int original = -1, copy = -1;
    double mass_before = 0.0;
  };
  std::array<RecordedSplit, SplitCorrection::max_splits> m_recent{};
  double m_static_regularisation = 0.0;
  bool m_refresh_pending = false; ///< linearly implicit: the last check found the kept factorisation stale
  int m_calls_since_check = 0;    ///< linearly implicit: calls since the residual after the step was last checked
  double m_potential = 0.0;       ///< the incremental potential at the last residual evaluation [J]
  Eigen::Matrix3Xd m_x0, m_v0, m_f, m_zero, m_x_before;
  Eigen::VectorXd m_r, m_dx;
  // Anderson mixing, per free entry: the iterate, its step, the previous ones, their differences.
  Eigen::VectorXd m_u, m_g, m_u_previous, m_g_previous, m_u_next;
  Eigen::MatrixXd m_du, m_dg;
  int m_free_count = 0;
  std::vector<int> m_free_entry, m_free_dof; ///< per free entry: 3 p + i, and its dof
  std::vector<double> m_free_mass;           ///< per free entry: the node's mass [kg]
  std::vector<int> m_free_lattice;           ///< per free entry: its LatticeForces::lattice_entry (while untorn)
};

} // namespace kerf
