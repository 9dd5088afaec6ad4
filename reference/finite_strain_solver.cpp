// FiniteStrainSolver (finite_strain_solver.hpp): the public class and the load-step driver. A load
// step is one `solve`: the predictor's start (the last two converged states extrapolated along the
// trajectory), then Newton–Raphson to equilibrium. The parts of the solver are in reference/solver/
// (finite_strain_impl.hpp lists them, one idea per file, in the order of deal.II's step-44).

#include "reference/finite_strain_solver.hpp"

#include "reference/solver/finite_strain_impl.hpp"

#include <deal.II/fe/fe_values.h>

#include <Eigen/LU>

#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>

namespace kerf::reference {

FiniteStrainSolver::FiniteStrainSolver(const FiniteStrainProblem& problem, const SolverSettings& settings)
    : m_impl(std::make_unique<Impl>()) {
  m_impl->settings = settings;
  m_impl->build(problem);
}

FiniteStrainSolver::~FiniteStrainSolver() = default;

EquilibriumReport FiniteStrainSolver::solve(const LoadState& load) {
  return m_impl->with_algebra([&](auto& la) { return m_impl->solve(la, load); });
}

double FiniteStrainSolver::Impl::extrapolation_factor(const LoadState& load) const {
  if (history < 2) return 0.0;
  const LoadState& l1 = load_last;
  const LoadState& l0 = load_before;
  // The load's parameter along the trajectory: the tool's travel, else the load factor; the time
  // when only time moves the problem (inertia, a viscous interface). A dwell (same load) keeps u₁.
  const bool same_load = load.load_factor == l1.load_factor && load.tool_position == l1.tool_position;
  const bool rate_dependent = dynamics.has_value() || (cohesive_law && cohesive_law->viscosity > 0.0);
  double s = 0.0;
  const Eigen::Vector3d d = l1.tool_position - l0.tool_position;
  if (same_load && !rate_dependent) {
    s = 0.0;
  } else if (d.squaredNorm() > 0.0) {
    s = (load.tool_position - l1.tool_position).dot(d) / d.squaredNorm();
  } else if (l1.load_factor != l0.load_factor) {
    s = (load.load_factor - l1.load_factor) / (l1.load_factor - l0.load_factor);
  } else if (rate_dependent && l1.time != l0.time) {
    s = (load.time - l1.time) / (l1.time - l0.time);
  }
  // Forward only, and at most twice the last increment: a start guess, never a leap.
  return std::isfinite(s) ? std::clamp(s, 0.0, 2.0) : 0.0;
}

template <class Algebra> EquilibriumReport FiniteStrainSolver::Impl::solve(Algebra& la, const LoadState& load) {
  using VectorType = typename Algebra::VectorType;
  Impl& m = *this;
  const VectorType start = la.u;
  // Dynamic step: h from the last converged time (0: a quasi-static solve, no inertia).
  if (m.dynamics) m.dynamics->step = std::max(0.0, load.time - m.committed_time);
  m.fault_fired = false;
  // The predictor: the last two converged states extrapolated linearly along the trajectory,
  // u = u₁ + s (u₁ − u₀). Only Newton's start changes; the equilibrium it converges to is the same
  // (to the Newton tolerance). Should Newton fail from there, it starts again from u₁.
  const double s = m.settings.extrapolate_initial_guess ? m.extrapolation_factor(load) : 0.0;
  EquilibriumReport report;
  if (s > 0.0) {
    la.u *= 1.0 + s;
    la.u.add(-s, la.u_previous);
    report = m.newton(la, load, start);
    if (!report.converged && !m.fault_fired) {
      EquilibriumReport again = m.newton(la, load, start);
      again.newton_iterations += report.newton_iterations;
      again.assembly_seconds += report.assembly_seconds;
      again.linear_solve_seconds += report.linear_solve_seconds;
      again.linear_iterations += report.linear_iterations;
      again.factorizations += report.factorizations;
      report = std::move(again);
    }
  } else {
    report = m.newton(la, load, start);
  }
  if (!report.converged) return report;
  la.u_previous = start;
  m.load_before = m.load_last;
  m.load_last = load;
  m.history = std::min(2, m.history + 1);
  return report;
}

std::size_t FiniteStrainSolver::dof_count() const { return m_impl->dof.n_dofs(); }
std::size_t FiniteStrainSolver::cell_count() const { return m_impl->tria.n_active_cells(); }
std::string FiniteStrainSolver::linear_solver_name() const { return m_impl->linear->name(); }
std::string FiniteStrainSolver::linear_solver_reason() const { return m_impl->linear->choice_reason(); }
double FiniteStrainSolver::contact_penalty() const { return m_impl->penalty; }
std::size_t FiniteStrainSolver::cohesive_point_count() const {
  return m_impl->cohesive_law ? m_impl->cohesive_pair_total * m_impl->face_quadrature->size() : 0;
}
double FiniteStrainSolver::crack_extent(const Eigen::Vector3d& direction) const {
  const Impl& m = *m_impl;
  if (!m.cohesive_law) return 0.0;
  const std::size_t nq = m.face_quadrature->size();
  const double df = m.cohesive_law->failure_opening();
  double first = std::numeric_limits<double>::infinity(), reach = -std::numeric_limits<double>::infinity();
  for (std::size_t p = 0; p < m.cohesive_pairs.size(); ++p) {
    for (const Eigen::Vector3d& v : m.cohesive_pairs[p].vertices) first = std::min(first, v.dot(direction));
    for (std::size_t q = 0; q < nq; ++q)
      if (m.cohesive_states[p * nq + q].max_opening >= df) reach = std::max(reach, m.cohesive_pairs[p].points[q].dot(direction));
  }
  // Distributed: over every process's pairs.
  first = m.min(first);
  reach = m.max(reach);
  return reach > first ? reach - first : 0.0;
}
double FiniteStrainSolver::max_displacement() const {
  double best = 0.0;
  const std::vector<double> u = state();
  for (std::size_t k = 0; k + 2 < u.size(); k += 3)
    best = std::max(best, std::sqrt(u[k] * u[k] + u[k + 1] * u[k + 1] + u[k + 2] * u[k + 2]));
  return best;
}

double FiniteStrainSolver::kinetic_energy() const { return m_impl->dynamics ? m_impl->dynamics->kinetic_energy : 0.0; }
double FiniteStrainSolver::damping_dissipation() const {
  return m_impl->dynamics ? m_impl->dynamics->damping_dissipation : 0.0;
}

SolverTimings FiniteStrainSolver::timings() const {
  const Impl& m = *m_impl;
  SolverTimings t = m.timings;
  if (m.parallel) t.communication_seconds += m.parallel->exchange_seconds;
  const TangentSolver::Timings linear = m.linear->timings();
  t.factorization_seconds = linear.setup_seconds;
  t.solve_seconds = linear.solve_seconds;
  return t;
}

int FiniteStrainSolver::process_count() const { return m_impl->distributed ? m_impl->process_count : 1; }

Eigen::Vector3d FiniteStrainSolver::displacement_at(const Eigen::Vector3d& X) const {
  const Impl& m = *m_impl;
  std::optional<Eigen::Vector3d> found;
  m.with_algebra([&](const auto& la) {
    const auto& u = la.ghosted(la.u);
    // The cell whose barycentric coordinates of X are all >= −tol (straight-sided tetrahedra).
    for (const auto& cell : m.dof.active_cell_iterators()) {
      if (!cell->is_locally_owned()) continue;
      Eigen::Matrix3d A;
      const Eigen::Vector3d v0 = to_eigen(cell->vertex(0));
      for (unsigned k = 1; k < 4; ++k) A.col(k - 1) = to_eigen(cell->vertex(k)) - v0;
      const Eigen::Vector3d xi = A.lu().solve(X - v0);
      const double tol = 1e-10;
      if (xi.minCoeff() < -tol || xi.sum() > 1.0 + tol) continue;
      // The unit tetrahedron's vertices 1, 2, 3 are e_x, e_y, e_z: the unit point is ξ itself.
      const dealii::Quadrature<3> point(dealii::Point<3>(xi[0], xi[1], xi[2]));
      dealii::FEValues<3> fv(*m.mapping, *m.fe, point, dealii::update_values);
      fv.reinit(cell);
      std::vector<dealii::Vector<double>> value(1, dealii::Vector<double>(3));
      fv.get_function_values(u, value);
      found = Eigen::Vector3d(value[0][0], value[0][1], value[0][2]);
      return;
    }
  });
  // Distributed: the lowest rank whose cells hold X answers.
  const double owner = -m.max(found ? -static_cast<double>(m.rank) : -static_cast<double>(INT_MAX));
  if (owner == static_cast<double>(INT_MAX))
    throw std::out_of_range("displacement_at: the point lies outside the mesh");
  Eigen::Vector3d value = found && owner == static_cast<double>(m.rank) ? *found : Eigen::Vector3d::Zero();
  m.sum(std::span<double>(value.data(), 3));
  return value;
}

std::vector<Eigen::Matrix3d> FiniteStrainSolver::quadrature_cauchy_stresses() const {
  const Impl& m = *m_impl;
  std::vector<Eigen::Matrix3d> out;
  dealii::FEValues<3> fv(*m.mapping, *m.fe, *m.cell_quadrature, dealii::update_gradients);
  std::vector<dealii::Tensor<2, 3>> grads(m.cell_quadrature->size());
  m.with_algebra([&](const auto& la) {
    const auto& u = la.ghosted(la.u);
    for (const auto& cell : m.dof.active_cell_iterators()) {
      if (!cell->is_locally_owned()) continue;
      fv.reinit(cell);
      fv[dealii::FEValuesExtractors::Vector(0)].get_function_gradients(u, grads);
      for (const auto& g : grads) {
        const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + to_eigen(g);
        out.push_back(cauchy_stress(F, m.laws[cell->material_id()]->stress_and_tangent(F).first_piola));
      }
    }
  });
  return out;
}

double FiniteStrainSolver::strain_energy() const {
  const Impl& m = *m_impl;
  return m.with_algebra([&](const auto& la) {
    const auto& u = la.ghosted(la.u);
    dealii::FEValues<3> fv(*m.mapping, *m.fe, *m.cell_quadrature, dealii::update_gradients | dealii::update_JxW_values);
    std::vector<dealii::Tensor<2, 3>> grads(m.cell_quadrature->size());
    double energy = 0.0;
    for (const auto& cell : m.dof.active_cell_iterators()) {
      if (!cell->is_locally_owned()) continue;
      fv.reinit(cell);
      fv[dealii::FEValuesExtractors::Vector(0)].get_function_gradients(u, grads);
      for (unsigned q = 0; q < fv.n_quadrature_points; ++q)
        energy += m.laws[cell->material_id()]->energy(Eigen::Matrix3d::Identity() + to_eigen(grads[q])) * fv.JxW(q);
    }
    return m.sum(energy);
  });
}

} // namespace kerf::reference
