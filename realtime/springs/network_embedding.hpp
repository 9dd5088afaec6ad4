#pragma once
// NetworkEmbedding: paper 000 §2.1 — the fine tetrahedral geometry follows the coarse network:
// every fine node inside a cell is moved by interpolating that cell's nodes, by trilinear
// interpolation or by a 3-D Coons patch; nodes outside the network keep their rest position.

#include "realtime/springs/spring_network.hpp"

#include <Eigen/Core>

#include <vector>

namespace kerf {

enum class EmbeddingScheme {
  /// x(ξ) = Σ_a N_a(ξ) x_a, N_a = Π_i (b_ai ξ_i + (1 − b_ai)(1 − ξ_i)), ξ ∈ [0, 1]³.
  trilinear,
  /// Transfinite (Coons) interpolation of the cell from its 12 edge curves, in Gordon & Hall's
  /// edge-blended form ("Construction of curvilinear co-ordinate systems and applications to
  /// mesh generation", IJNME 7, 1973, Eq. for the trilinearly blended interpolant from edges):
  ///   x(ξ) = Σ_{12 edges e} B_e(ξ) E_e(ξ_e) − 2 Σ_a N_a(ξ) x_a,
  /// with B_e the bilinear blend of the two coordinates across edge e and E_e the edge curve:
  /// a cubic Hermite through its two nodes whose end tangents are central differences over the
  /// neighbouring network nodes along the edge (one-sided where the network ends or is torn).
  /// It interpolates every edge curve, so neighbouring cells join with matching edges and the
  /// fine mesh bends smoothly across cells; affine motions are reproduced exactly.
  coons
};

class NetworkEmbedding {
public:
  /// Locates each point (#P by 3 rest positions [m]) in the kept cells of `net` (its rest
  /// grid); `host_cells`, when given (one per point, −1 for none), overrides the search (a torn
  /// mesh's nodes on an exposed face belong to the cell of their side). Allocates.
  NetworkEmbedding(const SpringNetwork& net, const Eigen::MatrixXd& points, EmbeddingScheme scheme,
                   const std::vector<int>* host_cells = nullptr);

  /// Writes the embedded positions (#P by 3) for network positions `x` into `out` (sized by the
  /// caller). Allocation-free.
  void apply(const SpringNetwork& net, const Eigen::Matrix3Xd& x, Eigen::MatrixXd& out) const noexcept;

  /// Number of points inside the network.
  [[nodiscard]] int embedded_count() const;

private:
  EmbeddingScheme m_scheme;
  Eigen::MatrixXd m_rest;
  std::vector<int> m_cell;              ///< host cell per point, −1 outside
  std::vector<Eigen::Vector3d> m_local; ///< ξ ∈ [0, 1]³ per point
};

} // namespace kerf
