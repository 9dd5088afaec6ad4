// The dynamic step (SolverSettings::dynamic): implicit Newmark average acceleration (β = 1/4,
// γ = 1/2) with the consistent mass M_ab = ∫ ρ N_a N_b dV. This file builds the cells' mass
// matrices, commits a converged step (a_{n+1}, v_{n+1}, the kinetic energy) and computes the
// Kelvin–Voigt viscous nodal forces for the dissipation's trapezoid rule; the inertia and viscous
// terms of Newton's residual and tangent are assembled with the cells (assemble_system.cpp).

#include "reference/solver/finite_strain_impl.hpp"

#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_values.h>

#include <algorithm>
#include <span>

namespace kerf::reference {

void FiniteStrainSolver::Impl::build_dynamics() {
  Dynamics d;
  const dealii::FE_SimplexP<3> scalar(static_cast<unsigned>(settings.degree));
  d.nodes = scalar.n_dofs_per_cell();
  const unsigned n = fe->n_dofs_per_cell();
  d.node_of_dof.resize(n);
  for (unsigned i = 0; i < n; ++i) d.node_of_dof[i] = fe->system_to_component_index(i).second;
  // m_ij = ∫ ρ N_i N_j dV with the mass quadrature (degree + 1 points per direction: exact for
  // N_i N_j of P1; of P2 (degree 4) QGaussSimplex(3) is exact to degree 5).
  dealii::FEValues<3> fv(*mapping, scalar, *mass_quadrature, dealii::update_values | dealii::update_JxW_values);
  // This process's cells (distributed: the others' are assembled there).
  const dealii::Triangulation<3>& cells = dof.get_triangulation();
  d.cell_mass.resize(cells.n_active_cells());
  for (const auto& cell : cells.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    fv.reinit(cell);
    const double rho = densities[cell->material_id()];
    std::vector<double> m(static_cast<std::size_t>(d.nodes) * d.nodes, 0.0);
    for (unsigned q = 0; q < fv.n_quadrature_points; ++q)
      for (unsigned i = 0; i < d.nodes; ++i)
        for (unsigned j = 0; j < d.nodes; ++j) m[i * d.nodes + j] += rho * fv.shape_value(i, q) * fv.shape_value(j, q) * fv.JxW(q);
    d.cell_mass[cell->active_cell_index()] = std::move(m);
  }
  d.u.reinit(dof.n_dofs());
  d.v.reinit(dof.n_dofs());
  d.a.reinit(dof.n_dofs());
  d.damped = std::any_of(damping.begin(), damping.end(), [](const KelvinVoigtDamping& k) { return k.retardation_time > 0.0; });
  if (d.damped) d.viscous_force.reinit(dof.n_dofs());
  dynamics = std::move(d);
}

double FiniteStrainSolver::Impl::commit_dynamics(const dealii::Vector<double>& u) {
  // Every process commits all DOFs (u is whole on every process: gathered when distributed), so
  // that u_n, v_n and a_n are the same everywhere; the cell sums (viscous forces, kinetic energy)
  // are this process's cells', summed over the processes.
  Dynamics& d = *dynamics;
  if (d.step > 0.0)
    for (dealii::types::global_dof_index i = 0; i < u.size(); ++i) {
      // a_{n+1} (Newmark β = 1/4), then v_{n+1} = v_n + h/2 (a_n + a_{n+1}) (γ = 1/2)
      const double a_next = newmark_acceleration(i, u[i]);
      d.v[i] += 0.5 * d.step * (d.a[i] + a_next);
      d.a[i] = a_next;
    }
  if (d.damped) {
    // The viscous forces at (u_{n+1}, v_{n+1}); a step (h > 0) dissipates their trapezoid work
    // ½ (f_v,n + f_v,n+1)·(u_{n+1} − u_n), the term the Newmark energy identity books for them.
    dealii::Vector<double> f_next(u.size());
    assemble_viscous_force(u, d.v, f_next);
    sum(std::span<double>(f_next.begin(), f_next.size()));
    if (d.step > 0.0)
      for (dealii::types::global_dof_index i = 0; i < u.size(); ++i)
        d.damping_dissipation += 0.5 * (d.viscous_force[i] + f_next[i]) * (u[i] - d.u[i]);
    d.viscous_force = std::move(f_next);
  }
  d.u = u;
  // ½ vᵀ M v, cell by cell (M_ab = m_ij δ(c_a, c_b)).
  const unsigned n = fe->n_dofs_per_cell();
  std::vector<dealii::types::global_dof_index> local(n);
  double kinetic = 0.0;
  for (const auto& cell : dof.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    cell->get_dof_indices(local);
    const std::vector<double>& m = d.cell_mass[cell->active_cell_index()];
    for (unsigned i = 0; i < n; ++i)
      for (unsigned j = 0; j < n; ++j)
        if (fe->system_to_component_index(i).first == fe->system_to_component_index(j).first)
          kinetic += 0.5 * d.v[local[i]] * m[d.node_of_dof[i] * d.nodes + d.node_of_dof[j]] * d.v[local[j]];
  }
  d.kinetic_energy = sum(kinetic);
  return d.kinetic_energy;
}

void FiniteStrainSolver::Impl::assemble_viscous_force(const dealii::Vector<double>& u, const dealii::Vector<double>& v,
                                                      dealii::Vector<double>& out) const {
  out = 0.0;
  const unsigned n = fe->n_dofs_per_cell();
  dealii::FEValues<3> fv(*mapping, *fe, *cell_quadrature, dealii::update_gradients | dealii::update_JxW_values);
  const dealii::FEValuesExtractors::Vector disp(0);
  std::vector<dealii::Tensor<2, 3>> grads(cell_quadrature->size()), rates(cell_quadrature->size());
  std::vector<dealii::types::global_dof_index> local(n);
  dealii::Vector<double> cell_f(n);
  for (const auto& cell : dof.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue; // distributed: another process's cell
    const KelvinVoigtDamping& kv = damping[cell->material_id()];
    if (kv.retardation_time == 0.0) continue;
    fv.reinit(cell);
    cell->get_dof_indices(local);
    fv[disp].get_function_gradients(u, grads);
    fv[disp].get_function_gradients(v, rates);
    cell_f = 0.0;
    for (unsigned q = 0; q < fv.n_quadrature_points; ++q) {
      const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + to_eigen(grads[q]);
      const Eigen::Matrix3d P_v = kelvin_voigt_stress(kv, F, to_eigen(rates[q]), 0.0).first_piola;
      for (unsigned i = 0; i < n; ++i) {
        const unsigned c = fe->system_to_component_index(i).first;
        const auto g = fv.shape_grad_component(i, q, c);
        cell_f(i) += P_v.row(c).dot(Eigen::Vector3d(g[0], g[1], g[2])) * fv.JxW(q);
      }
    }
    out.add(local, cell_f);
  }
}

} // namespace kerf::reference
