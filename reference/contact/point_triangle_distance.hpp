#pragma once
// Squared distance from a fixed point to a deformable triangle, with its gradient and Hessian with
// respect to the triangle's three vertices: the kinematics of node-to-surface contact where the
// slave point belongs to a rigid tool (Wriggers 2006, "Computational Contact Mechanics", 2nd ed.,
// §4.3 and §9.3: closest-point projection onto a surface facet, its variation and linearisation).
//
// The closest point x_c = Σ λ_i x_i lies on one feature of the triangle (its interior, one edge,
// or one vertex). With λ = λ(β) affine in the feature's free coordinates β (two, one or none),
// d²(x) = min_β f(x, β), f = |p − Σ λ_i(β) x_i|². At the minimiser (envelope theorem)
//   ∂d²/∂x_i = −2 λ_i r,   r = p − x_c,
// and the Hessian is the Schur complement of f's Hessian in (x, β):
//   ∇²d² = H_xx − H_xβ H_ββ⁻¹ H_βx,
//   H_xx = 2 λλᵀ ⊗ I,  (H_xβ)_{i,j} = −2 (∂λ_i/∂β_j) r + 2 λ_i D_j,  (H_ββ)_{jk} = 2 D_j·D_k,
// D_j = Σ_i (∂λ_i/∂β_j) x_i the feature's tangent directions. Inside a feature's region the
// result is exact; across region boundaries d² is C¹.

#include <Eigen/Core>

#include <array>

namespace kerf::reference {

/// Which kind of feature of the triangle holds the closest point (its number of free coordinates:
/// two, one, none); kerf::TriangleFeature (meshes/triangle_closest_point.hpp) names which one.
enum class TriangleFeature { face, edge, vertex };

/// d² of a point to a triangle and its derivatives with respect to the vertices (x0, x1, x2),
/// stacked as a 9-vector [x0; x1; x2]. Units: m², m, 1.
struct PointTriangleDistance {
  double squared_distance = 0.0;                          ///< d² [m²]
  Eigen::Vector3d closest = Eigen::Vector3d::Zero();      ///< x_c [m]
  std::array<double, 3> barycentric{1.0, 0.0, 0.0};      ///< λ of x_c (exact zeros off the feature)
  TriangleFeature feature = TriangleFeature::face;
  Eigen::Matrix<double, 9, 1> gradient = Eigen::Matrix<double, 9, 1>::Zero(); ///< ∂d²/∂[x0;x1;x2] [m]
  Eigen::Matrix<double, 9, 9> hessian = Eigen::Matrix<double, 9, 9>::Zero();  ///< ∂²d²/∂[x0;x1;x2]² [1]
};

/// Closest point of the triangle (x0, x1, x2) to p (Ericson 2005, "Real-Time Collision
/// Detection", §5.1.5: Voronoi regions of the vertices, edges and face), d², and its gradient and
/// Hessian with respect to the vertices (see file comment). Throws std::invalid_argument for a
/// degenerate triangle (area below 1e-14 of its squared longest edge).
PointTriangleDistance point_triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& x0,
                                              const Eigen::Vector3d& x1, const Eigen::Vector3d& x2);

} // namespace kerf::reference
