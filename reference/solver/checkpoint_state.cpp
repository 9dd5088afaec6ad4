// The solver's state as a vector of numbers, for a checkpoint (FiniteStrainSolver::state and
// set_state): the displacement DOFs, then the cohesive interface's history, then the Newmark
// velocity and acceleration, in the layout finite_strain_solver.hpp states.

#include "reference/solver/finite_strain_impl.hpp"

#include <span>
#include <stdexcept>

namespace kerf::reference {

dealii::Vector<double> FiniteStrainSolver::Impl::gathered(const dealii::PETScWrappers::MPI::Vector& v) const {
  // Every process's locally owned values in place, summed over the processes.
  const DistributedAlgebra& la = *parallel;
  std::vector<dealii::types::global_dof_index> indices(la.owned.begin(), la.owned.end());
  std::vector<double> owned(indices.size());
  v.extract_subvector_to(indices, owned);
  dealii::Vector<double> all(dof.n_dofs());
  for (std::size_t k = 0; k < indices.size(); ++k) all[indices[k]] = owned[k];
  sum(std::span<double>(all.begin(), all.size()));
  return all;
}

std::vector<double> FiniteStrainSolver::state() const {
  const Impl& m = *m_impl;
  std::vector<double> values;
  if (!m.distributed) {
    values.assign(m.serial.u.begin(), m.serial.u.end());
  } else {
    const dealii::Vector<double> u = m.gathered(m.parallel->u);
    values.assign(u.begin(), u.end());
  }
  if (m.cohesive_law) {
    // Each point's history at its pair's place in the whole interface (distributed: each
    // process's pairs in place, summed over the processes).
    const std::size_t nq = m.face_quadrature->size();
    std::vector<double> history(4 * m.cohesive_pair_total * nq, 0.0);
    for (std::size_t p = 0; p < m.cohesive_pairs.size(); ++p)
      for (std::size_t q = 0; q < nq; ++q) {
        const CohesiveState& s = m.cohesive_states[p * nq + q];
        const std::size_t at = 4 * (m.cohesive_pairs[p].index * nq + q);
        history[at] = s.max_opening;
        for (int c = 0; c < 3; ++c) history[at + 1 + static_cast<std::size_t>(c)] = s.previous_opening[c];
      }
    m.sum(history);
    values.insert(values.end(), history.begin(), history.end());
    values.push_back(m.committed_time);
    values.push_back(m.cohesive_viscous_dissipation);
  }
  if (m.dynamics) { // the same on every process
    values.insert(values.end(), m.dynamics->v.begin(), m.dynamics->v.end());
    values.insert(values.end(), m.dynamics->a.begin(), m.dynamics->a.end());
    values.push_back(m.committed_time);
    values.push_back(m.cohesive_trapezoid_work);
    if (m.dynamics->damped) values.push_back(m.dynamics->damping_dissipation);
  }
  return values;
}

void FiniteStrainSolver::set_state(const std::vector<double>& values) {
  Impl& m = *m_impl;
  m.history = 0; // the predictor starts over from the restored state
  const std::size_t n_dofs = m.dof.n_dofs();
  const std::size_t damped = m.dynamics && m.dynamics->damped ? 1 : 0;
  const std::size_t points = m.cohesive_law ? m.cohesive_pair_total * m.face_quadrature->size() : 0;
  const std::size_t expected = n_dofs + (m.cohesive_law ? 4 * points + 2 : 0) + (m.dynamics ? 2 * n_dofs + 2 + damped : 0);
  if (values.size() != expected)
    throw std::invalid_argument("set_state: " + std::to_string(values.size()) + " values, expected " + std::to_string(expected) +
                                " (" + std::to_string(n_dofs) + " DOFs" +
                                (m.cohesive_law ? " + 4 per cohesive point + 2" : std::string()) +
                                (m.dynamics ? " + velocity and acceleration per DOF + 2 (dynamic step)" : std::string()) +
                                (damped ? " + 1 (Kelvin-Voigt damping)" : "") + ")");
  if (m.cohesive_law) {
    const auto history = values.begin() + static_cast<std::ptrdiff_t>(n_dofs);
    const std::size_t nq = m.face_quadrature->size();
    for (std::size_t p = 0; p < m.cohesive_pairs.size(); ++p)
      for (std::size_t q = 0; q < nq; ++q) {
        CohesiveState& s = m.cohesive_states[p * nq + q];
        auto it = history + static_cast<std::ptrdiff_t>(4 * (m.cohesive_pairs[p].index * nq + q));
        s.max_opening = *it++;
        for (int c = 0; c < 3; ++c) s.previous_opening[c] = *it++;
      }
    auto it = history + static_cast<std::ptrdiff_t>(4 * points);
    m.committed_time = *it++;
    m.cohesive_viscous_dissipation = *it++;
  }
  const auto u_end = values.begin() + static_cast<std::ptrdiff_t>(n_dofs);
  if (!m.distributed) {
    std::copy(values.begin(), u_end, m.serial.u.begin());
  } else {
    DistributedAlgebra& la = *m.parallel;
    std::vector<dealii::types::global_dof_index> indices(la.owned.begin(), la.owned.end());
    std::vector<double> owned(indices.size());
    for (std::size_t k = 0; k < indices.size(); ++k) owned[k] = values[indices[k]];
    la.u.set(indices, owned);
    la.u.compress(dealii::VectorOperation::insert);
  }
  if (m.dynamics) {
    const auto tail = values.end() - static_cast<std::ptrdiff_t>(damped);
    auto it = tail - static_cast<std::ptrdiff_t>(2 * n_dofs + 2);
    std::copy(it, it + static_cast<std::ptrdiff_t>(n_dofs), m.dynamics->v.begin());
    std::copy(it + static_cast<std::ptrdiff_t>(n_dofs), it + static_cast<std::ptrdiff_t>(2 * n_dofs), m.dynamics->a.begin());
    m.committed_time = tail[-2];
    m.cohesive_trapezoid_work = tail[-1];
    if (damped) m.dynamics->damping_dissipation = values.back();
    m.dynamics->step = 0.0;
    // u_n = u; the kinetic energy and viscous forces of the restored v (all DOFs on every process).
    if (!m.distributed) {
      (void)m.commit_dynamics(m.serial.u);
    } else {
      dealii::Vector<double> u(n_dofs);
      std::copy(values.begin(), u_end, u.begin());
      (void)m.commit_dynamics(u);
    }
  }
}

} // namespace kerf::reference
