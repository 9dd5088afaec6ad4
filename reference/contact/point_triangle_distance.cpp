#include "reference/contact/point_triangle_distance.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <stdexcept>
#include <vector>

namespace kerf::reference {

namespace {

/// The closest point's feature and barycentric coordinates (Ericson 2005, §5.1.5). Returns, for
/// an edge, the index of the vertex off the edge (else −1).
int closest_feature(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                    const Eigen::Vector3d& c, PointTriangleDistance& out) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  auto set = [&](TriangleFeature f, double l0, double l1, double l2, int off = -1) {
    out.feature = f;
    out.barycentric = {l0, l1, l2};
    return off;
  };
  if (d1 <= 0.0 && d2 <= 0.0) return set(TriangleFeature::vertex, 1.0, 0.0, 0.0);
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return set(TriangleFeature::vertex, 0.0, 1.0, 0.0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    return set(TriangleFeature::edge, 1.0 - v, v, 0.0, 2);
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return set(TriangleFeature::vertex, 0.0, 0.0, 1.0);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    return set(TriangleFeature::edge, 1.0 - w, 0.0, w, 1);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return set(TriangleFeature::edge, 0.0, 1.0 - w, w, 0);
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return set(TriangleFeature::face, 1.0 - v - w, v, w);
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
