// The blade edge pass: the second contact pass of a wedge tool, whose edge (a line) enters the body
// between the boundary's quadrature points. The body's boundary facets are gathered once on
// every process as flat triangles (a P2 face split into four); at each assembly the edge points
// inside the body push on their closest facets with the line penalty ε_L (the contact itself:
// contact/blade_edge_contact.hpp), and the terms go into f_ext and the tangent.

#include "reference/solver/finite_strain_impl.hpp"

#include <deal.II/lac/full_matrix.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <map>
#include <stdexcept>

namespace kerf::reference {

namespace {

/// Every process's `values`, in rank order (MPI_Allgatherv; collective on `comm`).
std::vector<std::vector<double>> all_gather(MPI_Comm comm, const std::vector<double>& values) {
  int size = 0;
  MPI_Comm_size(comm, &size);
  int count = static_cast<int>(values.size());
  std::vector<int> counts(static_cast<std::size_t>(size)), offsets(static_cast<std::size_t>(size) + 1, 0);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (std::size_t r = 0; r < counts.size(); ++r) offsets[r + 1] = offsets[r] + counts[r];
  std::vector<double> all(static_cast<std::size_t>(offsets.back()));
  MPI_Allgatherv(values.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, comm);
  std::vector<std::vector<double>> out;
  for (std::size_t r = 0; r < counts.size(); ++r)
    out.emplace_back(all.begin() + offsets[r], all.begin() + offsets[r + 1]);
  return out;
}

/// A term as numbers: facet, weight, line load, the 9 forces and the 81 stiffness entries.
constexpr std::size_t term_size = 3 + 9 + 81;

/// The boundary facets of face `f` of `cell`, as flat triangles of global node numbers k (DOFs
/// 3k + c, checked node-major in build), outward: (X1 − X0) × (X2 − X0) points away from the
/// cell's centre. P1: the face; P2: four sub-facets through its edge midpoints, each oriented as
/// the face. Appended to `facets` as 4 numbers each (its place in the whole mesh's order,
/// 16 × `whole` + `sub`: 4 faces × at most 4 sub-facets; then k0, k1, k2), their nodes' reference
/// positions to `nodes`.
void add_face_facets(const dealii::DoFHandler<3>::active_cell_iterator& cell, unsigned f, std::size_t whole,
                     std::size_t& sub, int degree, std::vector<double>& facets,
                     std::map<dealii::types::global_dof_index, Eigen::Vector3d>& nodes) {
  auto node = [](dealii::types::global_dof_index i) { return i / 3; };
  const auto face = cell->face(f);
  std::array<dealii::types::global_dof_index, 3> v{};
  std::array<unsigned, 3> vi{};
  for (unsigned a = 0; a < 3; ++a) {
    v[a] = node(face->vertex_dof_index(a, 0));
    vi[a] = face->vertex_index(a);
    nodes[v[a]] = to_eigen(face->vertex(a));
  }
  const Eigen::Vector3d X0 = nodes[v[0]];
  const Eigen::Vector3d n = (nodes[v[1]] - X0).cross(nodes[v[2]] - X0);
  if (n.dot(X0 - to_eigen(cell->center())) < 0.0) {
    std::swap(v[1], v[2]);
    std::swap(vi[1], vi[2]);
  }
  auto add = [&](dealii::types::global_dof_index a, dealii::types::global_dof_index b, dealii::types::global_dof_index c) {
    facets.push_back(static_cast<double>(16 * whole + sub++));
    for (const auto k : {a, b, c}) facets.push_back(static_cast<double>(k));
  };
  if (degree == 1) {
    add(v[0], v[1], v[2]);
    return;
  }
  // P2: m[a] is the midpoint node of the edge (vi[a], vi[a+1]).
  std::array<dealii::types::global_dof_index, 3> m{};
  std::array<bool, 3> found{false, false, false};
  for (unsigned l = 0; l < 3; ++l) {
    const auto line = face->line(l);
    for (std::size_t a = 0; a < 3; ++a) {
      const unsigned p = vi[a], q = vi[(a + 1) % 3];
      if ((line->vertex_index(0) == p && line->vertex_index(1) == q) ||
          (line->vertex_index(0) == q && line->vertex_index(1) == p)) {
        m[a] = node(line->dof_index(0));
        nodes[m[a]] = to_eigen(line->center()); // straight-sided cells (MappingFE of P1)
        found[a] = true;
      }
    }
  }
  if (!(found[0] && found[1] && found[2]))
    throw std::logic_error("finite strain solver: a P2 boundary face without its edge midpoint nodes");
  add(v[0], m[0], m[2]);
  add(m[0], v[1], m[1]);
  add(m[2], m[1], v[2]);
  add(m[0], m[1], m[2]);
}

/// The boundary facets of this process's cells (add_face_facets); `whole_mesh` is the whole
/// (refined) mesh every process holds, whose cell numbers order the facets.
void boundary_facets_here(const dealii::DoFHandler<3>& dof, const dealii::Triangulation<3>& whole_mesh,
                          bool distributed, int degree, std::vector<double>& facets,
                          std::map<dealii::types::global_dof_index, Eigen::Vector3d>& nodes) {
  for (const auto& cell : dof.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    // The facets' order is the whole mesh's (its cells, their faces, the sub-facets), on any number
    // of processes: the edge pass takes the first of the facets tied at the smallest distance (an
    // edge point over the crack path is as near the top faces of both its sides), so the order
    // decides which side takes the term, and with it the equilibrium among the equally near ones.
    const std::size_t whole =
        distributed ? whole_mesh.create_cell_iterator(cell->id())->active_cell_index() : cell->active_cell_index();
    std::size_t sub = 0;
    for (const unsigned f : cell->face_indices())
      if (cell->face(f)->at_boundary()) add_face_facets(cell, f, whole, sub, degree, facets, nodes);
  }
}

} // namespace

std::vector<EdgeContactTerm> FiniteStrainSolver::Impl::all_terms(const std::vector<EdgeContactTerm>& mine) const {
  std::vector<double> packed;
  packed.reserve(term_size * mine.size());
  for (const EdgeContactTerm& t : mine) {
    packed.insert(packed.end(), {static_cast<double>(t.facet), t.weight, t.line_load});
    packed.insert(packed.end(), t.force_on_body.data(), t.force_on_body.data() + 9);
    packed.insert(packed.end(), t.stiffness.data(), t.stiffness.data() + 81);
  }
  std::vector<std::vector<double>> every;
  {
    const ScopedTimer timer(timings.communication_seconds);
    every = all_gather(parallel->comm, packed);
  }
  std::vector<EdgeContactTerm> terms;
  for (const std::vector<double>& from : every)
    for (std::size_t k = 0; k + term_size <= from.size(); k += term_size) {
      EdgeContactTerm t;
      t.facet = static_cast<std::size_t>(from[k]);
      t.nodes = blade_edge->facets[t.facet];
      t.weight = from[k + 1];
      t.line_load = from[k + 2];
      t.force_on_body = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(&from[k + 3]);
      t.stiffness = Eigen::Map<const Eigen::Matrix<double, 9, 9>>(&from[k + 12]);
      terms.push_back(std::move(t));
    }
  return terms;
}

void FiniteStrainSolver::Impl::build_blade_edge() {
  // This process's boundary facets (4 numbers each: their order, k0, k1, k2) and their nodes.
  std::vector<double> facets_here;
  std::map<dealii::types::global_dof_index, Eigen::Vector3d> nodes_here;
  boundary_facets_here(dof, tria, distributed, settings.degree, facets_here, nodes_here);
  // Every process's facets and nodes (rank order): 4 numbers per facet (order, k0, k1, k2); 4 per
  // node (k, X).
  std::vector<double> my_nodes;
  for (const auto& [k, X] : nodes_here) my_nodes.insert(my_nodes.end(), {static_cast<double>(k), X.x(), X.y(), X.z()});
  std::vector<std::vector<double>> all_facets{facets_here}, all_nodes{my_nodes};
  if (distributed) {
    all_facets = all_gather(parallel->comm, facets_here);
    all_nodes = all_gather(parallel->comm, my_nodes);
  }
  const int here = distributed ? rank : 0;
  BladeEdgeBoundary b;
  std::map<dealii::types::global_dof_index, int> compact;
  for (std::size_t r = 0; r < all_nodes.size(); ++r)
    for (std::size_t i = 0; i + 3 < all_nodes[r].size(); i += 4) {
      const auto k = static_cast<dealii::types::global_dof_index>(all_nodes[r][i]);
      if (compact.count(k) != 0) continue; // the first process holding a node supplies it
      compact.emplace(k, static_cast<int>(b.node_of.size()));
      b.node_of.push_back(k);
      b.positions.emplace_back(all_nodes[r][i + 1], all_nodes[r][i + 2], all_nodes[r][i + 3]);
      b.node_here.push_back(static_cast<int>(r) == here ? 1 : 0);
    }
  std::vector<std::pair<double, std::pair<std::size_t, std::size_t>>> order; // (order, (process, offset))
  for (std::size_t r = 0; r < all_facets.size(); ++r)
    for (std::size_t i = 0; i + 3 < all_facets[r].size(); i += 4) order.push_back({all_facets[r][i], {r, i}});
  std::sort(order.begin(), order.end());
  double longest = 0.0;
  for (const auto& [key, where] : order) {
    const auto [r, i] = where;
    BoundaryFacet facet{};
    for (std::size_t a = 0; a < 3; ++a)
      facet[a] = compact.at(static_cast<dealii::types::global_dof_index>(all_facets[r][i + 1 + a]));
    for (std::size_t a = 0; a < 3; ++a)
      longest = std::max(longest, (b.positions[static_cast<std::size_t>(facet[a])] -
                                   b.positions[static_cast<std::size_t>(facet[(a + 1) % 3])]).norm());
    b.facets.push_back(facet);
    b.facet_here.push_back(static_cast<int>(r) == here ? 1 : 0);
  }
  // ε_L = ε_N h_min (a line load E h_min costs a penetration h_min / 50 with the automatic ε_N)
  b.settings.line_penalty = settings.edge_line_penalty > 0.0 ? settings.edge_line_penalty : penalty * h_min;
  b.settings.point_spacing = settings.edge_point_spacing > 0.0 ? settings.edge_point_spacing : 0.25 * h_min;
  // Facets farther than two boundary edges from an edge point cannot hold its closest point once
  // the edge has entered the body by less than that in one load increment.
  b.settings.search_distance = 2.0 * longest;
  b.displacement.assign(3 * b.node_of.size(), 0.0);
  blade_edge = std::move(b);
}

template <class VectorType, class MatrixType, class Tally>
void FiniteStrainSolver::Impl::assemble_blade_edge(const dealii::Vector<double>& state, const LoadState& load, bool with_matrix,
                                                   Tally& out, const dealii::AffineConstraints<double>* constraints,
                                                   MatrixType& K, VectorType* rhs, VectorType& f_ext) const {
  const BladeEdgeBoundary& b = *blade_edge;
  // The boundary nodes' displacements, each supplied by one process (collective when distributed).
  std::fill(b.displacement.begin(), b.displacement.end(), 0.0);
  for (std::size_t k = 0; k < b.node_of.size(); ++k)
    if (b.node_here[k] != 0)
      for (unsigned c = 0; c < 3; ++c) b.displacement[3 * k + c] = state[3 * b.node_of[k] + c];
  sum(b.displacement);
  // Distributed, each process searches its share of the edge points (blade_edge_contact's
  // `part`), and every process receives all the terms found (collective), in edge order, to
  // assemble those on its own facets.
  BladeEdgeContact contact = blade_edge_contact(*tool, load.tool_position, b.facets, b.positions, b.displacement,
                                                b.settings, distributed ? static_cast<std::size_t>(rank) : 0,
                                                distributed ? static_cast<std::size_t>(process_count) : 1);
  if (distributed) contact.terms = all_terms(contact.terms);
  dealii::FullMatrix<double> term_K(9, 9);
  dealii::Vector<double> term_f(9);
  std::vector<dealii::types::global_dof_index> term_dofs(9);
  for (const EdgeContactTerm& t : contact.terms) {
    if (b.facet_here[t.facet] == 0) continue; // another process's facet
    for (unsigned i = 0; i < 9; ++i) {
      term_dofs[i] = 3 * b.node_of[static_cast<std::size_t>(t.nodes[i / 3])] + i % 3;
      term_f(i) = t.force_on_body(i);
      for (unsigned j = 0; j < 9; ++j) term_K(i, j) = t.stiffness(i, j);
    }
    f_ext.add(term_dofs, term_f);
    // K += ∂²W/∂x², rhs += f (rhs = f_ext − f_int)
    if (with_matrix) constraints->distribute_local_to_global(term_K, term_f, term_dofs, K, *rhs);
    for (int i = 0; i < 3; ++i) out.contact_on_body += t.force_on_body.template segment<3>(3 * i);
    ++out.edge_points;
    out.edge_length += t.weight;
    out.max_line_load = std::max(out.max_line_load, t.line_load);
    // W = ½ ε_L w d² = ½ w q² / ε_L with the line load q = ε_L d (blade_edge_contact.hpp).
    out.contact_energy += 0.5 * t.weight * t.line_load * t.line_load / b.settings.line_penalty;
  }
}

// For the two algebras (algebra.hpp); the assembly calls them (assemble_system.cpp).
template void FiniteStrainSolver::Impl::assemble_blade_edge(const dealii::Vector<double>&, const LoadState&, bool,
                                                            Assembly<SerialAlgebra::VectorType>&,
                                                            const dealii::AffineConstraints<double>*,
                                                            SerialAlgebra::MatrixType&, SerialAlgebra::VectorType*,
                                                            SerialAlgebra::VectorType&) const;
template void FiniteStrainSolver::Impl::assemble_blade_edge(const dealii::Vector<double>&, const LoadState&, bool,
                                                            Assembly<DistributedAlgebra::VectorType>&,
                                                            const dealii::AffineConstraints<double>*,
                                                            DistributedAlgebra::MatrixType&, DistributedAlgebra::VectorType*,
                                                            DistributedAlgebra::VectorType&) const;

} // namespace kerf::reference
