// Newton–Raphson for one load (step-44's solve_nonlinear_timestep): K du = −R with the Dirichlet
// increment imposed through the constraints, a backtracking line search on the free residual,
// limited-memory BFGS steps between tangents (Matthies & Strang 1979) where they are allowed, the
// convergence test |R_free| <= rel (|f_int| + |f_ext|) + abs (or a stall within ten times it),
// and after convergence the support reactions and the commit of the cohesive interface and the
// Newmark state.
//
// NewtonIteration holds one load's iteration; its steps, in the loop's order (solve_nonlinear):
// assemble_state (the residual, with the tangent when a Newton step follows), converged,
// solve_linear_system (the Newton step K du = −R, or the quasi-Newton direction), line_search
// (assemble_trial for each step length), update_quasi_newton, accept_step (which of the step's
// assemblies is the next state's); after convergence, commit.

#include "reference/solver/finite_strain_impl.hpp"

#include "reference/material/finite_strain_error.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <type_traits>

namespace kerf::reference {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

} // namespace

template <class Algebra>
class FiniteStrainSolver::Impl::NewtonIteration {
public:
  using VectorType = typename Algebra::VectorType;
  static constexpr bool serial_algebra = std::is_same_v<VectorType, dealii::Vector<double>>;

  NewtonIteration(Impl& impl, Algebra& algebra, const LoadState& load_state)
      : m(impl), la(algebra), load(load_state),
        quasi_newton_allowed(serial_algebra && m.settings.quasi_newton && !m.tool && !m.cohesive_law &&
                             m.linear->kind() == TangentSolver::Kind::direct) {
    la.reinit(rhs);
    la.reinit(full_rhs);
    la.reinit(du);
  }

  /// Iterates from the state in la.u to equilibrium (report.converged): nothing, else why not.
  std::optional<std::string> solve_nonlinear() {
    for (int it = 0;; ++it) {
      if (!assembled) assemble_state(it);
      assembled = false;
      const double r = m.free_norm(assembly.residual, la.free_mask);
      report.residual_history.push_back(r);
      const double scale = assembly.internal_norm + assembly.external_norm;
      const double tol = m.settings.relative_tolerance * scale + m.settings.absolute_tolerance;
      if (converged(r, tol)) {
        report.converged = true;
        return std::nullopt;
      }
      if (it >= m.settings.max_newton_iterations)
        return "no convergence in " + std::to_string(m.settings.max_newton_iterations) + " Newton iterations";
      const bool newton_step = newton_next || mismatch > 0.0 || !quasi_newton_allowed;
      solve_linear_system(newton_step);
      ++report.newton_iterations;
      const VectorType base = la.u;
      const Step step = line_search(base, it, r, tol);
      if (!newton_step && !(step.r < r)) {
        // The quasi-Newton direction does not reduce |R|: back to the state, a Newton step next.
        la.u = base;
        newton_next = true;
        assembled = true; // the residual is still the state's (its tangent is assembled above)
        with_tangent = false;
        continue;
      }
      if (step.alpha == 0.0) return "every line-search step inverts an element";
      la.u = base;
      la.u.add(step.alpha, du);
      if constexpr (serial_algebra) {
        if (quasi_newton_allowed) update_quasi_newton(step, r);
      }
      interface_tangent = after_step(interface_tangent, it + 1, step.alpha == 1.0 && step.r <= good_ratio * r);
      accept_step(step, newton_step);
    }
  }

  /// The converged state: the support reactions, the commit of the cohesive interface and the
  /// Newmark state, the tool's and the foundations' forces and the contact's tallies.
  void commit() {
    support_reactions();
    if (m.cohesive_law) report.cohesive = m.commit_cohesive(load, la.readable(la.u));
    if (m.dynamics) {
      if constexpr (serial_algebra)
        report.kinetic_energy = m.commit_dynamics(la.u);
      else
        report.kinetic_energy = m.commit_dynamics(m.gathered(la.u)); // u_{n+1} on every process
      report.damping_dissipation = m.dynamics->damping_dissipation;
    }
    m.committed_time = load.time;
    report.tool_force = -assembly.contact_on_body;
    report.traction_resultant = assembly.traction_on_body;
    report.force_imbalance = report.traction_resultant - report.tool_force - report.support_reaction;
    // The foundations: body on anchor = −∫ k (d − u) dA.
    for (const Eigen::Vector3d& f : assembly.foundation_on_body) {
      report.foundation_forces.push_back(-f);
      report.force_imbalance += f;
    }
    report.foundation_energy = assembly.foundation_energy;
    report.edge_contact_points = assembly.edge_points;
    report.edge_contact_length = assembly.edge_length;
    report.max_edge_line_load = assembly.max_line_load;
    report.contact_points = assembly.contact_points;
    report.contact_area = assembly.contact_area;
    report.max_contact_pressure = assembly.max_pressure;
    report.contact_energy = assembly.contact_energy;
  }

  EquilibriumReport report;

private:
  /// A line search's result: the accepted step length α (0: every α tried inverts an element)
  /// and the |R_free| it leaves.
  struct Step {
    double alpha = 0.0;
    double r = std::numeric_limits<double>::infinity();
  };

  // A cohesive interface whose points switch between loading and unloading can make the
  // consistent Newton iteration cycle. From a third of the allowed iterations on, a step that is
  // not good (a shortened step, or |R| reduced by less than `good_ratio`) hands the interface to
  // its secant tangent (slower, but it does not cycle); once `needed` secant steps in a row are
  // good, the iteration has settled and the consistent tangent returns, so that the last
  // iterations converge quadratically instead of linearly. Each return that ends in another
  // switch doubles `needed`, so that a cycling iteration stays with the secant. The choice changes
  // the tangent only, never the residual or the equilibrium.
  struct InterfaceTangent {
    bool secant = false;
    int good_run = 0; // good secant steps in a row
    int needed = 1;   // good secant steps before the consistent tangent returns
    bool returned = false;
  };
  static constexpr double good_ratio = 0.7;

  static constexpr std::size_t max_updates = 10; // quasi-Newton: BFGS updates kept before a Newton step

  Impl& m;
  Algebra& la;
  const LoadState& load;
  // `assembly` (with la.K, `rhs` and `constraints` when `with_tangent`) is the assembly of the
  // current state la.u when `assembled`. A Newton step assembles its full step (α = 1) with the
  // tangent, so that when it is accepted the next Newton step starts from it.
  Assembly<VectorType> assembly, full, trial;
  VectorType rhs, full_rhs, du;
  dealii::AffineConstraints<double> constraints, full_constraints;
  double mismatch = 0.0;
  bool assembled = false, with_tangent = false;
  // Quasi-Newton (SolverSettings::quasi_newton; serial direct solver): steps with the last
  // factorised tangent K₀ corrected by the BFGS updates of the steps since (limited memory, the
  // two-loop recursion with H₀ = K₀⁻¹; Matthies & Strang 1979, Nocedal 1980). A full Newton step
  // (tangent assembled and factorised) is taken when a Dirichlet increment is pending, when no
  // factorisation exists, and after a quasi-Newton step that reduced |R| by less than half, did
  // not reduce it, or used up the updates.
  // Contact and a cohesive interface change the tangent abruptly (points enter and leave the
  // contact set, the interface softens): there the updates converge slowly, and full Newton is used.
  // Every solve starts with a Newton step (FEBio's "reform each time step"), so that a solve
  // depends on its start state alone (a run resumed from a checkpoint repeats it bit for bit).
  const bool quasi_newton_allowed;
  bool newton_next = true;
  std::vector<VectorType> S, Y; // the steps s = Δu and residual changes y = ΔR of the updates
  std::vector<double> rho;      // 1 / (yᵀ s)
  // Fault injection: asked once per iteration (the full step's assembly asks for the next one).
  int fault_asked = -1;
  bool fault_answer = false;
  InterfaceTangent interface_tangent;
  // The line search's full step (α = 1): assembled without an inverted element, with its
  // tangent, with the secant interface tangent, and its Dirichlet mismatch.
  bool full_valid = false, full_tangent = false, full_secant = false;
  double full_mismatch = 0.0;

  bool fault(int it) {
    if (!m.settings.residual_fault) return false;
    if (fault_asked != it) {
      fault_asked = it;
      fault_answer = m.settings.residual_fault(load, it);
    }
    m.fault_fired = m.fault_fired || fault_answer;
    return fault_answer;
  }

  /// The interface tangent of iteration `next` after a step that was (not) good.
  [[nodiscard]] InterfaceTangent after_step(InterfaceTangent t, int next, bool good) const {
    if (!m.cohesive_law || next < m.settings.max_newton_iterations / 3) return InterfaceTangent{};
    if (!t.secant) {
      if (!good) {
        t.secant = true;
        t.good_run = 0;
        if (t.returned) t.needed *= 2;
      }
      return t;
    }
    t.good_run = good ? t.good_run + 1 : 0;
    if (t.good_run >= t.needed) {
      t.secant = false;
      t.returned = true;
    }
    return t;
  }

  /// The state's constraints and residual, with the tangent when a Newton step follows.
  void assemble_state(int it) {
    const auto t0 = Clock::now();
    mismatch = m.dirichlet_constraints(la, la.u, load, constraints);
    m.cohesive_secant = interface_tangent.secant;
    m.poison_residual = fault(it);
    with_tangent = newton_next || mismatch > 0.0;
    m.assemble(la, la.u, load, with_tangent, assembly, with_tangent ? &constraints : nullptr,
               with_tangent ? &rhs : nullptr);
    m.poison_residual = false;
    report.assembly_seconds += seconds_since(t0);
  }

  /// |R_free| <= tol with the Dirichlet increment imposed, or a stall within ten times tol.
  [[nodiscard]] bool converged(double r, double tol) const {
    // The floor of the arithmetic: an iteration whose last three steps each reduced |R| by less
    // than half, within ten times the tolerance, has stopped converging and stays where the
    // roundoff of the solve and the residual leave it (the double cantilever beam's first
    // sample on quadratic cells: |R| 1.5e-10 → 1.4e-10 → 1.2e-10 N … against 8.9e-11 N, the
    // system having carried a 104 N reaction in its first iteration). That state is accepted.
    const std::vector<double>& h = report.residual_history;
    const std::size_t n_h = h.size();
    const bool stalled = n_h >= 4 && r <= 10.0 * tol && h[n_h - 1] > 0.5 * h[n_h - 2] &&
                         h[n_h - 2] > 0.5 * h[n_h - 3] && h[n_h - 3] > 0.5 * h[n_h - 4];
    const double u_scale = std::max(la.u.linfty_norm(), 1e-300);
    return (r <= tol || stalled) && mismatch <= 1e-12 * u_scale + 1e-300;
  }

  /// du: the Newton step K du = −R (its Dirichlet increment distributed), or the quasi-Newton one.
  void solve_linear_system(bool newton_step) {
    if (newton_step && !with_tangent) {
      // The state's residual came from a line search: its tangent is assembled now.
      const auto t0 = Clock::now();
      m.cohesive_secant = interface_tangent.secant;
      m.assemble(la, la.u, load, true, assembly, &constraints, &rhs);
      report.assembly_seconds += seconds_since(t0);
    }
    const auto t0 = Clock::now();
    if (newton_step) {
      report.linear_iterations += m.linear->solve(la.K, du, rhs);
      constraints.distribute(du);
      ++report.factorizations;
      S.clear();
      Y.clear();
      rho.clear();
    } else if constexpr (serial_algebra) {
      quasi_newton_direction();
    }
    report.linear_solve_seconds += seconds_since(t0);
  }

  /// du = −H R over the free DOFs: the two-loop recursion around K₀⁻¹.
  void quasi_newton_direction() {
    VectorType q = assembly.residual;
    q.scale(la.free_mask);
    q *= -1.0;
    std::vector<double> alpha_k(S.size());
    for (std::size_t k = S.size(); k-- > 0;) {
      alpha_k[k] = rho[k] * (S[k] * q);
      q.add(-alpha_k[k], Y[k]);
    }
    m.linear->solve_factorized(du, q);
    du.scale(la.free_mask);
    for (std::size_t k = 0; k < S.size(); ++k) {
      const double beta = rho[k] * (Y[k] * du);
      du.add(alpha_k[k] - beta, S[k]);
    }
  }

  /// Backtracking line search on the free residual from `base` along du: the first α in 1, ½, …
  /// (6 tries) that keeps every element valid and reduces |R|, else the valid α with the smallest
  /// |R|. While a Dirichlet increment is pending the residual is no merit function (it starts at
  /// zero and must grow with the imposed displacement): then the largest valid α is taken.
  /// With LineSearch::energy, the test is on s(α) = du · R_free(u + α du) instead, the next α
  /// the secant root of s within [α/10, α/2].
  Step line_search(const VectorType& base, int it, double r, double tol) {
    Step best;
    full_valid = full_tangent = full_secant = false;
    full_mismatch = 0.0;
    const bool energy_search = m.settings.line_search == LineSearch::energy;
    const double s0 = energy_search ? directional(assembly.residual) : 0.0;
    double next_alpha = 1.0;
    for (int search = 0; search < 6; ++search) {
      const double alpha = next_alpha;
      next_alpha = 0.5 * alpha;
      la.u = base;
      la.u.add(alpha, du);
      if (!assemble_trial(alpha, it)) continue;
      const Assembly<VectorType>& a = alpha == 1.0 ? full : trial;
      const double rt = m.free_norm(a.residual, la.free_mask);
      if (rt < best.r) {
        best.r = rt;
        best.alpha = alpha;
      }
      if (energy_search && mismatch <= 0.0 && rt > tol) {
        const double sa = directional(a.residual);
        if (std::abs(sa) <= 0.9 * std::abs(s0)) {
          best.alpha = alpha;
          best.r = rt; // the accepted state's |R|, larger than an earlier trial's possibly
          break;
        }
        if (s0 != sa) next_alpha = std::clamp(alpha * s0 / (s0 - sa), 0.1 * alpha, 0.5 * alpha);
        continue;
      }
      if (mismatch > 0.0 || rt <= (1.0 - 1e-4 * alpha) * r || rt <= tol) {
        best.alpha = alpha;
        break;
      }
    }
    return best;
  }

  /// du · R over the free DOFs.
  [[nodiscard]] double directional(const VectorType& residual) const {
    VectorType masked = residual;
    masked.scale(la.free_mask);
    return du * masked;
  }

  /// The residual of the trial state la.u = base + α du into `full` (α = 1) or `trial`; false
  /// when an element inverts.
  bool assemble_trial(double alpha, int it) {
    const auto t0 = Clock::now();
    if (alpha == 1.0) {
      // The full step, assembled as the next iteration would (its constraints, fault). Under
      // full Newton its tangent too, which the next iteration needs if the step is accepted
      // whole. Under quasi-Newton the residual alone: whether a Newton step follows is known
      // only after the line search, and then the tangent is assembled at the loop's top (on
      // Cook's membrane four of five such tangents went unused: the line search shortened
      // the step, or BFGS took the next one).
      full_mismatch = m.dirichlet_constraints(la, la.u, load, full_constraints);
      // The tangent of the next iteration if this step is good (it is accepted whole).
      full_secant = after_step(interface_tangent, it + 1, true).secant;
      m.cohesive_secant = full_secant;
      const bool poisoned = fault(it + 1);
      m.poison_residual = poisoned;
      full_tangent = !quasi_newton_allowed;
      try {
        m.assemble(la, la.u, load, full_tangent, full, full_tangent ? &full_constraints : nullptr,
                   full_tangent ? &full_rhs : nullptr);
      } catch (const FiniteStrainError&) {
        m.poison_residual = false;
        report.assembly_seconds += seconds_since(t0);
        if (poisoned) throw FiniteStrainError("finite strain: non-finite residual");
        return false;
      }
      m.poison_residual = false;
      full_valid = true;
    } else {
      m.cohesive_secant = interface_tangent.secant;
      try {
        m.assemble(la, la.u, load, false, trial, nullptr, nullptr);
      } catch (const FiniteStrainError&) {
        report.assembly_seconds += seconds_since(t0);
        return false;
      }
    }
    report.assembly_seconds += seconds_since(t0);
    return true;
  }

  /// The BFGS update of the accepted step, when its state's residual is at hand: s = Δu,
  /// y = ΔR over the free DOFs, kept while yᵀ s > 0 (the curvature condition). Then whether a
  /// Newton step comes next.
  void update_quasi_newton(Step step, double r) {
    const Assembly<VectorType>* accepted = step.alpha == 1.0 ? (full_valid ? &full : nullptr) : &trial;
    const bool last_trial_is_best = step.alpha == 1.0 || step.r == m.free_norm(trial.residual, la.free_mask);
    if (accepted != nullptr && last_trial_is_best) {
      VectorType s = du;
      s *= step.alpha;
      s.scale(la.free_mask);
      VectorType y = accepted->residual;
      y -= assembly.residual;
      y.scale(la.free_mask);
      const double ys = y * s;
      if (ys > 0.0) {
        S.push_back(std::move(s));
        Y.push_back(std::move(y));
        rho.push_back(1.0 / ys);
      }
    }
    newton_next = !(step.r <= 0.5 * r) || S.size() >= max_updates;
  }

  /// The accepted state's assembly, when the line search left it at hand (else the loop's top
  /// assembles it).
  void accept_step(Step step, bool newton_step) {
    if (step.alpha == 1.0 && full_valid) {
      std::swap(assembly, full);
      // A step accepted whole that was not good: its tangent is assembled again with the
      // interface tangent chosen now (at the loop's top).
      if (full_tangent && full_secant != interface_tangent.secant) full_tangent = false;
      if (full_tangent) {
        rhs.swap(full_rhs);
        std::swap(constraints, full_constraints);
      } else {
        constraints.clear(); // residual only: constraints are rebuilt if a Newton step follows
        full_mismatch = m.dirichlet_constraints(la, la.u, load, constraints);
      }
      mismatch = full_mismatch;
      with_tangent = full_tangent;
      assembled = true;
    } else if (!newton_step || quasi_newton_allowed) {
      // A shortened step: the last trial is the accepted state's residual when it was the best.
      if (step.alpha < 1.0 && step.r == m.free_norm(trial.residual, la.free_mask)) {
        std::swap(assembly, trial);
        mismatch = m.dirichlet_constraints(la, la.u, load, constraints);
        with_tangent = false; // a Newton step next assembles the tangent at the loop's top
        assembled = true;
      }
    }
  }

  /// Reactions: the residual R on the Dirichlet DOFs is the force the supports put on the body;
  /// the reaction of boundary b (body on support) is −Σ R over the Dirichlet DOFs assigned to b.
  void support_reactions() {
    report.boundary_reactions.resize(m.boundaries.size());
    for (std::size_t b = 0; b < m.boundaries.size(); ++b) report.boundary_reactions[b].surface = m.boundaries[b].surface;
    for (const auto& d : m.dirichlet)
      if (la.owns(d.index))
        report.boundary_reactions[static_cast<std::size_t>(d.boundary)].force[d.component] -= assembly.residual[d.index];
    for (BoundaryReaction& b : report.boundary_reactions) {
      m.sum(std::span<double>(b.force.data(), 3));
      report.support_reaction += b.force;
    }
  }
};

template <class Algebra>
EquilibriumReport FiniteStrainSolver::Impl::newton(Algebra& la, const LoadState& load,
                                                   const typename Algebra::VectorType& start) {
  NewtonIteration<Algebra> iteration(*this, la, load);
  std::optional<std::string> failure;
  try {
    failure = iteration.solve_nonlinear();
  } catch (const FiniteStrainError& e) {
    poison_residual = false;
    failure = e.what();
  } catch (const std::exception& e) { // PETSc/UMFPACK errors (deal.II exceptions are std::exception)
    failure = std::string("linear solver: ") + e.what();
  }
  if (failure) {
    la.u = start;
    iteration.report.converged = false;
    iteration.report.failure = std::move(*failure);
    return iteration.report;
  }
  iteration.commit();
  return iteration.report;
}

// For the two algebras (algebra.hpp); the load-step driver calls them (finite_strain_solver.cpp).
template EquilibriumReport FiniteStrainSolver::Impl::newton<SerialAlgebra>(SerialAlgebra&, const LoadState&,
                                                                 const SerialAlgebra::VectorType&);
template EquilibriumReport FiniteStrainSolver::Impl::newton<DistributedAlgebra>(DistributedAlgebra&, const LoadState&,
                                                                 const DistributedAlgebra::VectorType&);

} // namespace kerf::reference
