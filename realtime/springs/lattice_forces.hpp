#pragma once
// LatticeForces: the spring network's internal forces (the same as network_forces) computed on
// the regular lattice of the block (the box of its kept cells): every spring of the block is
// one of 13 lattice directions from a lattice point, and every cell one lattice point (its lower
// corner), so the force loops run over contiguous, unit-stride arrays and vectorise (SIMD lanes
// = neighbouring lattice points) instead of gathering and scattering per spring.

#include "realtime/springs/spring_network.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace kerf {

/// Network forces on the block's lattice (paper 000 §2.1's cubic cells, springs as in
/// network_forces). Built for one network (allocates); `evaluate` uses the lattice while the
/// network still has the cells, corners and constants it was built with (its `topology` count
/// unchanged, i.e. no tear since). After tears (vertex splits, §2.2: some cells' corners
/// re-pointed to copies appended after the network's nodes) it evaluates the torn network as
/// the lattice with exceptions: the cells whose corners are all still the lattice's own nodes
/// stay on the lattice, and the others (the cells at a split vertex's copy) are evaluated one by
/// one with cell_forces on their own corners. Allocation-free.
class LatticeForces {
public:
  LatticeForces() = default;
  /// Lattice arrays of `net`: per direction and lattice point the summed constant of the
  /// (merged) springs that start there, per lattice point whether a cell starts there.
  explicit LatticeForces(const SpringNetwork& net);

  /// True if `net` is still the network this was built for (no vertex split since).
  [[nodiscard]] bool applies(const SpringNetwork& net) const noexcept;
  /// True if `net` is the network this was built for, torn since or not: its first nodes are
  /// the lattice's, its cells the same cells (copies of split vertices come after).
  [[nodiscard]] bool applies_torn(const SpringNetwork& net) const noexcept;
  /// Cells of `net` evaluated off the lattice (those with a corner not the lattice's own node)
  /// at the last torn evaluation; 0 while untorn.
  [[nodiscard]] int exception_count() const noexcept { return static_cast<int>(m_exceptions.size()); }

  /// f (3 x capacity, overwritten for the nodes in use) = the internal forces at positions x and
  /// velocities v, exactly the sum network_forces computes (to round-off):
  ///   spring:  f_a = k (l − L) d + τ k ((v_b − v_a)·d) d,  d = (x_b − x_a)/l   (and −that on b);
  ///   volume:  f_a = −κ V₀ ((J − 1) + τ J̇) cof(F) g_a.
  /// Returns the elastic energy Σ ½ k (l − L)² + Σ ½ κ V₀ (J − 1)² [J]. With
  /// ForcePrecision::single_precision the loops run in single precision (see `substep`); a torn
  /// network is evaluated in double precision whatever is asked: on the lattice with exceptions
  /// while `applies_torn`, else by network_forces.
  enum class ForcePrecision { double_precision, single_precision };
  double evaluate(const SpringNetwork& net, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v, Eigen::Matrix3Xd& f,
                  ForcePrecision precision = ForcePrecision::double_precision) noexcept;

  /// The internal forces at positions x and velocities v (3 x capacity) as `evaluate` computes
  /// them with ForcePrecision::single_precision, left on the lattice instead of written per
  /// node: `single_forces()` holds them, node n's axis i at entry `lattice_entry(n, i)` (for a
  /// caller that reads only some of them, or wants them in single precision: the linearly
  /// implicit step's right-hand side). Loads only the single-precision copies of the state.
  /// Only while `applies(net)`. Returns the elastic energy [J]. Allocation-free.
  double evaluate_on_lattice(const SpringNetwork& net, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v) noexcept;
  /// Entry of node `node`'s axis `axis` (0, 1, 2) in `single_forces()` (axis planes of the
  /// lattice's points). Only while `applies(net)`.
  [[nodiscard]] int lattice_entry(int node, int axis) const noexcept {
    return axis * m_points + m_slot[static_cast<std::size_t>(node)];
  }
  /// The forces of the last `evaluate_on_lattice` [N], 3 x points (x, y, z planes).
  [[nodiscard]] const float* single_forces() const noexcept { return m_f_single.data(); }

  /// Symplectic Euler kept on the lattice between sub-steps (the arithmetic of
  /// symplectic_euler_step, without gathering and scattering the state at every sub-step):
  /// `gather` loads x and v (3 x capacity), `place` overwrites one node's position [m] and
  /// velocity [m/s] (a prescribed node, e.g. under a stylus), `substep` advances by h [s]
  ///   v ← v + h M⁻¹ f(x, v),  then  x ← x + h v   on the free axes (fixed axes keep what was
  ///   placed; lumped masses, constraints as at construction),
  /// and `scatter` writes x and v back. Only while `applies(net)`. Allocation-free.
  void gather(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v) noexcept;
  void place(int node, const Eigen::Vector3d& x, const Eigen::Vector3d& v) noexcept;
  /// What `substep` computes the forces in. Single precision: the same force loops on
  /// single-precision copies of the displacements from the rest lattice (u = x − X, written
  /// by the previous sub-step's update) and of the velocities, with the spring stretch and
  /// J − 1 written without cancellation (l − L = (2 L·Δu + |Δu|²)/(l + L); J − 1 = tr G +
  /// I₂(G) + det G, F = I + G); twice the SIMD lanes. Positions and velocities stay double.
  /// One sub-step on the gathered state; returns the elastic energy at its start [J].
  double substep(const SpringNetwork& net, double h, ForcePrecision precision = ForcePrecision::double_precision) noexcept;
  void scatter(Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v) const noexcept;

  /// gershgorin_frequency_bound (symplectic_euler.hpp) at positions x [1/s²], on the lattice:
  ///   max over nodes not fixed on all axes of (1/m_i) (Σ_{springs at i} 2 k max(1, |1 − L/l|)
  ///   + Σ_{cells at i} κ h³ |∇_i J| Σ_b |∇_b J|).
  /// Only while `applies(net)` (then equal to the flat-array bound to round-off); overwrites
  /// the gathered positions. Allocation-free.
  double gershgorin_bound(const SpringNetwork& net, const Eigen::Matrix3Xd& x) noexcept;

private:
  /// `gather`'s double-precision positions and velocities alone, and its single-precision
  /// displacements and velocities alone (what the forces of each precision read).
  void gather_double(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v) noexcept;
  void gather_single(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v) noexcept;
  /// Forces of the gathered state into the lattice force planes; returns the elastic energy.
  /// One pass for both precisions (`lattice_forces_in`): Real = double reads the positions into
  /// m_f, Real = float the single-precision displacements into m_f_single; the direction and
  /// volume kernels are each precision's own (the float ones on displacements, without
  /// cancellation).
  template <class Real>
  double lattice_forces_in(const SpringNetwork& net, bool torn = false) noexcept;
  /// `evaluate` on a torn network (`applies_torn`): the lattice with the torn constants and cell
  /// mask for the cells still on it, then cell_forces for each exception, added at its corners.
  double evaluate_torn(const SpringNetwork& net, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v, Eigen::Matrix3Xd& f) noexcept;
  /// The torn constants, cell mask and exception cells for `net`'s present corners (after each
  /// change of its topology). Allocation-free.
  void find_exceptions(const SpringNetwork& net) noexcept;
  /// True if every corner of `cell` is the lattice's own node at that corner's point.
  [[nodiscard]] bool on_lattice(const SpringNetwork& net, int cell) const noexcept;
  /// Adds `cell`'s 28 spring constants to k (13 x points) and marks it in mask (points).
  void add_to_lattice(const SpringNetwork& net, int cell, std::vector<double>& k, std::vector<double>& mask) const noexcept;
  double lattice_forces(const SpringNetwork& net) noexcept;
  /// The same in single precision, from the single-precision copies into m_f_single.
  double lattice_forces_single(const SpringNetwork& net) noexcept;

  std::uint64_t m_topology = 0;
  int m_node_count = -1;
  int m_cell_count = 0;
  int m_points = 0;                    ///< lattice points of the kept cells' box, (nx+1)(ny+1)(nz+1)
  int m_pad = 0;                       ///< leading zero entries of the cell arrays (the corner-7 offset)
  std::array<int, 13> m_offset{};      ///< linear offset of each direction
  std::array<int, 13> m_type{};        ///< 1 edge, 2 face diagonal, 3 body diagonal
  std::array<int, 8> m_corner{};       ///< linear offset of each cell corner
  std::vector<int> m_slot;             ///< lattice point of each node
  std::vector<double> m_k;             ///< 13 x points: summed spring constant [N/m]
  std::vector<double> m_cell;          ///< points: 1 where a cell starts, else 0
  std::vector<double> m_x, m_v, m_f;   ///< 3 x points each (x, y, z planes)
  std::vector<double> m_g;             ///< 3 x points: one direction's spring forces
  std::vector<double> m_q;             ///< 12 x (pad + points): per cell the volume forces on corners 0..3 [N]
  std::vector<double> m_inverse_mass;  ///< 3 x points: 1/m on a node's free axes, else 0 [1/kg]
  std::vector<double> m_free;          ///< 3 x points: 1 on a node's free axes, else 0
  std::vector<double> m_bound_weight;  ///< points: 1/m of a node not fixed on all axes, else 0 [1/kg]
  std::vector<double> m_row;           ///< points: Gershgorin row sums [N/m]
  std::vector<double> m_rest;          ///< 3 x points: the lattice points' rest positions [m]
  /// Each cell spring (cell_springs' order) as a lattice direction d and the local corner it
  /// starts from: its constant sits at m_k[d P + (cell's point + m_corner[start])].
  std::array<int, 28> m_spring_direction{}, m_spring_start{};
  std::vector<int> m_cell_point;       ///< per cell: its lattice point (lower corner)
  /// A torn network (`find_exceptions`): the constants and cell mask of the cells still on the
  /// lattice, the cells evaluated off it, and the topology these were found for.
  std::vector<double> m_k_torn, m_cell_torn;
  std::vector<int> m_exceptions;       ///< capacity: every cell (sized at construction)
  std::uint64_t m_torn_topology = 0; ///< 0: none found yet (a merge never gives 0)
  /// ForcePrecision::single_precision: u = x − X [m], v, f, one direction's forces, the cells'
  /// corner forces, the spring constants and the cell mask, in single precision.
  std::vector<float> m_u_single, m_v_single, m_f_single, m_g_single, m_q_single, m_k_single, m_cell_single;
};

} // namespace kerf
