#pragma once
// NetworkSystem: the sparse symmetric system A = w_m M + w_k K_T of a spring network over its
// free degrees of freedom, assembled into a fixed pattern and factorised by CHOLMOD's supernodal
// Cholesky (SuiteSparse; Chen, Davis, Hager & Rajamanickam, "CHOLMOD, supernodal sparse Cholesky
// factorization and update/downdate", ACM TOMS 35(3), 2008). The fill-reducing ordering and the
// symbolic analysis are done once per pattern (`rebuild`, which allocates); assembly, numeric
// factorisation and solves then reuse them and allocate nothing, which the realtime `step`
// needs (docs/spring-network.md, "Linear solver").

#include "realtime/springs/spring_network.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <vector>

struct cholmod_common_struct;
struct cholmod_factor_struct;
struct cholmod_dense_struct;

namespace kerf {

class NetworkSystem {
public:
  /// Lower triangle stored, rows and columns in the factor's (fill-reducing) order.
  using Matrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

  NetworkSystem();
  /// Builds the pattern for `net` (see `rebuild`).
  explicit NetworkSystem(const SpringNetwork& net);
  ~NetworkSystem();
  NetworkSystem(const NetworkSystem&) = delete;
  NetworkSystem& operator=(const NetworkSystem&) = delete;

  /// Numbers the free degrees of freedom (axes not fixed by NodeConstraint) of the nodes in use,
  /// lets CHOLMOD choose the fill-reducing ordering (AMD, or METIS/NESDIS when they give less
  /// fill) and the supernodes on the cell-coupling pattern, and sizes every workspace that
  /// `factorize` and `solve` use. Allocates; call again whenever cells, nodes or constraints
  /// change (a tear).
  void rebuild(const SpringNetwork& net);

  /// Number of free degrees of freedom.
  [[nodiscard]] int dof_count() const { return static_cast<int>(m_matrix.rows()); }
  /// Free dof of node n's axis i (entry 3 n + i), or -1 when fixed; in the factor's ordering.
  [[nodiscard]] const std::vector<int>& dof_of() const { return m_dof_of; }

  /// A = mass_weight M + stiffness_weight K_T(x) (K_T from cell_stiffness_matrix, lumped M).
  void assemble(const SpringNetwork& net, const Eigen::Matrix3Xd& x, double mass_weight, double stiffness_weight) noexcept;
  /// Numeric supernodal LLᵀ of the assembled A on the analysed pattern (cholmod_super_numeric on
  /// the matrix already in the factor's order, so no permuted copy is made; its one temporary,
  /// the supernode update block, comes from a buffer this object keeps). False if A is not
  /// positive definite.
  bool factorize() noexcept;
  /// out = A⁻¹ rhs with the last factorisation (both of size dof_count(); out is not resized).
  /// cholmod_solve2 with the solution and workspaces kept between calls.
  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& out) noexcept;

  /// The assembled matrix (lower triangle stored).
  [[nodiscard]] const Matrix& matrix() const { return m_matrix; }
  /// Entries of the factor L (0 before `rebuild`).
  [[nodiscard]] double factor_entries() const;

private:
  void release() noexcept;

  std::vector<int> m_dof_of;
  Matrix m_matrix;
  /// Per cell, 24 x 24 entries: index into m_matrix's values of (row, col), or -1 (fixed dof or
  /// upper triangle).
  std::vector<int> m_entry;
  std::vector<int> m_diagonal; ///< value index of each dof's diagonal
  cholmod_common_struct* m_common = nullptr;
  cholmod_factor_struct* m_factor = nullptr;
  cholmod_dense_struct* m_rhs = nullptr;
  cholmod_dense_struct* m_solution = nullptr;
  cholmod_dense_struct* m_work_y = nullptr;
  cholmod_dense_struct* m_work_e = nullptr;
  std::vector<double> m_update_buffer; ///< CHOLMOD's supernode update workspace (see factorize)
  bool m_factorized = false;
};

} // namespace kerf
