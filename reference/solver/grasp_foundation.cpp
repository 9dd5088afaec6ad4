// Elastic foundations (FiniteStrainProblem::foundations): a surface held by a compliant layer to an
// anchor that moves by d(X, λ), the compliant grasp of a stylus (docs/scenes.md "Grasp"). On the
// foundation's faces, per unit reference area, the layer's energy is ½ k |u − d|², its traction on
// the body t = k (d − u), k = k(X) the layer's stiffness (uniform, or the foundation's profile
// times its stiffness); so, with the face's shape functions N_a (component c_a),
//   f_ext,a += ∫ N_a t_{c_a} dA,   K_ab += k ∫ N_a N_b dA δ(c_a, c_b)
// (R = f_int − f_ext, ∂R/∂u = −∂f_ext/∂u). The term is linear in u: Newton stays quadratic. The
// faces and the traction are those of the reference configuration (a layer whose stiffness is
// per reference area, as the tie is a condition on reference points).

#include "reference/solver/finite_strain_impl.hpp"

#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/full_matrix.h>

#include <cmath>
#include <stdexcept>

namespace kerf::reference {

void FiniteStrainSolver::Impl::build_foundations(const FiniteStrainProblem& problem) {
  for (const ElasticFoundation& e : problem.foundations) {
    const auto it = std::find(surface_names.begin(), surface_names.end(), e.surface);
    if (it == surface_names.end())
      throw std::invalid_argument("finite strain solver: elastic foundation surface '" + e.surface +
                                  "' is not a surface group of the mesh");
    if (!(e.stiffness > 0.0) || !std::isfinite(e.stiffness))
      throw std::invalid_argument("finite strain solver: elastic foundation '" + e.surface +
                                  "': stiffness must be a finite k > 0 N/m^3, got " + std::to_string(e.stiffness));
    if (!e.displacement)
      throw std::invalid_argument("finite strain solver: elastic foundation '" + e.surface + "' has no displacement");
    const int group = static_cast<int>(it - surface_names.begin());
    if (!(surface_area(group) > 0.0))
      throw std::invalid_argument("finite strain solver: elastic foundation surface '" + e.surface + "' has no area");
    foundations.push_back({group, e.stiffness, e.displacement, e.profile});
  }
}

template <class VectorType, class MatrixType, class Tally>
void FiniteStrainSolver::Impl::assemble_foundations(const dealii::Vector<double>& state, const LoadState& load, bool with_matrix,
                                                    Tally& out, const dealii::AffineConstraints<double>* constraints,
                                                    MatrixType& K, VectorType* rhs, VectorType& f_ext) const {
  out.foundation_on_body.assign(foundations.size(), Eigen::Vector3d::Zero());
  out.foundation_energy = 0.0;
  if (foundations.empty()) return;
  const unsigned n = fe->n_dofs_per_cell();
  dealii::FEFaceValues<3> ffv(*mapping, *fe, *face_quadrature,
                              dealii::update_values | dealii::update_quadrature_points | dealii::update_JxW_values);
  const dealii::FEValuesExtractors::Vector disp(0);
  std::vector<dealii::Tensor<1, 3>> face_u(face_quadrature->size());
  dealii::FullMatrix<double> cell_K(n, n);
  dealii::Vector<double> cell_ext(n);
  std::vector<dealii::types::global_dof_index> local(n);
  std::vector<unsigned> comp(n);
  for (unsigned i = 0; i < n; ++i) comp[i] = fe->system_to_component_index(i).first;
  std::vector<double> N(n);
  for (const auto& cell : dof.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue; // distributed: another process assembles it
    bool touched = false;
    cell_K = 0.0;
    cell_ext = 0.0;
    for (const unsigned f : cell->face_indices()) {
      if (!cell->face(f)->at_boundary()) continue;
      const auto id = cell->face(f)->boundary_id();
      for (std::size_t e = 0; e < foundations.size(); ++e) {
        const Foundation& fd = foundations[e];
        if (!in_group(id, fd.group)) continue;
        touched = true;
        ffv.reinit(cell, f);
        ffv[disp].get_function_values(state, face_u);
        for (unsigned q = 0; q < ffv.n_quadrature_points; ++q) {
          const double JxW = ffv.JxW(q);
          const Eigen::Vector3d X = to_eigen(ffv.quadrature_point(q));
          const Eigen::Vector3d u(face_u[q][0], face_u[q][1], face_u[q][2]);
          const double k = fd.profile ? fd.stiffness * fd.profile(X) : fd.stiffness; // k(X)
          if (!(k > 0.0)) continue;
          const Eigen::Vector3d gap = fd.displacement(X, load.load_factor) - u; // d − u
          const Eigen::Vector3d t = k * gap;                                    // on the body
          out.foundation_on_body[e] += t * JxW;
          out.foundation_energy += 0.5 * k * gap.squaredNorm() * JxW;
          for (unsigned i = 0; i < n; ++i) N[i] = ffv.shape_value_component(i, q, comp[i]);
          for (unsigned i = 0; i < n; ++i) {
            if (N[i] == 0.0) continue;
            cell_ext(i) += N[i] * t[comp[i]] * JxW;
            if (!with_matrix) continue;
            for (unsigned j = 0; j < n; ++j)
              if (comp[j] == comp[i]) cell_K(i, j) += k * N[i] * N[j] * JxW;
          }
        }
      }
    }
    if (!touched) continue;
    cell->get_dof_indices(local);
    f_ext.add(local, cell_ext);
    // K += k ∫ N_a N_b dA, rhs += f_ext (rhs = f_ext − f_int)
    if (with_matrix) constraints->distribute_local_to_global(cell_K, cell_ext, local, K, *rhs);
  }
}

// For the two algebras (algebra.hpp); the assembly calls them (assemble_system.cpp).
template void FiniteStrainSolver::Impl::assemble_foundations(const dealii::Vector<double>&, const LoadState&, bool,
                                                             Assembly<SerialAlgebra::VectorType>&,
                                                             const dealii::AffineConstraints<double>*,
                                                             SerialAlgebra::MatrixType&, SerialAlgebra::VectorType*,
                                                             SerialAlgebra::VectorType&) const;
template void FiniteStrainSolver::Impl::assemble_foundations(const dealii::Vector<double>&, const LoadState&,
                                                             bool, Assembly<DistributedAlgebra::VectorType>&,
                                                             const dealii::AffineConstraints<double>*,
                                                             DistributedAlgebra::MatrixType&,
                                                             DistributedAlgebra::VectorType*,
                                                             DistributedAlgebra::VectorType&) const;

} // namespace kerf::reference
