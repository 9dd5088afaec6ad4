#include "reference/contact/point_triangle_distance.hpp"

#include "meshes/triangle_closest_point.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <stdexcept>
#include <vector>

namespace kerf::reference {

namespace {

/// The closest point's kind of feature and barycentric coordinates (the shared Voronoi-region
/// tests of meshes/triangle_closest_point.hpp, Ericson 2005, §5.1.5). Returns, for an edge, the
/// index of the vertex off the edge (else −1).
int closest_feature(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                    const Eigen::Vector3d& c, PointTriangleDistance& out) {
  const TriangleClosestPoint closest = closest_point_on_triangle(p, a, b, c);
  out.barycentric = closest.barycentric;
  switch (closest.feature) {
  case kerf::TriangleFeature::vertex_a:
  case kerf::TriangleFeature::vertex_b:
  case kerf::TriangleFeature::vertex_c: out.feature = TriangleFeature::vertex; return -1;
  case kerf::TriangleFeature::edge_bc: out.feature = TriangleFeature::edge; return 0;
  case kerf::TriangleFeature::edge_ca: out.feature = TriangleFeature::edge; return 1;
  case kerf::TriangleFeature::edge_ab: out.feature = TriangleFeature::edge; return 2;
  case kerf::TriangleFeature::face: break;
  }
  out.feature = TriangleFeature::face;
  return -1;
}

} // namespace

PointTriangleDistance point_triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& x0,
                                              const Eigen::Vector3d& x1, const Eigen::Vector3d& x2) {
  const double longest = std::max({(x1 - x0).squaredNorm(), (x2 - x1).squaredNorm(), (x0 - x2).squaredNorm()});
  const double area2 = (x1 - x0).cross(x2 - x0).norm();
  if (!(area2 > 1e-14 * longest))
    throw std::invalid_argument("point_triangle_distance: degenerate triangle (zero area)");
  PointTriangleDistance out;
  const int off = closest_feature(p, x0, x1, x2, out);
  const std::array<Eigen::Vector3d, 3> x{x0, x1, x2};
  const auto& lambda = out.barycentric;
  out.closest = lambda[0] * x0 + lambda[1] * x1 + lambda[2] * x2;
  // r = p − x_c
  const Eigen::Vector3d r = p - out.closest;
  out.squared_distance = r.squaredNorm();

  // ∂d²/∂x_i = −2 λ_i r
  for (int i = 0; i < 3; ++i) out.gradient.segment<3>(3 * i) = -2.0 * lambda[static_cast<std::size_t>(i)] * r;

  // The feature's free coordinates: ∂λ/∂β_j and D_j = Σ_i (∂λ_i/∂β_j) x_i.
  std::vector<Eigen::Vector3d> dlambda; // one per free coordinate, entries for x0, x1, x2
  if (out.feature == TriangleFeature::face) {
    dlambda = {Eigen::Vector3d(-1, 1, 0), Eigen::Vector3d(-1, 0, 1)};
  } else if (out.feature == TriangleFeature::edge) {
    // β runs along the edge from vertex a to vertex b (the third vertex is off the edge)
    const int a = (off + 1) % 3, b = (off + 2) % 3;
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    d[a] = -1.0;
    d[b] = 1.0;
    dlambda = {d};
  }
  const Eigen::Index k = static_cast<Eigen::Index>(dlambda.size());
  // H_xx = 2 λλᵀ ⊗ I
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out.hessian.block<3, 3>(3 * i, 3 * j) =
          2.0 * lambda[static_cast<std::size_t>(i)] * lambda[static_cast<std::size_t>(j)] * Eigen::Matrix3d::Identity();
  if (k == 0) return out;
  Eigen::MatrixXd Hxb(9, k), Hbb(k, k);
  std::vector<Eigen::Vector3d> D(static_cast<std::size_t>(k));
  for (Eigen::Index j = 0; j < k; ++j) {
    const Eigen::Vector3d& dl = dlambda[static_cast<std::size_t>(j)];
    D[static_cast<std::size_t>(j)] = dl[0] * x[0] + dl[1] * x[1] + dl[2] * x[2];
  }
  for (Eigen::Index j = 0; j < k; ++j) {
    const Eigen::Vector3d& dl = dlambda[static_cast<std::size_t>(j)];
    // (H_xβ)_{i,j} = −2 (∂λ_i/∂β_j) r + 2 λ_i D_j
    for (int i = 0; i < 3; ++i)
      Hxb.block(3 * i, j, 3, 1) = -2.0 * dl[i] * r + 2.0 * lambda[static_cast<std::size_t>(i)] * D[static_cast<std::size_t>(j)];
    // (H_ββ)_{jk} = 2 D_j·D_k
    for (Eigen::Index m = 0; m < k; ++m)
      Hbb(j, m) = 2.0 * D[static_cast<std::size_t>(j)].dot(D[static_cast<std::size_t>(m)]);
  }
  // ∇²d² = H_xx − H_xβ H_ββ⁻¹ H_βx
  out.hessian -= Hxb * Hbb.inverse() * Hxb.transpose();
  return out;
}

} // namespace kerf::reference
