#pragma once
// SweptSurface: the trajectory surface of a straight cutting edge (paper 000 §3.2, Fig. 9): the
// edge's recorded positions joined into a strip of triangular patches.

#include <Eigen/Core>

#include <span>

namespace kerf {

/// A triangle surface: #V by 3 vertex positions [m], #F by 3 vertex indices.
struct SweptSurface {
  Eigen::MatrixXd vertices;
  Eigen::MatrixXi triangles;
};

/// The surface swept by an edge of length `edge_length` [m] along unit `edge_direction`, whose
/// midpoint passes through `centres` in order (paper 000 §3.2: "the trajectory of the cutting
/// edge is recorded, and the trajectory surface is defined as a set of triangular patches").
/// Position k gives the vertices a_k = c_k - L/2 e (row 2k) and b_k = c_k + L/2 e (row 2k+1);
/// each step k -> k+1 gives the triangles (a_k, b_k, b_k+1) and (a_k, b_k+1, a_k+1), so n
/// positions give 2 (n - 1) triangles, consistently oriented. Throws std::invalid_argument for
/// fewer than two positions or a bad edge.
SweptSurface sweep_edge(std::span<const Eigen::Vector3d> centres, const Eigen::Vector3d& edge_direction,
                        double edge_length);

} // namespace kerf
