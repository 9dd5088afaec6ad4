// The serial assembly's scatter of a cell's matrix and right-hand side under Dirichlet
// constraints (reference/solver/cell_matrix_scatter.hpp) against a second method: deal.II's
// AffineConstraints::distribute_local_to_global with the same constraints, on linear and
// quadratic tetrahedra, random cell matrices (zero diagonal entries among them) and prescribed
// values. The matrices must agree entry by entry and the right-hand sides to roundoff.

#include "reference/solver/cell_matrix_scatter.hpp"

#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>

#include <gtest/gtest.h>

#include <random>

namespace kerf::reference {
namespace {

class CellMatrixScatterDegrees : public ::testing::TestWithParam<unsigned> {};

TEST_P(CellMatrixScatterDegrees, AddsWhatDistributeLocalToGlobalAdds) {
  dealii::Triangulation<3> tria;
  dealii::GridGenerator::subdivided_hyper_cube_with_simplices(tria, 2);
  dealii::FESystem<3> fe(dealii::FE_SimplexP<3>(GetParam()), 3);
  dealii::DoFHandler<3> dof(tria);
  dof.distribute_dofs(fe);
  // Dirichlet DOFs: every DOF of the cells touching the boundary face x = 0, with values.
  std::mt19937 random(11);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  dealii::AffineConstraints<double> constraints;
  std::vector<dealii::types::global_dof_index> local(fe.n_dofs_per_cell());
  for (const auto& cell : dof.active_cell_iterators())
    for (const unsigned f : cell->face_indices())
      if (cell->face(f)->at_boundary() && cell->face(f)->center()[0] < 1e-12) {
        std::vector<dealii::types::global_dof_index> face_dofs(fe.n_dofs_per_face(f));
        cell->face(f)->get_dof_indices(face_dofs);
        for (const auto i : face_dofs)
          if (!constraints.is_constrained(i)) {
            constraints.add_line(i);
            constraints.set_inhomogeneity(i, value(random));
          }
      }
  constraints.close();
  ASSERT_GT(constraints.n_constraints(), 0u);
  dealii::DynamicSparsityPattern dsp(dof.n_dofs());
  dealii::DoFTools::make_sparsity_pattern(dof, dsp, constraints, false);
  dealii::SparsityPattern pattern;
  pattern.copy_from(dsp);
  dealii::SparseMatrix<double> K_dealii(pattern), K_scatter(pattern);
  dealii::Vector<double> r_dealii(dof.n_dofs()), r_scatter(dof.n_dofs());
  CellMatrixScatter scatter;
  scatter.build(dof, pattern);
  double* values = CellMatrixScatter::values(K_scatter);
  const unsigned n = fe.n_dofs_per_cell();
  dealii::FullMatrix<double> Kc(n, n);
  dealii::Vector<double> rc(n);
  int cell_number = 0;
  for (const auto& cell : dof.active_cell_iterators()) {
    cell->get_dof_indices(local);
    for (unsigned i = 0; i < n; ++i) {
      rc(i) = value(random);
      for (unsigned j = 0; j < n; ++j) Kc(i, j) = value(random);
    }
    // Some cells with zero diagonal entries (deal.II's mean-diagonal rule for a constrained row).
    if (cell_number++ % 3 == 0)
      for (unsigned i = 0; i < n; i += 2) Kc(i, i) = 0.0;
    constraints.distribute_local_to_global(Kc, rc, local, K_dealii, r_dealii);
    scatter.add(cell->active_cell_index(), Kc, rc, local, constraints, values, r_scatter);
  }
  for (auto e = K_dealii.begin(); e != K_dealii.end(); ++e)
    EXPECT_EQ(e->value(), K_scatter(e->row(), e->column())) << "entry (" << e->row() << ", " << e->column() << ")";
  for (dealii::types::global_dof_index i = 0; i < dof.n_dofs(); ++i)
    EXPECT_NEAR(r_scatter(i), r_dealii(i), 1e-13 * (1.0 + std::abs(r_dealii(i)))) << "DOF " << i;
}

INSTANTIATE_TEST_SUITE_P(Degrees, CellMatrixScatterDegrees, ::testing::Values(1u, 2u));

} // namespace
} // namespace kerf::reference
