// The blade edge pass: the second contact pass of a wedge tool, whose edge (a line) enters the body
// between the boundary's quadrature points. The body's boundary facets are gathered once on
// every process as flat triangles (a P2 face split into four); at each assembly the edge points
// inside the body push on their closest facets with the line penalty ε_L (the contact itself:
// contact/blade_edge_contact.hpp), and the terms go into f_ext and the tangent.

#include "reference/solver/finite_strain_impl.hpp"

#include <deal.II/lac/full_matrix.h>

#include <Eigen/Geometry>

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

} // namespace

void FiniteStrainSolver::Impl::build_blade_edge() {
  // This process's boundary facets, each as three global node numbers k (DOFs 3k + c, checked
  // node-major in build), outward: (X1 − X0) × (X2 − X0) points away from the cell's centre.
  std::vector<double> facets_here; // 3 nodes per facet
  std::map<dealii::types::global_dof_index, Eigen::Vector3d> nodes_here;
  auto node = [](dealii::types::global_dof_index i) { return i / 3; };
  for (const auto& cell : dof.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    for (const unsigned f : cell->face_indices()) {
      if (!cell->face(f)->at_boundary()) continue;
      const auto face = cell->face(f);
      std::array<dealii::types::global_dof_index, 3> v{};
      std::array<unsigned, 3> vi{};
      for (unsigned a = 0; a < 3; ++a) {
        v[a] = node(face->vertex_dof_index(a, 0));
        vi[a] = face->vertex_index(a);
        nodes_here[v[a]] = to_eigen(face->vertex(a));
      }
      const Eigen::Vector3d X0 = nodes_here[v[0]];
      const Eigen::Vector3d n = (nodes_here[v[1]] - X0).cross(nodes_here[v[2]] - X0);
      if (n.dot(X0 - to_eigen(cell->center())) < 0.0) {
        std::swap(v[1], v[2]);
        std::swap(vi[1], vi[2]);
      }
      auto add = [&](dealii::types::global_dof_index a, dealii::types::global_dof_index b,
                     dealii::types::global_dof_index c) {
        for (const auto k : {a, b, c}) facets_here.push_back(static_cast<double>(k));
      };
      if (settings.degree == 1) {
        add(v[0], v[1], v[2]);
        continue;
      }
      // P2: m[a] is the midpoint node of the edge (vi[a], vi[a+1]); four flat sub-facets, each
      // oriented as the face.
      std::array<dealii::types::global_dof_index, 3> m{};
      std::array<bool, 3> found{false, false, false};
      for (unsigned l = 0; l < 3; ++l) {
        const auto line = face->line(l);
        for (std::size_t a = 0; a < 3; ++a) {
          const unsigned p = vi[a], q = vi[(a + 1) % 3];
          if ((line->vertex_index(0) == p && line->vertex_index(1) == q) ||
              (line->vertex_index(0) == q && line->vertex_index(1) == p)) {
            m[a] = node(line->dof_index(0));
            nodes_here[m[a]] = to_eigen(line->center()); // straight-sided cells (MappingFE of P1)
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
  }
  // Every process's facets and nodes (rank order): 3 numbers per facet; 4 per node (k, X).
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
  double longest = 0.0;
  for (std::size_t r = 0; r < all_facets.size(); ++r)
    for (std::size_t i = 0; i + 2 < all_facets[r].size(); i += 3) {
      BoundaryFacet facet{};
      for (std::size_t a = 0; a < 3; ++a)
        facet[a] = compact.at(static_cast<dealii::types::global_dof_index>(all_facets[r][i + a]));
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
void FiniteStrainSolver::Impl::assemble_blade_edge(const VectorType& state, const LoadState& load, bool with_matrix,
                                                   Tally& out, const dealii::AffineConstraints<double>* constraints,
                                                   MatrixType& K, VectorType* rhs, VectorType& f_ext) const {
  const BladeEdgeBoundary& b = *blade_edge;
  // The boundary nodes' displacements, each supplied by one process (collective when distributed).
  std::fill(b.displacement.begin(), b.displacement.end(), 0.0);
  for (std::size_t k = 0; k < b.node_of.size(); ++k)
    if (b.node_here[k] != 0)
      for (unsigned c = 0; c < 3; ++c) b.displacement[3 * k + c] = state[3 * b.node_of[k] + c];
  sum(b.displacement);
  const BladeEdgeContact contact =
      blade_edge_contact(*tool, load.tool_position, b.facets, b.positions, b.displacement, b.settings);
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
template void FiniteStrainSolver::Impl::assemble_blade_edge(const SerialAlgebra::VectorType&, const LoadState&, bool,
                                                            Assembly<SerialAlgebra::VectorType>&,
                                                            const dealii::AffineConstraints<double>*,
                                                            SerialAlgebra::MatrixType&, SerialAlgebra::VectorType*,
                                                            SerialAlgebra::VectorType&) const;
template void FiniteStrainSolver::Impl::assemble_blade_edge(const DistributedAlgebra::VectorType&, const LoadState&, bool,
                                                            Assembly<DistributedAlgebra::VectorType>&,
                                                            const dealii::AffineConstraints<double>*,
                                                            DistributedAlgebra::MatrixType&, DistributedAlgebra::VectorType*,
                                                            DistributedAlgebra::VectorType&) const;

} // namespace kerf::reference
