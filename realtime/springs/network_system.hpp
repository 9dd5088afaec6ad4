#pragma once
// NetworkSystem: the sparse symmetric system A = w_m M + w_k K_T of a spring network over its
// free degrees of freedom, assembled into a fixed pattern and factorised by a supernodal
// Cholesky: CHOLMOD's symbolic analysis (SuiteSparse; Chen, Davis, Hager & Rajamanickam,
// "CHOLMOD, supernodal sparse Cholesky factorization and update/downdate", ACM TOMS 35(3), 2008)
// and kerf's own numeric phase on its structure (supernodal_cholesky.hpp: CHOLMOD's would
// allocate inside libgomp). The fill-reducing ordering and the symbolic analysis are done once
// per pattern (`rebuild`, which allocates); assembly, numeric factorisation and solves then
// reuse them and allocate nothing, which the realtime `step` needs (docs/spring-network.md,
// "Linear solver").

#include "realtime/springs/spring_network.hpp"
#include "realtime/springs/supernodal_cholesky.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <array>
#include <cstdint>
#include <vector>

struct cholmod_common_struct;
struct cholmod_factor_struct;

namespace kerf {

class NetworkSystem {
public:
  /// Lower triangle stored, rows and columns in the factor's (fill-reducing) order.
  using Matrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

  /// What the triangular solves read and compute in: CHOLMOD's factor itself in double
  /// precision, or (single precision) per supernode the inverse T_s⁻¹ of its diagonal triangle
  /// (computed in double from the factor after each factorisation) and the rows R_s below it,
  /// both stored in single precision and applied with single-precision arithmetic (half the
  /// memory traffic, twice the SIMD lanes, and no sequential triangle inside a supernode); for
  /// a factor used as the approximate Jacobian of modified Newton, whose residual is evaluated
  /// in double precision: the solve's relative error, ~κ(A) 10⁻⁷, only slows its linear
  /// convergence by that much.
  enum class SolvePrecision { double_precision, single_precision };

  explicit NetworkSystem(SolvePrecision precision = SolvePrecision::double_precision);
  /// Builds the pattern for `net` (see `rebuild`).
  explicit NetworkSystem(const SpringNetwork& net, SolvePrecision precision = SolvePrecision::double_precision);
  ~NetworkSystem();
  NetworkSystem(const NetworkSystem&) = delete;
  NetworkSystem& operator=(const NetworkSystem&) = delete;

  /// Numbers the free degrees of freedom (axes not fixed by NodeConstraint) of the nodes in use,
  /// orders them to reduce fill (the lattice's geometric nested dissection, or AMD where that
  /// gives a smaller factor; both deterministic), lets CHOLMOD find the supernodes on the cell-coupling pattern, and sizes every workspace that
  /// `factorize` and `solve` use. Allocates; call again whenever cells, nodes or constraints
  /// change (a tear).
  ///
  /// `tear_ready`: the pattern also holds a shadow of every free degree of freedom, coupled like
  /// its node (every pair of nodes sharing a cell couples node and shadow alike), so that a
  /// vertex split (VertexTearing: the copy takes the original's rest position and constraint,
  /// each vertex splits once) is bound by `bind_split_vertices` without a new analysis. Unused
  /// shadows get a unit diagonal (decoupled, solution zero). The factor is larger (about twice
  /// the dofs, four times the entries). Needs an untorn network.
  void rebuild(const SpringNetwork& net, bool tear_ready = false) {
    rebuild(net, tear_ready ? SplitRoom::coupled_shadows : SplitRoom::none);
  }

  /// Room for vertex splits in the system (`rebuild`).
  enum class SplitRoom {
    none,            ///< the network's own dofs
    coupled_shadows, ///< `tear_ready` above: splits bound into the pattern, any later assembly takes them
    /// Each node that has not split (no other node at its lattice point; the network may be
    /// torn already) gets a shadow that stays decoupled: its dofs come after every node's, outside
    /// the Cholesky factor, as a diagonal block of their own (half the node's diagonal, as an
    /// unused coupled shadow gets). A split binds the copy to its original's shadow dofs without
    /// re-placing any entry (`bind_split_vertices`), so the system is then the matrix before the
    /// split, for a kept factor that SplitCorrection corrects; assembling it again needs a
    /// `rebuild` (`factorize` says false until then). The factor is the network's own size.
    decoupled_shadows
  };
  /// `check_mass`: end with a factorisation of the lumped mass matrix, which must succeed (a
  /// check that every mass is positive); false for a caller that assembles and factorises the
  /// system next anyway (the factor refresh's worker), which then makes that check.
  void rebuild(const SpringNetwork& net, SplitRoom room, bool check_mass = true);

  /// After vertex splits on a system with room for them: gives each new node (a copy) its
  /// original's shadow dofs and, with coupled shadows, re-places the entries of the cells whose
  /// corners changed. Allocation-free. False if the system has no room or a split does not fit
  /// the shadows (a second copy of a vertex, a changed constraint): then `rebuild` is needed.
  bool bind_split_vertices(const SpringNetwork& net) noexcept;
  /// Decoupled shadows (SplitRoom::decoupled_shadows): the dofs [0, factor_dofs()) are in the
  /// Cholesky factor, the rest are the decoupled shadows' (a diagonal block). Otherwise dof_count().
  [[nodiscard]] int factor_dofs() const { return m_factor_dofs; }
  [[nodiscard]] SplitRoom split_room() const { return m_room; }

  /// The fill-reducing ordering `rebuild` chose: the lattice's nested dissection, or AMD when
  /// that gave the smaller factor (or a node is off the block's lattice).
  enum class FillOrdering { lattice_nested_dissection, amd };
  [[nodiscard]] FillOrdering fill_ordering() const { return m_ordering; }

  /// Number of free degrees of freedom.
  [[nodiscard]] int dof_count() const { return static_cast<int>(m_matrix.rows()); }
  /// Free dof of node n's axis i (entry 3 n + i), or -1 when fixed; in the factor's ordering.
  [[nodiscard]] const std::vector<int>& dof_of() const { return m_dof_of; }

  /// A = mass_weight M + stiffness_weight K_T(x) (K_T from cell_stiffness_matrix with `tangent`,
  /// lumped M). An unused shadow (tear-ready) gets half its node's diagonal and no coupling: any
  /// positive value leaves the solution unchanged (its equation is decoupled, its right-hand
  /// side zero), and this one makes the factor a fair approximation of the system after the
  /// node splits (each half of its cells takes about half of its diagonal), for a factor kept
  /// across a split (NewtonStepper).
  void assemble(const SpringNetwork& net, const Eigen::Matrix3Xd& x, double mass_weight, double stiffness_weight,
                CellTangent tangent = CellTangent::projected) noexcept;
  /// Numeric supernodal LLᵀ of the assembled A on the analysed pattern (SupernodalCholesky on
  /// the matrix already in the factor's order, OpenBLAS on one thread; allocation-free), and the
  /// decoupled shadows' diagonal block. False if A is not positive definite, or if splits were
  /// bound to decoupled shadows since the last `rebuild` (the assembled matrix would not be the
  /// torn network's).
  bool factorize() noexcept;
  /// out = A⁻¹ rhs with the last factorisation (both of size dof_count(); out is not resized).
  /// Double precision: L y = rhs, then Lᵀ out = y, supernode by supernode on CHOLMOD's
  /// supernodal L (dense column-major blocks): per supernode the diagonal triangle, then the
  /// rows below it as one dense product, four columns per pass, in loops the compiler
  /// vectorises, with no BLAS call and no division (1/L_kk is kept) per supernode (most
  /// supernodes of a network are small, where the call overhead dominated cholmod_solve2).
  /// Single precision (rhs and out converted once), with each supernode's T_s⁻¹ and R_s (see
  /// SolvePrecision):
  ///   forward,  y_s ← T_s⁻¹ y_s,  y_b −= R_s y_s;   backward,  x_s ← T_s⁻ᵀ (x_s − R_sᵀ x_b),
  /// each a dense matrix-vector product of independent columns (four per pass).
  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& out) noexcept;
  /// SolvePrecision::single_precision: `solve` without the conversions, on the solve's own
  /// single-precision vector (dof_count() floats, in the factor's order): fill
  /// `single_precision_vector()` with the right-hand side, call `solve_in_place`, read A⁻¹ rhs
  /// from the same vector (for a caller whose right-hand side is in single precision already,
  /// the linearly implicit step's lattice forces). Allocation-free. False (nothing solved) with
  /// SolvePrecision::double_precision.
  [[nodiscard]] float* single_precision_vector() noexcept { return m_solution_single.data(); }
  bool solve_in_place() noexcept;
  /// SolvePrecision::single_precision: the forward half of `solve_in_place` alone, y ← L⁻¹ y,
  /// on a caller's vector of dof_count() floats (in the factor's order; `y` needs room for 16
  /// more). Supernodes whose part of y is zero on entry to them are skipped, so a sparse y
  /// costs only the supernodes on its elimination-tree paths. False with double precision.
  bool forward_solve_in_place(float* y) noexcept;
  /// The backward half, x ← L⁻ᵀ x, on a caller's vector as for `forward_solve_in_place`.
  bool backward_solve_in_place(float* x) noexcept;

  /// The assembled matrix (lower triangle stored): after `factorize`, the matrix the factor is of.
  [[nodiscard]] const Matrix& matrix() const { return m_matrix; }
  /// Entry (d, d) of the assembled matrix.
  [[nodiscard]] double diagonal(int d) const { return m_matrix.valuePtr()[m_diagonal[static_cast<std::size_t>(d)]]; }
  /// The factor's supernodes: their count, and the first column of each (supernode_start(count)
  /// = dof_count()); each decoupled shadow dof counts as a supernode of one column.
  [[nodiscard]] int supernode_count() const;
  [[nodiscard]] int supernode_start(int s) const;
  /// Nodes bound so far (rebuild, then each `bind_split_vertices`).
  [[nodiscard]] int bound_nodes() const { return m_bound_nodes; }
  /// Entries of the factor L (0 before `rebuild`).
  [[nodiscard]] double factor_entries() const;

private:
  void release() noexcept;
  /// Index of entry (r, c) of the lower triangle in the matrix's values, or −1.
  [[nodiscard]] int value_index(int r, int c) const noexcept;
  /// The value slots of one cell's 24 x 24 entries from its current corners; false if one is
  /// missing from the pattern.
  bool bind_cell(const SpringNetwork& net, int cell) noexcept;
  /// Sizes the numeric factorisation's and the solve's workspaces for the analysed factor (`rebuild`).
  void size_solve_workspaces();
  /// v_d ← v_d (A_dd)^(−power/2) on the decoupled shadows' dofs (the diagonal block's L = √A_dd:
  /// power 1 for one triangular solve, 2 for both).
  template <class Value>
  void scale_decoupled_shadows(Value* v, int power) const noexcept;

  std::vector<int> m_dof_of;
  Matrix m_matrix;
  /// Per cell, 24 x 24 entries: index into m_matrix's values of (row, col), or -1 (fixed dof or
  /// upper triangle).
  std::vector<int> m_entry;
  std::vector<int> m_diagonal; ///< value index of each dof's diagonal
  std::vector<int> m_shadow_of;             ///< tear-ready: shadow dof of node n's axis i (3 n + i), or −1
  std::vector<std::uint8_t> m_dof_in_use;   ///< per dof: 0 for a shadow no copy has taken yet
  SplitRoom m_room = SplitRoom::none;
  int m_factor_dofs = 0;                    ///< dofs in the Cholesky factor (the rest: decoupled shadows)
  bool m_bound_decoupled = false;           ///< a split bound to a decoupled shadow since `rebuild`
  std::vector<double> m_shadow_inverse_root; ///< decoupled shadows: 1 / √A_dd, dof d = factor_dofs() + k
  std::vector<int> m_node_at_point;         ///< tear-ready: the original node at each lattice point
  std::vector<std::array<int, 8>> m_bound_cells; ///< the cell corners the entries were placed for
  int m_bound_nodes = 0;
  cholmod_common_struct* m_common = nullptr;
  cholmod_factor_struct* m_factor = nullptr;
  SolvePrecision m_precision;
  /// single_precision: each supernode's T_s⁻¹ and R_s in panels of four columns (panel c holds
  /// columns c..c+3: T_s⁻¹'s rows c..nscol−1, then R_s's rows, column-major, each part
  /// zero-padded to whole 16-float vectors, zero past the last column), where each
  /// supernode's panels start (from the 64-byte aligned entry m_inverse_align).
  std::vector<float> m_inverse_blocks;
  int m_inverse_align = 0;
  std::vector<std::ptrdiff_t> m_inverse_block_at;
  std::vector<double> m_inverse_column; ///< four columns of a W_s in double (factorize)
  std::vector<double> m_below;         ///< solve workspace: the rows below one supernode
  std::vector<double> m_dots;          ///< solve workspace: one supernode's column dot products
  std::vector<double> m_inverse_diagonal; ///< 1 / L_kk of the last factorisation
  /// single_precision: the solution and one supernode's rows in single precision (its
  /// triangle's rows first, the rows below from m_rows_split).
  std::vector<float> m_solution_single, m_rows_single;
  int m_rows_split = 0;
  SupernodalCholesky m_numeric; ///< the numeric factorisation's workspaces
  bool m_factorized = false;
  FillOrdering m_ordering = FillOrdering::amd;
};

} // namespace kerf
