#pragma once
// Tearing of the spring network, paper 000 §2.2: the approximate maximum tensile stress at each
// vertex shared by cells; past the material's limit the vertex is split and the cells sharing it
// are regrouped by the sign of their contribution along the tension (the crack perpendicular to
// the tension).

#include "realtime/springs/spring_network.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace kerf {

/// The virial (Cauchy) stress of one cell [Pa], tension positive:
///   σ = (1/V₀) Σ_springs k (l − L) l d ⊗ d  +  κ (J − 1) I,  V₀ = h³.
Eigen::Matrix3d cell_stress(const SpringNetwork& net, const Eigen::Matrix<double, 3, 8>& x) noexcept;

/// Connected pieces of the network: cells sharing a node are connected. Writes each cell's
/// piece label (a node id shared by all cells of the piece) into `label` (size cell_count())
/// and returns the number of pieces. `parent` is
/// workspace of size >= node_capacity(). Allocation-free when the vectors are sized.
int network_pieces(const SpringNetwork& net, std::vector<int>& parent, std::vector<int>& label) noexcept;

/// Paper 000 §2.2 on a network: holds the per-node workspace so that `tear` allocates nothing.
class VertexTearing {
public:
  /// `tensile_limit` σ_max [Pa] > 0 (the scene's cohesive strength).
  VertexTearing(const SpringNetwork& net, double tensile_limit);

  /// Finds the vertex (shared by >= 2 cells, not `excluded`, not split before) whose averaged
  /// cell stress has the largest principal value σ₁ > σ_max, and splits it: the cells whose own
  /// force on the vertex points along +n₁ (the tension direction) keep it, the others get a copy
  /// of it (position, velocity, rest position and constraint copied; mass re-lumped). At most one
  /// split per call, and each vertex splits once: the vertex and its copy are not split again
  /// (a crack does not branch at a vertex it has opened). Returns true if a vertex was split.
  /// `excluded` has one entry per node (capacity).
  bool tear(SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, const std::vector<std::uint8_t>& excluded) noexcept;

  /// Largest principal vertex stress found by the last `tear` [Pa].
  [[nodiscard]] double last_max_stress() const { return m_last_max; }
  /// The sum of the cell stresses (cell_stress) of node `node`'s cells at the last `tear`, before
  /// any split it made [Pa]; the vertex stress is this over the node's cell count.
  [[nodiscard]] const Eigen::Matrix3d& cell_stress_sum(int node) const { return m_stress[static_cast<std::size_t>(node)]; }

private:
  /// Pairs every cell's 28 springs with the springs they share with other cells (the same two
  /// nodes and kind: an edge of up to four cells, a face diagonal of two), so that each spring's
  /// term of the cell stress is computed once a call. Allocation-free (sized at construction).
  void share_springs(const SpringNetwork& net) noexcept;
  /// After the split of `original` into `copy`: the moved cells' springs at the copy are shared
  /// springs of their own (among those cells only). Allocation-free.
  void share_springs_after_split(const SpringNetwork& net, int copy) noexcept;
  /// The cells' virial stresses summed per node into m_stress (each cell's sum exactly as
  /// cell_stress computes it, its springs' terms in the same order), m_cells counting them.
  void sum_cell_stresses(const SpringNetwork& net, const Eigen::Matrix3Xd& x) noexcept;

  double m_limit;
  double m_last_max = 0.0;
  std::vector<Eigen::Matrix3d> m_stress; ///< per node, summed over its cells
  std::vector<int> m_cells;              ///< per node, number of cells
  std::vector<std::uint8_t> m_opened;    ///< per node: split before (or the copy of a split vertex)
  // The shared springs: each cell spring's (28 x cells), their end nodes and kind, their stress
  // terms k (l − L)/(l V₀) e ⊗ e and whether their ends are apart (l > 0); the pairing's sort
  // workspace; the topology they were paired for (SpringNetwork::topology).
  std::vector<int> m_spring_of;
  std::vector<std::array<int, 3>> m_shared;
  std::vector<Eigen::Matrix3d> m_term;
  std::vector<std::uint8_t> m_apart;
  std::vector<std::pair<std::uint64_t, int>> m_pairing;
  int m_shared_count = 0;
  std::uint64_t m_topology = 0;
};

} // namespace kerf
