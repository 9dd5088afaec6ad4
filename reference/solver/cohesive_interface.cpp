// The cohesive interface along the crack path (Reference II; CohesiveInterfaceSpec): the coincident
// face pairs of the split mesh, the opening Δ = x⁺ − x⁻ at the + face's quadrature points, the
// interface's forces and tangent from the bilinear law (cohesive/cohesive_law.hpp), and the commit
// of each point's history after a converged solve, with the interface's energies.

#include "reference/solver/finite_strain_impl.hpp"

#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/full_matrix.h>

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <vector>

namespace kerf::reference {

namespace {

using CohesivePair = FiniteStrainSolver::Impl::CohesivePair;
using FaceKey = std::array<long long, 9>;

/// A face's key: its vertex positions rounded on a grid far finer than any element (the copies
/// made by the crack split, and their refinements, coincide exactly), sorted.
template <class FaceIterator> FaceKey face_key(const FaceIterator& face, double grid) {
  std::array<std::array<long long, 3>, 3> v{};
  for (unsigned k = 0; k < 3; ++k)
    for (unsigned c = 0; c < 3; ++c) v[k][c] = std::llround(face->vertex(k)[c] / grid);
  std::sort(v.begin(), v.end());
  FaceKey key{};
  for (unsigned k = 0; k < 3; ++k)
    for (unsigned c = 0; c < 3; ++c) key[3 * k + c] = v[k][c];
  return key;
}

/// The geometry of the pair of face f of `cell` (on the + side) and its coincident face of
/// `minus_cell`: the normal n from − into +, the face's vertices, and at each of the + face's
/// quadrature points its position, weight and both cells' shape values (`ffv` is reinitialised
/// on the + face). The cells may be a DoFHandler's or a Triangulation's (shape values need no DOFs).
template <class PlusCell, class MinusCell>
void pair_geometry(CohesivePair& pair, dealii::FEFaceValues<3>& ffv, const dealii::FESystem<3>& fe,
                   const std::vector<unsigned>& components, const PlusCell& cell, unsigned f, const MinusCell& minus_cell) {
  const unsigned n = fe.n_dofs_per_cell();
  ffv.reinit(cell, f);
  // The + cell's outward normal points into the − side; n points from − into +.
  pair.normal = -Eigen::Vector3d(ffv.normal_vector(0)[0], ffv.normal_vector(0)[1], ffv.normal_vector(0)[2]);
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
      plus[i] = ffv.shape_value_component(i, q, components[i]);
      minus[i] = fe.shape_value_component(i, unit, components[i]);
    }
    pair.plus_values.push_back(std::move(plus));
    pair.minus_values.push_back(std::move(minus));
    pair.weights.push_back(ffv.JxW(q));
    pair.points.push_back(x);
  }
}

/// A face of the + surface and its coincident face of the − surface, on cells of type `Cell`.
template <class Cell> struct FacePair {
  Cell plus;
  unsigned plus_face;
  Cell minus;
  unsigned minus_face;
};

/// The face pairs of the split crack path over `cells` (a DoFHandler's or a Triangulation's active
/// cells), in the order of the + faces over the cells. Throws std::invalid_argument naming the
/// surfaces if a + face has no coincident − face or the two surfaces' face counts differ.
template <class Cell, class Cells, class InGroup>
std::vector<FacePair<Cell>> find_face_pairs(const Cells& cells, const CohesiveInterfaceSpec& spec, int plus_group,
                                            int minus_group, const InGroup& in_group, double grid) {
  std::map<FaceKey, std::pair<Cell, unsigned>> minus_faces;
  for (const auto& cell : cells)
    for (const unsigned f : cell->face_indices())
      if (cell->face(f)->at_boundary() && in_group(cell->face(f)->boundary_id(), minus_group))
        minus_faces[face_key(cell->face(f), grid)] = {cell, f};
  std::vector<FacePair<Cell>> pairs;
  for (const auto& cell : cells)
    for (const unsigned f : cell->face_indices()) {
      if (!cell->face(f)->at_boundary() || !in_group(cell->face(f)->boundary_id(), plus_group)) continue;
      const auto match = minus_faces.find(face_key(cell->face(f), grid));
      if (match == minus_faces.end())
        throw std::invalid_argument("finite strain solver: a face of cohesive surface '" + spec.plus_surface + "' at (" +
                                    std::to_string(cell->face(f)->center()[0]) + ", " + std::to_string(cell->face(f)->center()[1]) +
                                    ", " + std::to_string(cell->face(f)->center()[2]) + ") m has no coincident face in '" +
                                    spec.minus_surface + "' (was the mesh split along the crack path?)");
      pairs.push_back({cell, f, match->second.first, match->second.second});
    }
  if (pairs.empty())
    throw std::invalid_argument("finite strain solver: cohesive surface '" + spec.plus_surface + "' has no boundary faces");
  if (pairs.size() != minus_faces.size())
    throw std::invalid_argument("finite strain solver: cohesive surfaces '" + spec.plus_surface + "' and '" + spec.minus_surface +
                                "' have different face counts (" + std::to_string(pairs.size()) + " and " +
                                std::to_string(minus_faces.size()) + ")");
  return pairs;
}

} // namespace

std::vector<std::pair<unsigned, unsigned>> FiniteStrainSolver::Impl::cohesive_cell_pairs(const CohesiveInterfaceSpec& spec,
                                                                                     int plus_group, int minus_group) const {
  // The faces are matched on a grid of 1e-6 of the smallest edge, as build_cohesive matches them.
  const auto in = [this](dealii::types::boundary_id id, int group) { return in_group(id, group); };
  std::vector<std::pair<unsigned, unsigned>> cells;
  for (const auto& face : find_face_pairs<dealii::Triangulation<3>::active_cell_iterator>(tria.active_cell_iterators(), spec,
                                                                                       plus_group, minus_group, in, 1e-6 * h_min))
    cells.emplace_back(face.plus->active_cell_index(), face.minus->active_cell_index());
  return cells;
}

void FiniteStrainSolver::Impl::build_cohesive(const CohesiveInterfaceSpec& spec, int plus_group, int minus_group) {
  validate(spec.law);
  if (spec.plus_surface == spec.minus_surface)
    throw std::invalid_argument("finite strain solver: cohesive plus and minus surfaces are the same group '" + spec.plus_surface + "'");
  const unsigned n = fe->n_dofs_per_cell();
  cell_components.resize(n);
  for (unsigned i = 0; i < n; ++i) cell_components[i] = fe->system_to_component_index(i).first;
  cohesive_law = spec.law;
  if (distributed) {
    build_distributed_cohesive(spec, plus_group, minus_group);
  } else {
    const auto in = [this](dealii::types::boundary_id id, int group) { return in_group(id, group); };
    dealii::FEFaceValues<3> ffv(*mapping, *fe, *face_quadrature,
                                dealii::update_values | dealii::update_quadrature_points | dealii::update_JxW_values |
                                    dealii::update_normal_vectors);
    std::vector<dealii::types::global_dof_index> plus_dofs(n), minus_dofs(n);
    for (const auto& face : find_face_pairs<dealii::DoFHandler<3>::active_cell_iterator>(
             dof.active_cell_iterators(), spec, plus_group, minus_group, in, 1e-6 * h_min)) {
      CohesivePair pair;
      pair.index = cohesive_pairs.size();
      pair_geometry(pair, ffv, *fe, cell_components, face.plus, face.plus_face, face.minus);
      face.plus->get_dof_indices(plus_dofs);
      face.minus->get_dof_indices(minus_dofs);
      pair.dofs = plus_dofs;
      pair.dofs.insert(pair.dofs.end(), minus_dofs.begin(), minus_dofs.end());
      crack_face_sides[4 * face.plus->active_cell_index() + face.plus_face] = pair.normal;
      crack_face_sides[4 * face.minus->active_cell_index() + face.minus_face] = -pair.normal;
      cohesive_pairs.push_back(std::move(pair));
    }
    cohesive_pair_total = cohesive_pairs.size();
  }
  cohesive_states.assign(cohesive_pairs.size() * face_quadrature->size(), CohesiveState{});
}

void FiniteStrainSolver::Impl::build_distributed_cohesive(const CohesiveInterfaceSpec& spec, int plus_group,
                                                          int minus_group) {
  // The pairs are found and numbered on `tria`, the whole mesh that every process holds, in the
  // order of its cells — the order of the serial build's, whose DoFHandler is on `tria` — so that
  // pair p is the same face pair on every process and in a serial run (its history's place in the
  // checkpoint). `tria`'s subdomain ids are the partition (partition_triangulation): process r
  // keeps the pairs whose + cell it owns. The − cell's DOFs come from the process that owns it
  // (the two sides of the crack path are different cells, which the partition may separate).
  // Shape values need no DOFs: each pair's geometry is computed on `tria`'s cells, whose vertex
  // order the distributed cells keep (checked below), so a local DOF means the same on both.
  const unsigned n = fe->n_dofs_per_cell();
  const auto here = static_cast<dealii::types::subdomain_id>(rank);
  const auto in = [this](dealii::types::boundary_id id, int group) { return in_group(id, group); };
  const auto pairs = find_face_pairs<dealii::Triangulation<3>::active_cell_iterator>(
      tria.active_cell_iterators(), spec, plus_group, minus_group, in, 1e-6 * h_min);
  cohesive_pair_total = pairs.size();
  // This process's cells of the distributed mesh, by their id (the same id as the whole mesh's cell).
  std::map<dealii::CellId, dealii::DoFHandler<3>::active_cell_iterator> owned;
  for (const auto& cell : dof.active_cell_iterators())
    if (cell->is_locally_owned()) owned.emplace(cell->id(), cell);
  auto distributed_cell = [&](const dealii::Triangulation<3>::active_cell_iterator& whole) {
    const auto it = owned.find(whole->id());
    if (it == owned.end()) throw std::logic_error("finite strain solver: a cell of this process is not in its distributed mesh");
    for (const unsigned v : whole->vertex_indices())
      if (it->second->vertex(v).distance(whole->vertex(v)) > 1e-12 * h_min)
        throw std::logic_error("finite strain solver: the distributed mesh orders a cell's vertices unlike the whole mesh");
    return it->second;
  };
  dealii::FEFaceValues<3> ffv(*mapping, *fe, *face_quadrature,
                              dealii::update_values | dealii::update_quadrature_points | dealii::update_JxW_values |
                                  dealii::update_normal_vectors);
  // The − cells of this process: their DOFs, [pair, n DOFs] per pair, to the process owning the
  // + cell (this one included), and the side of their crack face, −n = the + face's outward normal.
  std::map<unsigned, std::vector<dealii::types::global_dof_index>> minus_dofs_for;
  std::vector<dealii::types::global_dof_index> dofs(n);
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    if (pairs[p].minus->subdomain_id() != here) continue;
    const auto local = distributed_cell(pairs[p].minus);
    local->get_dof_indices(dofs);
    auto& to = minus_dofs_for[pairs[p].plus->subdomain_id()];
    to.push_back(p);
    to.insert(to.end(), dofs.begin(), dofs.end());
    ffv.reinit(pairs[p].plus, pairs[p].plus_face);
    crack_face_sides[4 * local->active_cell_index() + pairs[p].minus_face] =
        Eigen::Vector3d(ffv.normal_vector(0)[0], ffv.normal_vector(0)[1], ffv.normal_vector(0)[2]);
  }
  // Collective: every process receives the − cells' DOFs of the pairs it owns.
  std::map<std::size_t, std::vector<dealii::types::global_dof_index>> minus_dofs_of; // pair -> DOFs
  for (const auto& [from, list] : dealii::Utilities::MPI::some_to_some(parallel->comm, minus_dofs_for))
    for (std::size_t k = 0; k + n + 1 <= list.size(); k += n + 1)
      minus_dofs_of[static_cast<std::size_t>(list[k])].assign(list.begin() + static_cast<std::ptrdiff_t>(k + 1),
                                                               list.begin() + static_cast<std::ptrdiff_t>(k + 1 + n));
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    if (pairs[p].plus->subdomain_id() != here) continue;
    CohesivePair pair;
    pair.index = p;
    pair_geometry(pair, ffv, *fe, cell_components, pairs[p].plus, pairs[p].plus_face, pairs[p].minus);
    const auto local = distributed_cell(pairs[p].plus);
    local->get_dof_indices(dofs);
    const auto minus = minus_dofs_of.find(p);
    if (minus == minus_dofs_of.end() || minus->second.size() != n)
      throw std::logic_error("finite strain solver: the DOFs of a cohesive pair's − cell did not arrive");
    pair.dofs = dofs;
    pair.dofs.insert(pair.dofs.end(), minus->second.begin(), minus->second.end());
    crack_face_sides[4 * local->active_cell_index() + pairs[p].plus_face] = pair.normal;
    cohesive_dofs.insert(cohesive_dofs.end(), pair.dofs.begin(), pair.dofs.end());
    cohesive_pairs.push_back(std::move(pair));
  }
  std::sort(cohesive_dofs.begin(), cohesive_dofs.end());
  cohesive_dofs.erase(std::unique(cohesive_dofs.begin(), cohesive_dofs.end()), cohesive_dofs.end());
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
void FiniteStrainSolver::Impl::assemble_cohesive(const dealii::Vector<double>& state, const LoadState& load, bool with_matrix,
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

CohesiveSummary FiniteStrainSolver::Impl::commit_cohesive(const LoadState& load, const dealii::Vector<double>& u) {
  const std::size_t nq = face_quadrature->size();
  const double dt = load.time - committed_time;
  const double d0 = cohesive_law->peak_opening();
  CohesiveSummary summary;
  // The running totals take this process's increments; distributed, the increments are summed
  // over the processes below, so that every process holds the whole interface's totals.
  double viscous = 0.0, trapezoid_work = 0.0;
  double& viscous_total = distributed ? viscous : cohesive_viscous_dissipation;
  double& trapezoid_total = distributed ? trapezoid_work : cohesive_trapezoid_work;
  for (std::size_t p = 0; p < cohesive_pairs.size(); ++p)
    for (std::size_t q = 0; q < nq; ++q) {
      CohesiveState& state = cohesive_states[p * nq + q];
      const Eigen::Vector3d opening = cohesive_opening(cohesive_pairs[p], q, u);
      const CohesiveResponse r = cohesive_response(*cohesive_law, state, opening, cohesive_pairs[p].normal, dt);
      const double w = cohesive_pairs[p].weights[q];
      if (dt > 0.0) viscous_total += r.viscous_power_density * dt * w;
      if (dynamics) {
        // ½ (t_n + t_{n+1})·(Δ_{n+1} − Δ_n) without the viscous part (dt = 0): t_n is the traction at
        // the last converged opening Δ_n with the damage κ_n reached there.
        const Eigen::Vector3d& n = cohesive_pairs[p].normal;
        const CohesiveResponse before = cohesive_response(*cohesive_law, state, state.previous_opening, n, 0.0);
        const CohesiveResponse after = cohesive_law->viscosity > 0.0 ? cohesive_response(*cohesive_law, state, opening, n, 0.0) : r;
        const double trapezoid = 0.5 * (before.traction + after.traction).dot(opening - state.previous_opening) * w;
        trapezoid_total += trapezoid;
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
  if (distributed) {
    std::array<double, 8> parts{summary.failed_area,       summary.damaged_area,
                                summary.stored_energy,     summary.dissipated_energy,
                                summary.step_time_integration_error, summary.step_dissipation,
                                viscous,                   trapezoid_work};
    sum(parts);
    summary.failed_area = parts[0];
    summary.damaged_area = parts[1];
    summary.stored_energy = parts[2];
    summary.dissipated_energy = parts[3];
    summary.step_time_integration_error = parts[4];
    summary.step_dissipation = parts[5];
    cohesive_viscous_dissipation += parts[6];
    cohesive_trapezoid_work += parts[7];
    summary.max_damage = max(summary.max_damage);
  }
  committed_time = load.time;
  summary.viscous_dissipation = cohesive_viscous_dissipation;
  summary.trapezoid_work = cohesive_trapezoid_work;
  return summary;
}

// For the two algebras (algebra.hpp); the assembly calls them (assemble_system.cpp).
template void FiniteStrainSolver::Impl::assemble_cohesive(const dealii::Vector<double>&, const LoadState&, bool,
                                                          const dealii::AffineConstraints<double>*,
                                                          SerialAlgebra::MatrixType&, SerialAlgebra::VectorType*,
                                                          SerialAlgebra::VectorType&) const;
template void FiniteStrainSolver::Impl::assemble_cohesive(const dealii::Vector<double>&, const LoadState&, bool,
                                                          const dealii::AffineConstraints<double>*,
                                                          DistributedAlgebra::MatrixType&, DistributedAlgebra::VectorType*,
                                                          DistributedAlgebra::VectorType&) const;

} // namespace kerf::reference
