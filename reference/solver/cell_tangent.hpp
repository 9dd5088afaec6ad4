#pragma once
// The element tangent of the total-Lagrangian displacement formulation, one quadrature point at a
// time, in blocks of component pairs (used by assemble_system.cpp).
//
// With the shape gradients G = [Grad N_1 … Grad N_n] (3 × n, with respect to X) and the first
// elasticity tensor 𝔸 = ∂P/∂F stored as the 9 × 9 matrix A(3c+I, 3d+J) = 𝔸_cIdJ, the stiffness
// between node a's component c and node b's component d is
//
//   K_(a,c)(b,d) = ∫ Grad N_a · 𝔸_c·d· Grad N_b dV = Σ_q JxW_q Σ_IJ G_Ia A(3c+I, 3d+J) G_Jb,
//
// so the n × n block of the pair (c, d) is K_cd += JxW Gᵀ A_cd G with A_cd the 3 × 3 block of A.
// Written as the 9 × n product A(:, 3d..3d+2) G followed by one n × 3 times 3 × n product per c,
// every product has fixed sizes that Eigen unrolls and vectorises (n = 4 for linear, 10 for quadratic
// tetrahedra). A hyperelastic 𝔸 has the major symmetry 𝔸_cIdJ = 𝔸_dJcI, so K_dc = K_cdᵀ and only
// the blocks c <= d are computed; a tangent without it (Kelvin–Voigt damping) computes all nine.

#include <Eigen/Core>

#include <array>

namespace kerf::reference {

/// The nine n × n blocks K_cd of one cell's tangent (n at most 10: quadratic tetrahedra), node by
/// node: block (c, d) entry (a, b) couples node a's component c with node b's component d.
struct CellTangentBlocks {
  static constexpr int max_nodes = 10;
  using Block = Eigen::Matrix<double, max_nodes, max_nodes>;
  std::array<Block, 9> block;

  /// Zero the blocks' top-left nodes × nodes corners (the only part add() and complete_lower() touch).
  void set_zero(int nodes) {
    for (Block& b : block) b.topLeftCorner(nodes, nodes).setZero();
  }
  [[nodiscard]] Block& operator()(int c, int d) { return block[3 * c + d]; }
  [[nodiscard]] const Block& operator()(int c, int d) const { return block[3 * c + d]; }

  /// K_cd += JxW Gᵀ A_cd G for one quadrature point: G the N node gradients, 3 doubles each, node
  /// after node (3 × N column-major); A the 9 × 9 tangent; with `symmetric`, the blocks c <= d only
  /// (complete_lower() fills the others once per cell).
  template <int N>
  void add(const double* gradients, const Eigen::Matrix<double, 9, 9>& A, double JxW, bool symmetric) {
    static_assert(N <= max_nodes);
    const Eigen::Map<const Eigen::Matrix<double, 3, N>> G(gradients);
    for (int d = 0; d < 3; ++d) {
      // lazyProduct: coefficient by coefficient with fixed sizes, unrolled and vectorised (a plain
      // product of these sizes goes through Eigen's blocked GEMM, built for large matrices)
      const Eigen::Matrix<double, 9, N> AG = JxW * A.template middleCols<3>(3 * d).lazyProduct(G); // rows 3c+I
      for (int c = 0; c < (symmetric ? d + 1 : 3); ++c)
        (*this)(c, d).template topLeftCorner<N, N>() += G.transpose().lazyProduct(AG.template middleRows<3>(3 * c));
    }
  }

  /// K_dc = K_cdᵀ for c < d: the blocks add() left out for a symmetric tangent.
  void complete_lower(int nodes) {
    for (int d = 0; d < 3; ++d)
      for (int c = 0; c < d; ++c) (*this)(d, c).topLeftCorner(nodes, nodes) = (*this)(c, d).topLeftCorner(nodes, nodes).transpose();
  }
};

} // namespace kerf::reference
