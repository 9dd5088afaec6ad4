// The cohesive interface along the crack path (Reference II; CohesiveInterfaceSpec): the coincident
// face pairs of the split mesh, the opening Δ = x⁺ − x⁻ at the + face's quadrature points, the
// interface's forces and tangent from the bilinear law (cohesive/cohesive_law.hpp), and the commit
// of each point's history after a converged solve, with the interface's energies.

#include "reference/solver/finite_strain_impl.hpp"

#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/full_matrix.h>

#include <Eigen/LU>

#include <cmath>
#include <stdexcept>

namespace kerf::reference {

void FiniteStrainSolver::Impl::build_cohesive(const CohesiveInterfaceSpec& spec, int plus_group, int minus_group) {
  validate(spec.law);
  if (spec.plus_surface == spec.minus_surface)
    throw std::invalid_argument("finite strain solver: cohesive plus and minus surfaces are the same group '" + spec.plus_surface + "'");
  const unsigned n = fe->n_dofs_per_cell();
  cell_components.resize(n);
  for (unsigned i = 0; i < n; ++i) cell_components[i] = fe->system_to_component_index(i).first;

  // Coincident faces are found by their vertex positions, rounded on a grid far finer than any
  // element (the copies made by the crack split, and their refinements, coincide exactly).
  const double grid = 1e-6 * h_min;
  using Key = std::array<long long, 9>;
  auto key_of = [&](const auto& face) {
    std::array<std::array<long long, 3>, 3> v{};
    for (unsigned k = 0; k < 3; ++k)
      for (unsigned c = 0; c < 3; ++c) v[k][c] = std::llround(face->vertex(k)[c] / grid);
    std::sort(v.begin(), v.end());
    Key key{};
    for (unsigned k = 0; k < 3; ++k)
      for (unsigned c = 0; c < 3; ++c) key[3 * k + c] = v[k][c];
    return key;
  };
  std::map<Key, std::pair<dealii::DoFHandler<3>::active_cell_iterator, unsigned>> minus_faces;
  for (const auto& cell : dof.active_cell_iterators())
    for (const unsigned f : cell->face_indices())
      if (cell->face(f)->at_boundary() && in_group(cell->face(f)->boundary_id(), minus_group))
        minus_faces[key_of(cell->face(f))] = {cell, f};

  dealii::FEFaceValues<3> ffv(*mapping, *fe, *face_quadrature,
                              dealii::update_values | dealii::update_quadrature_points | dealii::update_JxW_values |
                                  dealii::update_normal_vectors);
  std::vector<dealii::types::global_dof_index> plus_dofs(n), minus_dofs(n);
  for (const auto& cell : dof.active_cell_iterators())
    for (const unsigned f : cell->face_indices()) {
      if (!cell->face(f)->at_boundary() || !in_group(cell->face(f)->boundary_id(), plus_group)) continue;
      const auto match = minus_faces.find(key_of(cell->face(f)));
      if (match == minus_faces.end())
        throw std::invalid_argument("finite strain solver: a face of cohesive surface '" + spec.plus_surface + "' at (" +
                                    std::to_string(cell->face(f)->center()[0]) + ", " + std::to_string(cell->face(f)->center()[1]) +
                                    ", " + std::to_string(cell->face(f)->center()[2]) + ") m has no coincident face in '" +
                                    spec.minus_surface + "' (was the mesh split along the crack path?)");
      const auto minus_cell = match->second.first;
      ffv.reinit(cell, f);
      CohesivePair pair;
      cell->get_dof_indices(plus_dofs);
      minus_cell->get_dof_indices(minus_dofs);
      pair.dofs = plus_dofs;
      pair.dofs.insert(pair.dofs.end(), minus_dofs.begin(), minus_dofs.end());
      // The + cell's outward normal points into the − side; n points from − into +.
      pair.normal = -Eigen::Vector3d(ffv.normal_vector(0)[0], ffv.normal_vector(0)[1], ffv.normal_vector(0)[2]);
      crack_face_sides[4 * cell->active_cell_index() + f] = pair.normal;
      crack_face_sides[4 * minus_cell->active_cell_index() + match->second.second] = -pair.normal;
      for (unsigned k = 0; k < 3; ++k) pair.vertices[k] = to_eigen(cell->face(f)->vertex(k));
      // The − cell's unit coordinates of each quadrature point (affine P1 geometry: ξ = A⁻¹ (x − v₀),
      // the unit tetrahedron's vertices 1, 2, 3 being e_x, e_y, e_z).
      Eigen::Matrix3d A;
      const Eigen::Vector3d v0 = to_eigen(minus_cell->vertex(0));
      for (unsigned k = 1; k < 4; ++k) A.col(k - 1) = to_eigen(minus_cell->vertex(k)) - v0;
      const Eigen::Matrix3d A_inv = A.inverse();
      for (unsigned q = 0; q < ffv.n_quadrature_points; ++q) {
        const Eigen::Vector3d x = to_eigen(ffv.quadrature_point(q));
        const Eigen::Vector3d xi = A_inv * (x - v0);
        const dealii::Point<3> unit(xi[0], xi[1], xi[2]);
        std::vector<double> plus(n), minus(n);
        for (unsigned i = 0; i < n; ++i) {
          plus[i] = ffv.shape_value_component(i, q, cell_components[i]);
          minus[i] = fe->shape_value_component(i, unit, cell_components[i]);
        }
        pair.plus_values.push_back(std::move(plus));
        pair.minus_values.push_back(std::move(minus));
        pair.weights.push_back(ffv.JxW(q));
        pair.points.push_back(x);
      }
      cohesive_pairs.push_back(std::move(pair));
    }
  if (cohesive_pairs.empty())
    throw std::invalid_argument("finite strain solver: cohesive surface '" + spec.plus_surface + "' has no boundary faces");
  if (cohesive_pairs.size() != minus_faces.size())
    throw std::invalid_argument("finite strain solver: cohesive surfaces '" + spec.plus_surface + "' and '" + spec.minus_surface +
                                "' have different face counts (" + std::to_string(cohesive_pairs.size()) + " and " +
                                std::to_string(minus_faces.size()) + ")");
  cohesive_law = spec.law;
  cohesive_states.assign(cohesive_pairs.size() * face_quadrature->size(), CohesiveState{});
}

template <class VectorType>
Eigen::Vector3d FiniteStrainSolver::Impl::cohesive_opening(const CohesivePair& pair, std::size_t q,
                                                          const VectorType& state) const {
  // Δ = x⁺ − x⁻ = u⁺ − u⁻ at a point where the two faces coincide in the reference configuration.
  const std::size_t n = cell_components.size();
  Eigen::Vector3d opening = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    opening[cell_components[i]] += pair.plus_values[q][i] * state(pair.dofs[i]);
    opening[cell_components[i]] -= pair.minus_values[q][i] * state(pair.dofs[n + i]);
  }
  return opening;
}

template <class VectorType, class MatrixType>
void FiniteStrainSolver::Impl::assemble_cohesive(const VectorType& state, const LoadState& load, bool with_matrix,
                                                 const dealii::AffineConstraints<double>* constraints, MatrixType& K,
                                                 VectorType* rhs, VectorType& f_int) const {
  // Interface potential Π = ∫ φ(Δ) dA with Δ = Σ N⁺ u⁺ − Σ N⁻ u⁻: f_int,a = ∫ s_a N_a t dA and
  // K_ab = ∫ s_a N_a (∂t/∂Δ) s_b N_b dA, s = +1 on the + side and −1 on the − side.
  const std::size_t n = cell_components.size(), nq = face_quadrature->size();
  const double dt = load.time - committed_time;
  dealii::FullMatrix<double> local_K(2 * n, 2 * n);
  dealii::Vector<double> local_rhs(2 * n), local_f(2 * n);
  std::vector<double> a(2 * n);
  std::vector<unsigned> comp(2 * n);
  for (std::size_t i = 0; i < 2 * n; ++i) comp[i] = cell_components[i % n];
  for (std::size_t p = 0; p < cohesive_pairs.size(); ++p) {
    const CohesivePair& pair = cohesive_pairs[p];
    local_K = 0.0;
    local_rhs = 0.0;
    local_f = 0.0;
    for (std::size_t q = 0; q < nq; ++q) {
      const CohesiveResponse r =
          cohesive_response(*cohesive_law, cohesive_states[p * nq + q], cohesive_opening(pair, q, state), pair.normal, dt,
                            cohesive_secant);
      const double w = pair.weights[q];
      for (std::size_t i = 0; i < n; ++i) {
        a[i] = pair.plus_values[q][i];
        a[n + i] = -pair.minus_values[q][i];
      }
      for (std::size_t i = 0; i < 2 * n; ++i) {
        if (a[i] == 0.0) continue;
        const double f = a[i] * r.traction[comp[i]] * w;
        local_f(static_cast<unsigned>(i)) += f;
        local_rhs(static_cast<unsigned>(i)) -= f;
        if (with_matrix)
          for (std::size_t j = 0; j < 2 * n; ++j)
            local_K(static_cast<unsigned>(i), static_cast<unsigned>(j)) += a[i] * a[j] * r.tangent(comp[i], comp[j]) * w;
      }
    }
    f_int.add(pair.dofs, local_f);
    if (with_matrix) constraints->distribute_local_to_global(local_K, local_rhs, pair.dofs, K, *rhs);
  }
}

CohesiveSummary FiniteStrainSolver::Impl::commit_cohesive(const LoadState& load) {
  const std::size_t nq = face_quadrature->size();
  const double dt = load.time - committed_time;
  const double d0 = cohesive_law->peak_opening();
  CohesiveSummary summary;
  for (std::size_t p = 0; p < cohesive_pairs.size(); ++p)
    for (std::size_t q = 0; q < nq; ++q) {
      CohesiveState& state = cohesive_states[p * nq + q];
      const Eigen::Vector3d opening = cohesive_opening(cohesive_pairs[p], q, serial.u);
      const CohesiveResponse r = cohesive_response(*cohesive_law, state, opening, cohesive_pairs[p].normal, dt);
      const double w = cohesive_pairs[p].weights[q];
      if (dt > 0.0) cohesive_viscous_dissipation += r.viscous_power_density * dt * w;
      if (dynamics) {
        // ½ (t_n + t_{n+1})·(Δ_{n+1} − Δ_n) without the viscous part (dt = 0): t_n is the traction at
        // the last converged opening Δ_n with the damage κ_n reached there.
        const Eigen::Vector3d& n = cohesive_pairs[p].normal;
        const CohesiveResponse before = cohesive_response(*cohesive_law, state, state.previous_opening, n, 0.0);
        const CohesiveResponse after = cohesive_law->viscosity > 0.0 ? cohesive_response(*cohesive_law, state, opening, n, 0.0) : r;
        const double trapezoid = 0.5 * (before.traction + after.traction).dot(opening - state.previous_opening) * w;
        cohesive_trapezoid_work += trapezoid;
        // The step's kinks error: the trapezoid work minus Δ(φ_e + φ_d) at this point.
        summary.step_time_integration_error +=
            trapezoid - (after.stored_energy + after.dissipated_energy - before.stored_energy - before.dissipated_energy) * w;
        summary.step_dissipation += (after.dissipated_energy - before.dissipated_energy) * w;
      }
      state.max_opening = r.damage_opening;
      state.previous_opening = opening;
      if (r.failed) summary.failed_area += w;
      if (r.damage_opening > d0) summary.damaged_area += w;
      summary.stored_energy += r.stored_energy * w;
      summary.dissipated_energy += r.dissipated_energy * w;
      summary.max_damage = std::max(summary.max_damage, r.damage);
    }
  committed_time = load.time;
  summary.viscous_dissipation = cohesive_viscous_dissipation;
  summary.trapezoid_work = cohesive_trapezoid_work;
  return summary;
}

// For the two algebras (algebra.hpp); the assembly calls them (assemble_system.cpp).
template void FiniteStrainSolver::Impl::assemble_cohesive(const SerialAlgebra::VectorType&, const LoadState&, bool,
                                                          const dealii::AffineConstraints<double>*,
                                                          SerialAlgebra::MatrixType&, SerialAlgebra::VectorType*,
                                                          SerialAlgebra::VectorType&) const;
template void FiniteStrainSolver::Impl::assemble_cohesive(const DistributedAlgebra::VectorType&, const LoadState&, bool,
                                                          const dealii::AffineConstraints<double>*,
                                                          DistributedAlgebra::MatrixType&, DistributedAlgebra::VectorType*,
                                                          DistributedAlgebra::VectorType&) const;

} // namespace kerf::reference
