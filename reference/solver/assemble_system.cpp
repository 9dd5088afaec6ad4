// The assembly of one Newton iteration (step-44's assemble_system), total Lagrangian: the internal
// forces f_int,a = ∫ P : (e_c ⊗ Grad N_a) dV of the hyperelastic cells and their tangent
// K_ab = ∫ (e_ca ⊗ Grad N_a) : 𝔸 : (e_cb ⊗ Grad N_b) dV (𝔸 = ∂P/∂F), the inertia M a(u) of the
// Newmark step and the Kelvin–Voigt viscous stress (newmark_dynamics.cpp), the dead-load
// tractions and the tool's frictionless penalty contact on the boundary faces; then the blade
// edge pass (blade_edge_pass.cpp), the elastic foundations (grasp_foundation.cpp) and the cohesive
// interface (cohesive_interface.cpp). The residual is R = f_int − f_ext (f_ext including the
// contact and foundation forces).

#include "reference/solver/finite_strain_impl.hpp"
#include "reference/solver/cell_matrix_scatter.hpp"
#include "reference/solver/cell_tangent.hpp"

#include "reference/material/finite_strain_error.hpp"

#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/full_matrix.h>

#include <petscmat.h>
#include <petscvec.h>

#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace kerf::reference {

namespace {

/// A cell's matrix and right-hand side into the distributed system. A cell without a constrained
/// DOF (nearly every cell) goes in as one n × n block, one MatSetValues and one VecSetValues,
/// where deal.II's distribute_local_to_global calls MatSetValues once per row; a cell with one
/// goes through distribute_local_to_global, which eliminates the constrained rows and columns.
/// The entries and the order in which each one is summed are the same either way.
template <class MatrixType, class VectorType>
void add_cell_to_distributed(const dealii::FullMatrix<double>& cell_K, const dealii::Vector<double>& cell_rhs,
                             const std::vector<dealii::types::global_dof_index>& dofs,
                             const dealii::AffineConstraints<double>& constraints, MatrixType& K, VectorType& rhs) {
  const std::size_t n = dofs.size();
  bool constrained = false;
  for (const auto i : dofs) constrained = constrained || constraints.is_constrained(i);
  if (constrained) {
    constraints.distribute_local_to_global(cell_K, cell_rhs, dofs, K, rhs);
    return;
  }
  // PETSc's indices; FullMatrix keeps its rows one after another, as MatSetValues reads them.
  std::array<PetscInt, 30> index{}; // a P2 tetrahedron's 30 DOFs at most
  if (n > index.size()) throw std::logic_error("finite strain: more DOFs per cell than a quadratic tetrahedron's");
  for (std::size_t i = 0; i < n; ++i) index[i] = static_cast<PetscInt>(dofs[i]);
  const auto count = static_cast<PetscInt>(n);
  PetscErrorCode error = MatSetValues(K.petsc_matrix(), count, index.data(), count, index.data(), &cell_K(0, 0), ADD_VALUES);
  if (error == 0) error = VecSetValues(rhs, count, index.data(), cell_rhs.data(), ADD_VALUES);
  if (error != 0) throw std::runtime_error("finite strain: PETSc could not add a cell's entries (error " + std::to_string(error) + ")");
}


using Impl = FiniteStrainSolver::Impl;
using Dofs = std::vector<dealii::types::global_dof_index>;

/// The Newmark step's inertia on cell `c` (β = 1/4): f_a += Σ_b M_ab a_b(u),
/// a_b = 4/h² (u_b − u_n,b) − 4/h v_n,b − a_n,b, and ∂f_a/∂u_b = 4/h² M_ab, with
/// M_ab = m_ij δ(c_a, c_b), m the cell's scalar mass matrix.
void add_cell_inertia(const Impl& s, std::size_t c, const Dofs& local, const std::vector<unsigned>& comp,
                      const dealii::Vector<double>& state, bool with_matrix, dealii::Vector<double>& cell_int,
                      dealii::FullMatrix<double>& cell_K) {
  const unsigned n = static_cast<unsigned>(local.size());
  const Impl::Dynamics& d = *s.dynamics;
  const std::vector<double>& m = d.cell_mass[c];
  const double h2 = 4.0 / (d.step * d.step);
  for (unsigned i = 0; i < n; ++i)
    for (unsigned j = 0; j < n; ++j) {
      if (comp[i] != comp[j]) continue;
      const double Mij = m[d.node_of_dof[i] * d.nodes + d.node_of_dof[j]];
      cell_int(i) += Mij * s.newmark_acceleration(local[j], state(local[j]));
      if (with_matrix) cell_K(i, j) += h2 * Mij;
    }
}

/// The stress of cell `c_index` at its quadrature points: f_int,a = ∫ P : (e_c ⊗ Grad N_a) dV
/// into `cell_int` and, with the matrix, the tangent's blocks into `tangent`. `damping`: the
/// Kelvin–Voigt law of a dynamic step's damped material (its velocities in `velocity`), or null.
/// `gradN`: n entries of scratch.
void add_cell_stress(const Impl& s, std::size_t c_index, const HyperelasticLaw& law, const KelvinVoigtDamping* damping,
                     const std::vector<double>& cell_u, const std::vector<double>& velocity,
                     const std::vector<unsigned>& comp, bool with_matrix, std::vector<Eigen::Vector3d>& gradN,
                     CellTangentBlocks& tangent, dealii::Vector<double>& cell_int) {
  const unsigned n = static_cast<unsigned>(cell_u.size());
  for (unsigned q = 0; q < s.geometry.points; ++q) {
    for (unsigned i = 0; i < n; ++i) gradN[i] = Eigen::Map<const Eigen::Vector3d>(s.geometry.gradient(c_index, q, s.geometry.node_of_dof[i]));
    // F = I + Grad u = I + Σ_a u_a e_c ⊗ Grad N_a (total Lagrangian: gradients with respect to
    // the reference configuration)
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    for (unsigned i = 0; i < n; ++i) F.row(comp[i]) += cell_u[i] * gradN[i].transpose();
    const double JxW = s.geometry.JxW[c_index * s.geometry.points + q];
    // The residual-only assemblies of the line search need P = F S alone (the same bits).
    StressTangent st;
    if (with_matrix) {
      Eigen::Matrix3d S;
      Tensor4 C4;
      law.second_piola_and_tangent(F, S, C4);
      st = first_piola_and_tangent(F, S, C4);
    } else {
      st.first_piola = F * law.second_piola(F);
    }
    if (damping) {
      // Ḟ = Grad v = Σ_a v_a e_c ⊗ Grad N_a; P += P_v(F, Ḟ), 𝔸 += ∂P_v/∂F with ∂Ḟ/∂F = γ/(βh) = 2/h.
      Eigen::Matrix3d F_rate = Eigen::Matrix3d::Zero();
      for (unsigned i = 0; i < n; ++i) F_rate.row(comp[i]) += velocity[i] * gradN[i].transpose();
      const StressTangent sv = kelvin_voigt_stress(*damping, F, F_rate, 2.0 / s.dynamics->step);
      st.first_piola += sv.first_piola;
      if (with_matrix) st.tangent += sv.tangent;
    }
    // f_int,a = ∫ P : (e_c ⊗ Grad N_a) dV
    for (unsigned i = 0; i < n; ++i) cell_int(i) += st.first_piola.row(comp[i]).dot(gradN[i]) * JxW;
    if (!with_matrix) continue;
    // K_ab = ∫ (e_ca ⊗ Grad N_a) : 𝔸 : (e_cb ⊗ Grad N_b) dV, by blocks of component pairs
    // (cell_tangent.hpp); 𝔸 of a hyperelastic law has the major symmetry 𝔸_iJkL = 𝔸_kLiJ, so K
    // is symmetric and half its blocks are mirrored (the Kelvin–Voigt tangent has no such
    // symmetry: then every block).
    const double* G = s.geometry.gradient(c_index, q, 0);
    if (s.geometry.nodes == 4) tangent.add<4>(G, st.tangent, JxW, !damping);
    else tangent.add<10>(G, st.tangent, JxW, !damping);
  }
}

/// The cell's boundary faces: the dead-load tractions (scaled by the load factor) and the tool's
/// frictionless penalty contact, into `cell_ext` and, with the matrix, the contact's tangent
/// into `cell_K`; the tallies (traction and contact force, contact points, area, largest
/// pressure, penalty energy) into `out`. A cell that `cell_outside_tool` () finds wholly outside
/// the tool is not searched.
template <class CellIterator, class OutsideTool, class Tally>
void add_boundary_faces(const Impl& s, const CellIterator& cell, const dealii::Vector<double>& state,
                        const LoadState& load, bool with_matrix, OutsideTool& cell_outside_tool,
                        const std::vector<unsigned>& comp, dealii::FEFaceValues<3>& ffv,
                        std::vector<dealii::Tensor<1, 3>>& face_u, Tally& out, dealii::Vector<double>& cell_ext,
                        dealii::FullMatrix<double>& cell_K) {
  const unsigned n = static_cast<unsigned>(comp.size());
  const dealii::FEValuesExtractors::Vector disp(0);
  int near_tool = -1; // the cell's bound against the tool: -1 not tested yet, 0 outside, 1 may touch
  for (const unsigned f : cell->face_indices()) {
    if (!cell->face(f)->at_boundary()) continue;
    const auto id = cell->face(f)->boundary_id();
    Eigen::Vector3d traction_sum = Eigen::Vector3d::Zero();
    const Eigen::Vector3d* traction = nullptr;
    for (const auto& [group, t] : s.tractions)
      if (s.in_group(id, group)) {
        traction_sum += t;
        traction = &traction_sum;
      }
    if (s.tool && near_tool < 0) near_tool = cell_outside_tool() ? 0 : 1;
    const bool search = near_tool == 1;
    if (traction == nullptr && !search) continue;
    ffv.reinit(cell, f);
    if (search) ffv[disp].get_function_values(state, face_u);
    const Eigen::Vector3d side = search ? s.crack_side(cell, f) : Eigen::Vector3d::Zero();
    for (unsigned q = 0; q < ffv.n_quadrature_points; ++q) {
      const double JxW = ffv.JxW(q);
      Eigen::Vector3d t = Eigen::Vector3d::Zero();
      if (traction != nullptr) {
        t += load.load_factor * *traction;
        out.traction_on_body += load.load_factor * *traction * JxW;
      }
      Eigen::Matrix3d dt_dx = Eigen::Matrix3d::Zero();
      if (search) {
        const Eigen::Vector3d x = to_eigen(ffv.quadrature_point(q)) + Eigen::Vector3d(face_u[q][0], face_u[q][1], face_u[q][2]);
        const ToolContactPoint c = tool_contact(*s.tool, load.tool_position, x, side);
        if (c.inside) {
          // t_c = ε_N p n (per unit reference area), p = −g
          const Eigen::Vector3d tc = s.penalty * c.penetration * c.normal;
          t += tc;
          out.contact_on_body += tc * JxW;
          ++out.contact_points;
          out.contact_area += JxW;
          out.max_pressure = std::max(out.max_pressure, s.penalty * c.penetration);
          // Penalty energy ½ ε_N p² per reference area (its derivative is the traction above).
          out.contact_energy += 0.5 * s.penalty * c.penetration * c.penetration * JxW;
          // ∂t_c/∂x = ε_N (−n⊗n + p ∂n/∂x)
          dt_dx = s.penalty * (-c.normal * c.normal.transpose() + c.penetration * c.normal_derivative);
        }
      }
      for (unsigned i = 0; i < n; ++i) {
        const double Ni = ffv.shape_value_component(i, q, comp[i]);
        if (Ni == 0.0) continue;
        cell_ext(i) += Ni * t[comp[i]] * JxW;
        if (with_matrix && search)
          for (unsigned j = 0; j < n; ++j)
            cell_K(i, j) -= Ni * dt_dx(comp[i], comp[j]) * ffv.shape_value_component(j, q, comp[j]) * JxW;
      }
    }
  }
}
} // namespace

template <class Algebra>
void FiniteStrainSolver::Impl::assemble(Algebra& la, const typename Algebra::VectorType& owned_state,
                                        const LoadState& load, bool with_matrix,
                                        Assembly<typename Algebra::VectorType>& out,
                                        const dealii::AffineConstraints<double>* constraints,
                                        typename Algebra::VectorType* rhs) {
  typename Algebra::VectorType f_int, f_ext;
  la.reinit(f_int);
  la.reinit(f_ext);
  la.reinit(out.residual);
  out.contact_on_body.setZero();
  out.traction_on_body.setZero();
  out.contact_points = 0;
  out.contact_area = 0.0;
  out.max_pressure = 0.0;
  out.contact_energy = 0.0;
  if (with_matrix) {
    la.K = 0.0;
    *rhs = 0.0;
  }
  // The assembly's time without the communication inside it (SolverTimings), also when it throws.
  struct AssemblyTimer {
    const Impl& m;
    const std::chrono::steady_clock::time_point begin = std::chrono::steady_clock::now();
    const double communication_before = communication();
    double communication() const { return m.timings.communication_seconds + (m.parallel ? m.parallel->exchange_seconds : 0.0); }
    ~AssemblyTimer() {
      m.timings.assembly_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count() -
                                    (communication() - communication_before);
    }
  } timer{*this};
  // The state with the ghost values this process's cells, edge terms and cohesive pairs read.
  const dealii::Vector<double>& state = la.readable(owned_state);
  // An element that fails on one process fails the assembly on every process (after the
  // collective compress), so that all of them take the same branch of Newton and line search.
  std::string failure;
  try {
    assemble_cells(state, load, with_matrix, out, constraints, la.K, rhs, f_int, f_ext);
  } catch (const FiniteStrainError& e) {
    failure = e.what();
  }
  out.edge_points = 0;
  out.edge_length = 0.0;
  out.max_line_load = 0.0;
  if (blade_edge) assemble_blade_edge(state, load, with_matrix, out, constraints, la.K, rhs, f_ext);
  assemble_foundations(state, load, with_matrix, out, constraints, la.K, rhs, f_ext);
  if (distributed) {
    // The entries added to other processes' rows and vectors go to their owners.
    const ScopedTimer exchange(timings.communication_seconds);
    if (with_matrix) {
      la.K.compress(dealii::VectorOperation::add);
      rhs->compress(dealii::VectorOperation::add);
    }
    f_int.compress(dealii::VectorOperation::add);
    f_ext.compress(dealii::VectorOperation::add);
  }
  if (max(failure.empty() ? 0.0 : 1.0) > 0.0)
    throw FiniteStrainError(failure.empty() ? "finite strain: an element of another process failed" : failure);
  // The contact and traction tallies of every process's cells.
  std::array<double, 11> tally{out.contact_on_body.x(), out.contact_on_body.y(), out.contact_on_body.z(),
                               out.traction_on_body.x(), out.traction_on_body.y(), out.traction_on_body.z(),
                               static_cast<double>(out.contact_points), out.contact_area,
                               static_cast<double>(out.edge_points), out.edge_length, out.contact_energy};
  sum(tally);
  out.contact_on_body = Eigen::Vector3d(tally[0], tally[1], tally[2]);
  out.traction_on_body = Eigen::Vector3d(tally[3], tally[4], tally[5]);
  out.contact_points = static_cast<int>(tally[6]);
  out.contact_area = tally[7];
  out.edge_points = static_cast<int>(tally[8]);
  out.edge_length = tally[9];
  out.contact_energy = tally[10];
  for (Eigen::Vector3d& f : out.foundation_on_body) sum(std::span<double>(f.data(), 3));
  out.foundation_energy = sum(out.foundation_energy);
  out.max_pressure = max(out.max_pressure);
  out.max_line_load = max(out.max_line_load);
  out.residual = f_int;
  out.residual -= f_ext;
  out.internal_norm = f_int.l2_norm();
  out.external_norm = f_ext.l2_norm();
  if (poison_residual) out.residual *= std::numeric_limits<double>::quiet_NaN(); // fault injection (issue 10)
  if (!std::isfinite(out.residual.l2_norm())) throw FiniteStrainError("finite strain: non-finite residual");
}

template <class VectorType, class MatrixType, class Tally>
void FiniteStrainSolver::Impl::assemble_cells(const dealii::Vector<double>& state, const LoadState& load, bool with_matrix,
                                              Tally& out, const dealii::AffineConstraints<double>* constraints,
                                              MatrixType& K, VectorType* rhs, VectorType& f_int,
                                              VectorType& f_ext) const {
  const unsigned n = fe->n_dofs_per_cell();
  const CellGeometry& geo = geometry;
  dealii::FEFaceValues<3> ffv(*mapping, *fe, *face_quadrature,
                              dealii::update_values | dealii::update_quadrature_points | dealii::update_JxW_values);
  std::vector<dealii::Tensor<1, 3>> face_u(face_quadrature->size());
  std::vector<double> cell_u(n);
  dealii::FullMatrix<double> cell_K(n, n);
  dealii::Vector<double> cell_int(n), cell_ext(n), cell_rhs(n);
  std::vector<dealii::types::global_dof_index> local(n);
  std::vector<unsigned> comp(n);
  for (unsigned i = 0; i < n; ++i) comp[i] = fe->system_to_component_index(i).first;
  std::vector<Eigen::Vector3d> gradN(n);
  CellTangentBlocks tangent;
  const std::vector<unsigned>& node = geo.node_of_dof; // DOF i is component comp[i] of node node[i]
  if (geo.nodes != 4 && geo.nodes != 10)
    throw FiniteStrainError("finite strain: " + std::to_string(geo.nodes) + " nodes per cell, expected 4 or 10 (linear or quadratic tetrahedra)");
  std::vector<double> velocity(n);
  // The serial matrix: each cell's entries added at their places (cell_matrix_scatter.hpp, built
  // with the serial pattern); the distributed one through deal.II's distribute_local_to_global.
  constexpr bool serial_matrix = std::is_same_v<MatrixType, dealii::SparseMatrix<double>>;
  double* K_values = nullptr;
  if constexpr (serial_matrix)
    if (with_matrix) K_values = CellMatrixScatter::values(K);
  // The contact search's bound: a cell whose deformed shape lies outside one of the tool's
  // bounding half-spaces (rigid_tool.hpp) has no boundary point inside the tool, so its faces are
  // not searched. The deformed cell x(ξ) = Σ_a x_a N_a(ξ) (affine reference cell, P1 or P2
  // displacement) lies in the convex hull of its Bézier control points: for P1 the nodes; for P2
  // the vertices and, per edge (a, b) with midpoint node m, b_ab = 2 x_m − (x_a + x_b)/2 (the
  // quadratic Bernstein form, x_m = ¼ x_a + ½ b_ab + ¼ x_b; Farin 2002, "Curves and Surfaces for
  // CAGD", §17). The test is exact: it skips only faces whose every point is outside the tool.
  const std::optional<ToolHalfSpaces> tool_bound =
      tool ? std::optional<ToolHalfSpaces>(bounding_half_spaces(*tool)) : std::nullopt;
  std::vector<Eigen::Vector3d> control(geo.nodes);
  // P2: the two vertices of each edge node (the unit support point midway between them).
  std::vector<std::array<unsigned, 2>> edge_ends;
  if (geo.nodes == 10) {
    const std::vector<dealii::Point<3>>& p = fe->base_element(0).get_unit_support_points();
    for (unsigned k = 4; k < 10; ++k)
      for (unsigned a = 0; a < 4; ++a)
        for (unsigned b = a + 1; b < 4; ++b)
          if ((0.5 * (p[a] + p[b]) - p[k]).norm() < 1e-12) edge_ends.push_back({a, b});
    if (edge_ends.size() != 6) throw std::logic_error("finite strain: the quadratic tetrahedron's edge nodes are not edge midpoints");
  }
  auto cell_outside_tool = [&] {
    for (unsigned i = 0; i < n; ++i) control[node[i]][comp[i]] = reference_coordinate[local[i]] + cell_u[i];
    for (std::size_t l = 0; l < edge_ends.size(); ++l)
      control[4 + l] = 2.0 * control[4 + l] - 0.5 * (control[edge_ends[l][0]] + control[edge_ends[l][1]]);
    return outside_together(*tool_bound, load.tool_position, control);
  };

  for (const auto& cell : dof.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue; // distributed: another process assembles it
    cell->get_dof_indices(local);
    const std::size_t c_index = cell->active_cell_index();
    for (unsigned i = 0; i < n; ++i) cell_u[i] = state(local[i]);
    cell_K = 0.0;
    if (with_matrix) tangent.set_zero(geo.nodes);
    cell_int = 0.0;
    cell_ext = 0.0;
    const HyperelasticLaw& law = *laws[cell->material_id()];
    if (dynamics && dynamics->step > 0.0) add_cell_inertia(*this, c_index, local, comp, state, with_matrix, cell_int, cell_K);
    // Kelvin–Voigt damping (dynamic step): the Newmark velocity v_{n+1}(u) of the cell's DOFs.
    const bool damped = dynamics && dynamics->damped && dynamics->step > 0.0 &&
                        damping[cell->material_id()].retardation_time > 0.0;
    if (damped)
      for (unsigned i = 0; i < n; ++i) velocity[i] = newmark_velocity(local[i], state(local[i]));
    add_cell_stress(*this, c_index, law, damped ? &damping[cell->material_id()] : nullptr, cell_u, velocity, comp,
                    with_matrix, gradN, tangent, cell_int);
    if (with_matrix) {
      if (!damped) tangent.complete_lower(static_cast<int>(geo.nodes));
      for (unsigned i = 0; i < n; ++i)
        for (unsigned j = 0; j < n; ++j) cell_K(i, j) += tangent(comp[i], comp[j])(node[i], node[j]);
    }

    add_boundary_faces(*this, cell, state, load, with_matrix, cell_outside_tool, comp, ffv, face_u, out, cell_ext, cell_K);
    f_int.add(local, cell_int);
    f_ext.add(local, cell_ext);
    if (with_matrix) {
      for (unsigned i = 0; i < n; ++i) cell_rhs(i) = cell_ext(i) - cell_int(i);
      if constexpr (serial_matrix)
        cell_scatter.add(c_index, cell_K, cell_rhs, local, *constraints, K_values, *rhs);
      else
        add_cell_to_distributed(cell_K, cell_rhs, local, *constraints, K, *rhs);
    }
  }
  if (cohesive_law) assemble_cohesive(state, load, with_matrix, constraints, K, rhs, f_int);
}

// For the two algebras (algebra.hpp); Newton calls them (newton_raphson.cpp).
template void FiniteStrainSolver::Impl::assemble<SerialAlgebra>(SerialAlgebra&, const SerialAlgebra::VectorType&, const LoadState&, bool,
                                                     Assembly<SerialAlgebra::VectorType>&,
                                                     const dealii::AffineConstraints<double>*, SerialAlgebra::VectorType*);
template void FiniteStrainSolver::Impl::assemble<DistributedAlgebra>(DistributedAlgebra&, const DistributedAlgebra::VectorType&, const LoadState&, bool,
                                                     Assembly<DistributedAlgebra::VectorType>&,
                                                     const dealii::AffineConstraints<double>*, DistributedAlgebra::VectorType*);

} // namespace kerf::reference
