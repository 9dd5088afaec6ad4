#pragma once
// SplitCorrection: a kept factor of a tear-ready NetworkSystem made exact again for the vertex
// splits made since its matrix was assembled, by the Sherman–Morrison–Woodbury formula
// (Woodbury, "Inverting modified matrices", 1950; Hager, "Updating the inverse of a matrix",
// SIAM Review 31(2), 1989), so that Newton keeps converging on the kept factor while a fresh
// one is computed off the servo thread (FactorRefresh).
//
// A split of node p into p and its copy p' (VertexTearing) moves the cells of one side, C₂, from
// p to p'. In the tear-ready pattern p' is p's shadow, assembled as a decoupled unknown; the
// split changes only the rows and columns of p and p':
//   ΔA(p, p)  = −w_k Σ_{C₂} K_c(p, p) − w_m (m_p,before − m_p) I,
//   ΔA(p', p') = w_k Σ_{C₂} K_c(p, p) + w_m m_p' I − A_kept(p', p'),
//   ΔA(p, N)  = −B,  ΔA(p', N) = +B,   B = w_k Σ_{c ∈ C₂} K_c(p, N),
// N the other corners of C₂ (K_c the cell stiffness at the current positions, with the kept
// factor's tangent; w_m, w_k the kept matrix's weights). With S the free dofs of p and p' (r
// free axes each), E = U_S [−I; I] and V = U_N Bᵀ,
//   ΔA = U_S D U_Sᵀ + E Vᵀ + V Eᵀ = W C Wᵀ,  W = [U_S, V] (n x 3r),  C = [[D, J], [Jᵀ, 0]],
// J = [−I; I]: a rank-3r term. For the splits so far W = [W₁ …], C = diag(C₁ …), and
//   (P + W C Wᵀ)⁻¹ b = y − P⁻¹ W H⁻¹ C Wᵀ y,  y = P⁻¹ b,  H = I + C (Wᵀ P⁻¹ W),
// where Wᵀ P⁻¹ W = Fᵀ F with F = L⁻¹ W (forward substitutions of W's sparse columns, costing
// only the supernodes on their elimination-tree paths, P = L Lᵀ; the products Fᵀ F run over the
// supernodes both columns reach). Each split costs 3r such forward substitutions and the new rows
// of Fᵀ F. A solve with pending splits costs one solve with P, split in its halves:
//   (P + W C Wᵀ)⁻¹ b = L⁻ᵀ (y − F t),  y = L⁻¹ b,  t = H⁻¹ C Fᵀ y
// (Wᵀ P⁻¹ b = Fᵀ L⁻¹ b and P⁻¹ W t = L⁻ᵀ F t), F's columns read over the supernodes they reach.
// Allocation-free after `reserve`.

#include "realtime/springs/cell_stiffness.hpp"
#include "realtime/springs/network_system.hpp"
#include "realtime/springs/spring_network.hpp"

#include <Eigen/Core>

#include <vector>

namespace kerf {

class SplitCorrection {
public:
  /// Splits a correction holds (beyond that the caller must refresh the factor).
  static constexpr int max_splits = 16;
  /// Columns of W per split (3r, r ≤ 3 free axes).
  static constexpr int max_columns_per_split = 9;
  static constexpr int max_columns = max_splits * max_columns_per_split;
  /// Other corners of the moved cells: at most the 26 neighbours of a lattice point.
  static constexpr int max_neighbours = 26;

  /// Sizes the workspaces for systems of up to `dofs` unknowns (allocates). The first split after
  /// `clear` takes the size of the system it corrects.
  void reserve(int dofs);
  /// No split pending: the kept factor is exact for the topology.
  void clear() noexcept { m_splits = 0; m_columns = 0; }
  [[nodiscard]] int splits() const noexcept { return m_splits; }
  [[nodiscard]] bool full() const noexcept { return m_splits >= max_splits; }

  /// Adds the split of node `original` into `copy` (already bound in `system`, whose factor is
  /// the kept one, `system.matrix()` the matrix it factorised); `mass_before` is the original's
  /// mass before the split [kg]; `mass_weight`, `stiffness_weight` and `tangent` those of the
  /// kept matrix; x the positions at which the moved cells' stiffness is taken (the kept
  /// matrix's own). False (nothing added) when full or when H is singular; then the splits
  /// added before stay corrected for, or, if H of those alone is singular too, none does.
  /// Allocation-free.
  /// `later` lists the splits made after this one, as (copy, original) node pairs (a split
  /// corrected for after later ones, when a factor assembled before it is adopted): the cells are
  /// then taken with those copies' corners back at their originals, as they were at this split.
  struct NodePair {
    int copy = -1, original = -1;
  };
  bool add(NetworkSystem& system, const SpringNetwork& net, const Eigen::Matrix3Xd& x, int original, int copy,
           double mass_before, double mass_weight, double stiffness_weight, CellTangent tangent,
           const NodePair* later = nullptr, int later_count = 0) noexcept;

  /// out = (P + W C Wᵀ)⁻¹ rhs with the kept factor P of `system`: one forward and one backward
  /// substitution, and with pending splits two products with F's reached rows between them.
  /// `out` has the system's size. Allocation-free.
  void solve(NetworkSystem& system, const Eigen::VectorXd& rhs, Eigen::VectorXd& out) noexcept;

private:
  /// H = I + C G, factorised in place with partial pivoting (LAPACK's dgetrf algorithm, on the
  /// preallocated m x m leading block): false if a pivot is zero or not finite.
  bool factor_h(int m) noexcept;
  /// x ← H⁻¹ x with that factor.
  void solve_h(double* x) const noexcept;
  /// One split's W: S (its dofs: the original's r free axes, then the copy's), N and B (r x |N|).
  struct Split {
    int r = 0;
    int s[6] = {};
    int neighbours = 0;
    int n[3 * max_neighbours] = {};
    double b[3][3 * max_neighbours] = {};
    double d[6][6] = {};
  };
  /// Column j of W (a split's unit column of S, or a column of V) into the dense float vector v.
  void column_of_w(int split, int j, float* v) const noexcept;

  int m_capacity = 0; ///< dofs the workspaces hold
  int m_dofs = 0;     ///< dofs of the system corrected
  int m_splits = 0;
  int m_columns = 0;
  Split m_split[max_splits];
  std::vector<float> m_f;       ///< F = L⁻¹ W, column j at j (dofs + 16)
  /// Per split, the column ranges [begin, end) of the supernodes its F columns reach (at most
  /// one range per supernode, merged where contiguous), and how many.
  std::vector<int> m_ranges;
  int m_range_count[max_splits] = {};
  std::vector<float> m_y_single; ///< solve workspace: L⁻¹ b, then L⁻ᵀ (L⁻¹ b − F t) (dofs + 16)
  Eigen::MatrixXd m_g;          ///< Fᵀ F (max_columns square, the leading block in use)
  Eigen::MatrixXd m_c;          ///< C = diag(C₁ …)
  Eigen::MatrixXd m_h;          ///< H = I + C Fᵀ F, then its LU factors
  std::vector<int> m_pivot;     ///< H's row interchanges
  Eigen::VectorXd m_u, m_t;     ///< Wᵀ y and H⁻¹ C Wᵀ y
};

} // namespace kerf
