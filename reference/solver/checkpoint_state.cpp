// The solver's state as a vector of numbers, for a checkpoint (FiniteStrainSolver::state and
// set_state): the displacement DOFs, then the cohesive interface's history, then the Newmark
// velocity and acceleration, in the layout finite_strain_solver.hpp states.

#include "reference/solver/finite_strain_impl.hpp"

#include <stdexcept>

namespace kerf::reference {

std::vector<double> FiniteStrainSolver::state() const {
  const Impl& m = *m_impl;
  std::vector<double> values;
  if (!m.distributed) {
    values.assign(m.serial.u.begin(), m.serial.u.end());
  } else {
    // Every process's locally owned values in place, summed over the processes.
    const DistributedAlgebra& la = *m.parallel;
    std::vector<dealii::types::global_dof_index> indices(la.owned.begin(), la.owned.end());
    std::vector<double> owned(indices.size());
    la.u.extract_subvector_to(indices, owned);
    values.assign(m.dof.n_dofs(), 0.0);
    for (std::size_t k = 0; k < indices.size(); ++k) values[indices[k]] = owned[k];
    m.sum(values);
  }
  if (m.cohesive_law) { // serial only (build refuses a distributed cohesive interface)
    for (const CohesiveState& s : m.cohesive_states)
      values.insert(values.end(), {s.max_opening, s.previous_opening[0], s.previous_opening[1], s.previous_opening[2]});
    values.push_back(m.committed_time);
    values.push_back(m.cohesive_viscous_dissipation);
  }
  if (m.dynamics) { // serial only (build refuses a distributed dynamic step)
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
  const std::size_t expected = n_dofs + (m.cohesive_law ? 4 * m.cohesive_states.size() + 2 : 0) +
                               (m.dynamics ? 2 * n_dofs + 2 + damped : 0);
  if (values.size() != expected)
    throw std::invalid_argument("set_state: " + std::to_string(values.size()) + " values, expected " + std::to_string(expected) +
                                " (" + std::to_string(n_dofs) + " DOFs" +
                                (m.cohesive_law ? " + 4 per cohesive point + 2" : std::string()) +
                                (m.dynamics ? " + velocity and acceleration per DOF + 2 (dynamic step)" : std::string()) +
                                (damped ? " + 1 (Kelvin-Voigt damping)" : "") + ")");
  if (m.cohesive_law) {
    auto it = values.begin() + static_cast<std::ptrdiff_t>(n_dofs);
    for (CohesiveState& s : m.cohesive_states) {
      s.max_opening = *it++;
      for (int c = 0; c < 3; ++c) s.previous_opening[c] = *it++;
    }
    m.committed_time = *it++;
    m.cohesive_viscous_dissipation = *it++;
  }
  if (!m.distributed) {
    std::copy(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(n_dofs), m.serial.u.begin());
    if (m.dynamics) {
      const auto tail = values.end() - static_cast<std::ptrdiff_t>(damped);
      auto it = tail - static_cast<std::ptrdiff_t>(2 * n_dofs + 2);
      std::copy(it, it + static_cast<std::ptrdiff_t>(n_dofs), m.dynamics->v.begin());
      std::copy(it + static_cast<std::ptrdiff_t>(n_dofs), it + static_cast<std::ptrdiff_t>(2 * n_dofs), m.dynamics->a.begin());
      m.committed_time = tail[-2];
      m.cohesive_trapezoid_work = tail[-1];
      if (damped) m.dynamics->damping_dissipation = values.back();
      m.dynamics->step = 0.0;
      (void)m.commit_dynamics(m.serial.u); // u_n = u; the kinetic energy and viscous forces of the restored v
    }
    return;
  }
  DistributedAlgebra& la = *m.parallel;
  std::vector<dealii::types::global_dof_index> indices(la.owned.begin(), la.owned.end());
  std::vector<double> owned(indices.size());
  for (std::size_t k = 0; k < indices.size(); ++k) owned[k] = values[indices[k]];
  la.u.set(indices, owned);
  la.u.compress(dealii::VectorOperation::insert);
}

} // namespace kerf::reference
