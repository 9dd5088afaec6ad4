#pragma once
// SpringNetwork: paper 000 §2.1's coarse physical model — cubic cells joined at their vertices,
// 28 springs per cell (every pair of its 8 nodes), built on a block of N_x x N_y x N_z cells of
// which only the kept ones (those inside the body) exist. The springs of a cell belong to the
// cell: splitting a vertex (tearing, §2.2) only re-points the corners of some cells to a copy.

#include "realtime/springs/cell_stiffness.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace kerf {

/// The block of cells the network is cut from: cell (i, j, k) spans origin + h [i, i+1] x [j,
/// j+1] x [k, k+1] [m].
struct NetworkBlock {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero(); ///< lower corner [m]
  double cell_size = 0.0;                           ///< h [m] > 0
  Eigen::Vector3i cells = Eigen::Vector3i::Ones();  ///< cells along x, y, z (each >= 1)
};

/// The 28 springs of a cell as pairs of local corners. Local corner a = bx + 2 by + 4 bz sits at
/// origin + h (i + bx, j + by, k + bz); `type` is 1 (edge), 2 (face diagonal), 3 (body diagonal),
/// the number of axes along which the two corners differ.
struct CellSpring {
  int a, b, type;
};
extern const std::array<CellSpring, 28> cell_springs;

/// Node constraint bits: a fixed axis keeps the position the caller gives it (supports, tools).
enum NodeConstraint : std::uint8_t { fix_x = 1, fix_y = 2, fix_z = 4, fix_all = 7 };

/// The network's springs as flat arrays (structure of arrays) for the force loop: the 28 springs
/// of every cell, with parallel springs — the same two nodes and kind, an edge shared by up to
/// four cells, a face diagonal by two — merged into one of the summed constant (which halves the
/// springs of a full block). Sized for 28 springs per cell so that a rebuild after a tear
/// allocates nothing; springs [0, count) are in use.
struct SpringArrays {
  std::vector<int> a, b;       ///< end nodes
  std::vector<double> k;       ///< constant [N/m] (sum over the merged cells' springs)
  std::vector<double> rest;    ///< rest length L [m]
  /// The cells' spring keys (spring_key, 28 per cell), sorted: kept from one merge to the next,
  /// so that a split re-sorts only the keys it changes (merge_springs_after_split).
  std::vector<std::uint64_t> key;
  std::vector<std::uint64_t> key_merged; ///< workspace of merge_springs_after_split
  std::uint64_t key_topology = 0;        ///< the network's topology when `key` was sorted
  int count = 0;
};

/// The anchors of a compliant grasp (docs/spring-network.md §3, "Compliant grasp"): node[i] is
/// held by a zero-length spring of stiffness stiffness[i] [N/m], with the Kelvin–Voigt dashpot
/// τ K of the network's springs, to the point position.col(i) moving at velocity.col(i) [m, m/s]
/// (the tool's motion):
///   f = K (a − x) + τ K (ȧ − v)  on the node,  stored energy ½ K |a − x|².
/// Whoever moves the tools sets position and velocity; the force loops (network_forces,
/// LatticeForces), the stiffness matrix (NetworkSystem) and the explicit stability bounds include
/// the anchors. Anchored nodes are free (not constrained) and never split.
struct NodeAnchors {
  std::vector<int> node;
  std::vector<double> stiffness;
  Eigen::Matrix3Xd position = Eigen::Matrix3Xd(3, 0);
  Eigen::Matrix3Xd velocity = Eigen::Matrix3Xd(3, 0);
  [[nodiscard]] int count() const { return static_cast<int>(node.size()); }
};

/// The network (paper 000 §2.1). Node arrays are sized for `node_capacity()` so that tearing
/// can add copies of split vertices without allocating; nodes [0, node_count) are in use.
/// Whoever re-points `cell_nodes` (a tear) calls `merge_springs` (or, after one split,
/// `merge_springs_after_split`) afterwards.
struct SpringNetwork {
  NetworkBlock block;
  CellStiffness stiffness;
  double cell_mass = 0.0;     ///< ρ h³ [kg], lumped 1/8 on each corner
  double damping_time = 0.0;  ///< Kelvin–Voigt retardation time τ = η/E [s]: dashpot c = τ k per spring
  std::vector<Eigen::Vector3i> cell_index;     ///< grid index of each cell
  std::vector<std::array<int, 8>> cell_nodes;  ///< node of each local corner
  std::vector<int> cell_at;                    ///< block cell (i + Nx (j + Ny k)) -> cell, or -1
  Eigen::Matrix3Xd rest;                       ///< 3 x capacity rest positions [m]
  std::vector<double> mass;                    ///< [kg]
  std::vector<std::uint8_t> constraint;        ///< NodeConstraint bits
  int node_count = 0;
  SpringArrays springs;                        ///< from cell_nodes by merge_springs
  NodeAnchors anchors;                         ///< a compliant grasp's anchors (none: rigid or no grasp)
  /// Set by every merge_springs to a value no network has had before in the process: it changes
  /// whenever the cells' corners may have, and equal values mean equal corners (LatticeForces
  /// uses it to know the network is still the one it was built for, and which cells a tear took
  /// off its lattice).
  std::uint64_t topology = 0;

  [[nodiscard]] int cell_count() const { return static_cast<int>(cell_nodes.size()); }
  [[nodiscard]] int node_capacity() const { return static_cast<int>(rest.cols()); }
  [[nodiscard]] double rest_length(int type) const;
  [[nodiscard]] double spring_constant(int type) const;
  /// The kept cell at grid index g, or -1 (outside the block or pruned).
  [[nodiscard]] int cell_at_index(const Eigen::Vector3i& g) const;
};

/// Builds the network of the cells of `block` marked in `keep` (size Nx Ny Nz, index i + Nx (j +
/// Ny k)): shared vertices become one node, masses lumped (ρ h³ / 8 per cell corner), stiffness
/// as given, τ = η / E. Throws std::invalid_argument on bad sizes, no kept cell, or ρ <= 0.
SpringNetwork build_spring_network(const NetworkBlock& block, const std::vector<bool>& keep,
                                   const CellStiffness& stiffness, double density, double damping_time);

/// A cell spring's key, by which the springs of cells that share them are found (merge_springs,
/// VertexTearing): end nodes a < b and kind packed as a in bits 34-63, b in bits 4-33, kind in
/// bits 0-3, so that sorting the keys sorts by (a, b, kind).
[[nodiscard]] inline std::uint64_t spring_key(int p, int q, int kind) noexcept {
  const auto a = static_cast<std::uint64_t>(p), b = static_cast<std::uint64_t>(q);
  return ((a < b ? a : b) << 34) | ((a < b ? b : a) << 4) | static_cast<std::uint64_t>(kind);
}
/// The spring of a key: {a, b, kind}.
[[nodiscard]] inline std::array<int, 3> spring_of_key(std::uint64_t key) noexcept {
  return {static_cast<int>(key >> 34), static_cast<int>((key >> 4) & ((std::uint64_t{1} << 30) - 1)), static_cast<int>(key & 15u)};
}

/// Rebuilds `net.springs` from the cells' corners: every cell spring keyed (spring_key), sorted
/// in place, equal keys merged with summed constants. Allocation-free once the arrays are sized
/// (build_spring_network sizes them).
void merge_springs(SpringNetwork& net) noexcept;

/// merge_springs after one vertex split, in time linear in the springs: the cells that now hold
/// `copy` at a corner held `original` there when the springs were last merged. Their springs at
/// that corner (7 per cell) leave the kept sorted keys and their springs at `copy` are merged in,
/// the few changed keys sorted alone (a full merge sorts all 28 per cell: ~0.2 ms of a tear
/// storm's splitting sample on clay_tear's 192 cells). The arrays are merge_springs' to the bit.
/// Precondition: since the springs were last merged the cells changed by this split alone (a
/// change made otherwise is not seen). Keys of the split that are not among the kept ones (a
/// wrong `original`), or a merge since by other means, make it a full merge_springs.
void merge_springs_after_split(SpringNetwork& net, int original, int copy) noexcept;

/// The deformation gradient of a cell at its centre from its corners x_a (trilinear shape
/// functions): F = Σ_a x_a ⊗ g_a, g_a = s_a / (4h) with s_a the corner's sign vector (±1)³.
Eigen::Matrix3d cell_deformation_gradient(const Eigen::Matrix<double, 3, 8>& corners, double cell_size);

/// Internal forces of one cell on its 8 corners [N] at positions `x` and velocities `v`:
///   spring:  f_a = k (l − L) d + τ k ((v_b − v_a)·d) d,  d = (x_b − x_a)/l   (and −that on b);
///   volume:  f_a = −κ V₀ ((J − 1) + τ J̇) cof(F) g_a,  J = det F,  J̇ = Σ_b (cof(F) g_b)·v_b.
/// Returns the cell's elastic energy Σ ½ k (l − L)² + ½ κ V₀ (J − 1)² [J].
double cell_forces(const SpringNetwork& net, int cell, const Eigen::Matrix<double, 3, 8>& x,
                   const Eigen::Matrix<double, 3, 8>& v, Eigen::Matrix<double, 3, 8>& f) noexcept;

/// Which stiffness `cell_stiffness_matrix` returns.
enum class CellTangent {
  /// Positive semi-definite: a compressed spring's negative geometric stiffness and the volume
  /// term's (J − 1) ∂²J are left out.
  projected,
  /// The derivative of the elastic forces, −∂f/∂x (indefinite where springs buckle or cells
  /// collapse).
  exact
};

/// The cell's stiffness (24 x 24, corner-major) for Newton:
///   spring block K_aa = k [d dᵀ + g (I − d dᵀ)], K_ab = −K_aa, with g = 1 − L/l (exact) or
///   max(0, 1 − L/l) (projected);
///   volume block κ V₀ [(cof(F) g_a)(cof(F) g_b)ᵀ + (J − 1) ∂²J/∂x_a∂x_b] (the second term only
///   exact), where ∂²J/∂x_a,i∂x_b,k = ε_ikm w_m, w = F (g_a × g_b) (the second derivative of
///   det F, ε_ikm ε_jln F_mn, contracted with g_a,j g_b,l).
/// At rest both are the exact linear stiffness.
void cell_stiffness_matrix(const SpringNetwork& net, int cell, const Eigen::Matrix<double, 3, 8>& x,
                           Eigen::Matrix<double, 24, 24>& K, CellTangent tangent = CellTangent::projected) noexcept;

/// Sum of all cells' internal forces into f (3 x capacity, overwritten for nodes in use), the
/// same forces as cell_forces summed over the cells but with the springs taken from the merged
/// flat arrays (`net.springs`) and the volume term per cell, plus the anchors' forces
/// (`add_anchor_forces`); returns the elastic energy [J]. Allocation-free.
double network_forces(const SpringNetwork& net, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                      Eigen::Matrix3Xd& f) noexcept;

/// Adds the anchors' forces K (a − x) + τ K (ȧ − v) (NodeAnchors) to f at their nodes; returns
/// their energy Σ ½ K |a − x|² [J]. Allocation-free.
double add_anchor_forces(const SpringNetwork& net, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                         Eigen::Matrix3Xd& f) noexcept;

} // namespace kerf
