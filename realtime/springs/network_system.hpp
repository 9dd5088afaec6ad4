#pragma once
// NetworkSystem: the sparse symmetric system A = w_m M + w_k K_T of a spring network over its
// free degrees of freedom, assembled into a fixed pattern and factorised by Eigen's simplicial
// sparse Cholesky (LDLᵀ). The fill-reducing ordering (AMD) and the symbolic analysis are done
// once per pattern (`rebuild`); assembly, numeric factorisation and solves then reuse them and
// allocate nothing, which the realtime `step` needs. (CHOLMOD allocates its workspace inside
// every factorisation, so it is not used on the hot path; docs/spring-network.md.)

#include "realtime/springs/spring_network.hpp"

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <vector>

namespace kerf {

class NetworkSystem {
public:
  using Matrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

  NetworkSystem() = default;
  /// Builds the pattern for `net` (see `rebuild`).
  explicit NetworkSystem(const SpringNetwork& net) { rebuild(net); }

  /// Numbers the free degrees of freedom (axes not fixed by NodeConstraint) of the nodes in use,
  /// orders them by approximate minimum degree (Amestoy, Davis & Duff 1996, Eigen::AMDOrdering),
  /// builds the upper-triangular pattern of the cell couplings and analyses it. Allocates; call
  /// again whenever cells, nodes or constraints change (a tear).
  void rebuild(const SpringNetwork& net);

  /// Number of free degrees of freedom.
  [[nodiscard]] int dof_count() const { return static_cast<int>(m_matrix.rows()); }
  /// Free dof of node n's axis i (entry 3 n + i), or -1 when fixed; in the factor's ordering.
  [[nodiscard]] const std::vector<int>& dof_of() const { return m_dof_of; }

  /// A = mass_weight M + stiffness_weight K_T(x) (K_T from cell_stiffness_matrix, lumped M).
  void assemble(const SpringNetwork& net, const Eigen::Matrix3Xd& x, double mass_weight, double stiffness_weight) noexcept;
  /// Numeric LDLᵀ of the assembled A on the analysed pattern; false if not positive definite.
  bool factorize() noexcept;
  /// out = A⁻¹ rhs with the last factorisation (both of size dof_count()).
  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& out) const noexcept;

  /// The assembled matrix (upper triangle stored).
  [[nodiscard]] const Matrix& matrix() const { return m_matrix; }

private:
  /// Simplicial LDLᵀ on a matrix already in fill-reducing order, factorised without the copy
  /// that SimplicialLDLT::factorize makes (it allocates a temporary).
  class PreorderedLdlt : public Eigen::SimplicialLDLT<Matrix, Eigen::Upper, Eigen::NaturalOrdering<int>> {
  public:
    void factorize_in_place(const Matrix& a) { this->template factorize_preordered<true>(a); }
    /// D of LDLᵀ by reference (SimplicialLDLT::vectorD() returns a copy, which allocates).
    [[nodiscard]] const Eigen::VectorXd& diagonal() const { return this->m_diag; }
  };

  std::vector<int> m_dof_of;
  Matrix m_matrix;
  /// Per cell, 24 x 24 entries: index into m_matrix's values of (row, col), or -1 (fixed dof or
  /// lower triangle).
  std::vector<int> m_entry;
  std::vector<int> m_diagonal; ///< value index of each dof's diagonal
  PreorderedLdlt m_ldlt;
  bool m_factorized = false;
};

} // namespace kerf
