// Tests of meshes/tet_quality: closed forms for the regular and the right-corner tetrahedron,
// degenerate and inverted elements, and a sweep of near-degenerate inputs checked against a
// second, independent computation of each measure.
#include "meshes/tet_quality.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <numbers>
#include <random>

namespace kerf {
namespace {

using Vec = Eigen::Vector3d;
constexpr double pi = std::numbers::pi;

/// Regular tetrahedron with edge 2 sqrt(2), positively oriented (alternate cube corners).
std::array<Vec, 4> regular_tet() { return {Vec(1, 1, 1), Vec(1, -1, -1), Vec(-1, -1, 1), Vec(-1, 1, -1)}; }

/// Reference dihedral angle at edge (i, j), by a second method: project the other two vertices
/// onto the plane orthogonal to the edge and take the angle between the projections.
double dihedral_by_projection(const std::array<Vec, 4>& p, int i, int j) {
  int k = -1;
  int l = -1;
  for (int m = 0; m < 4; ++m)
    if (m != i && m != j) (k < 0 ? k : l) = m;
  const Vec e = (p[j] - p[i]).normalized();
  const Vec u = (p[k] - p[i]) - (p[k] - p[i]).dot(e) * e;
  const Vec v = (p[l] - p[i]) - (p[l] - p[i]).dot(e) * e;
  return std::acos(std::clamp(u.normalized().dot(v.normalized()), -1.0, 1.0));
}

/// Reference radius ratio by a second method: circumcentre from the linear system
/// 2 (p_i - p_0) . o = |p_i|^2 - |p_0|^2, inradius 3 |V| / (sum of face areas).
double radius_ratio_by_solve(const std::array<Vec, 4>& p) {
  Eigen::Matrix3d A;
  Vec b;
  for (int i = 1; i < 4; ++i) {
    A.row(i - 1) = 2.0 * (p[i] - p[0]).transpose();
    b(i - 1) = p[i].squaredNorm() - p[0].squaredNorm();
  }
  const Vec centre = A.fullPivLu().solve(b);
  const double circumradius = (centre - p[0]).norm();
  const double area = 0.5 * ((p[1] - p[0]).cross(p[2] - p[0]).norm() + (p[1] - p[0]).cross(p[3] - p[0]).norm() +
                             (p[2] - p[0]).cross(p[3] - p[0]).norm() + (p[2] - p[1]).cross(p[3] - p[1]).norm());
  const double inradius = 3.0 * std::abs(signed_volume(p[0], p[1], p[2], p[3])) / area;
  return 3.0 * inradius / circumradius;
}

TetMesh mesh_of(const std::vector<std::array<Vec, 4>>& tets) {
  TetMesh mesh;
  mesh.nodes.resize(static_cast<Eigen::Index>(4 * tets.size()), 3);
  mesh.tets.resize(static_cast<Eigen::Index>(tets.size()), 4);
  for (std::size_t t = 0; t < tets.size(); ++t)
    for (int j = 0; j < 4; ++j) {
      mesh.nodes.row(static_cast<Eigen::Index>(4 * t + j)) = tets[t][j].transpose();
      mesh.tets(static_cast<Eigen::Index>(t), j) = static_cast<int>(4 * t + j);
    }
  return mesh;
}

TEST(TetQuality, RegularTetrahedron) {
  const auto p = regular_tet();
  // Closed form: V = a^3 / (6 sqrt 2) with a = 2 sqrt 2, i.e. 8/3.
  EXPECT_NEAR(signed_volume(p[0], p[1], p[2], p[3]), 8.0 / 3.0, 1e-14);
  // Closed form: every dihedral angle of the regular tetrahedron is acos(1/3).
  EXPECT_NEAR(min_dihedral_angle(p[0], p[1], p[2], p[3]), std::acos(1.0 / 3.0), 1e-14);
  // By definition the normalised radius ratio 3 r_in / r_circ is 1 for the regular tetrahedron.
  EXPECT_NEAR(radius_ratio(p[0], p[1], p[2], p[3]), 1.0, 1e-14);
}

TEST(TetQuality, RightCornerTetrahedron) {
  const Vec a(0, 0, 0), b(1, 0, 0), c(0, 1, 0), d(0, 0, 1);
  // Closed form: V = 1/6.
  EXPECT_NEAR(signed_volume(a, b, c, d), 1.0 / 6.0, 1e-15);
  // Closed form: the three edges at the corner have pi/2; the edges of the slanted face make
  // pi - angle(-e_i, (1,1,1)/sqrt 3) = acos(1/sqrt 3) = 54.7356 deg with the coordinate faces.
  EXPECT_NEAR(min_dihedral_angle(a, b, c, d), std::acos(1.0 / std::sqrt(3.0)), 1e-14);
  // Closed form: r_in = 3V / A = 1 / (3 + sqrt 3), r_circ = sqrt 3 / 2, so 3 r_in / r_circ = sqrt 3 - 1.
  EXPECT_NEAR(radius_ratio(a, b, c, d), std::sqrt(3.0) - 1.0, 1e-14);
}

TEST(TetQuality, FlatTetrahedronIsDegenerate) {
  // Four corners of a unit square: zero volume, zero dihedral angle, zero radius ratio.
  const Vec a(0, 0, 0), b(1, 0, 0), c(1, 1, 0), d(0, 1, 0);
  EXPECT_EQ(signed_volume(a, b, c, d), 0.0);
  EXPECT_EQ(min_dihedral_angle(a, b, c, d), 0.0);
  EXPECT_EQ(radius_ratio(a, b, c, d), 0.0);
  const TetQualitySummary summary = tet_quality_summary(mesh_of({{a, b, c, d}}));
  EXPECT_EQ(summary.degenerate, 1);
  EXPECT_EQ(summary.inverted, 0);
  EXPECT_EQ(summary.slivers, 0);
  EXPECT_FALSE(summary.valid());
}

TEST(TetQuality, InvertedTetrahedron) {
  auto p = regular_tet();
  std::swap(p[2], p[3]);
  // Swapping two vertices negates det[b-a, c-a, d-a]; shape measures are unchanged.
  EXPECT_NEAR(signed_volume(p[0], p[1], p[2], p[3]), -8.0 / 3.0, 1e-14);
  EXPECT_NEAR(min_dihedral_angle(p[0], p[1], p[2], p[3]), std::acos(1.0 / 3.0), 1e-14);
  EXPECT_NEAR(radius_ratio(p[0], p[1], p[2], p[3]), 1.0, 1e-14);
  const TetQualitySummary summary = tet_quality_summary(mesh_of({regular_tet(), p}));
  EXPECT_EQ(summary.tet_count, 2);
  EXPECT_EQ(summary.node_count, 8);
  EXPECT_EQ(summary.inverted, 1);
  EXPECT_EQ(summary.degenerate, 0);
  EXPECT_NEAR(summary.total_volume, 0.0, 1e-14);
  EXPECT_NEAR(summary.min_volume, -8.0 / 3.0, 1e-14);
  EXPECT_FALSE(summary.valid());
}

TEST(TetQuality, SliverOnASquare) {
  // Four nearly coplanar points on a unit square, the diagonals lifted by +-delta: the classic
  // sliver, with a positive volume (delta/3) but dihedral angles near 0 and pi.
  const double delta = 0.01;
  const Vec a(0, 0, 0), b(1, 1, 0), c(0, 1, delta), d(1, 0, delta);
  EXPECT_NEAR(signed_volume(a, b, c, d), delta / 3.0, 1e-15);
  EXPECT_LT(min_dihedral_angle(a, b, c, d), 5.0 * pi / 180.0);
  EXPECT_LT(radius_ratio(a, b, c, d), 0.05);
  const TetQualitySummary summary = tet_quality_summary(mesh_of({regular_tet(), {a, b, c, d}}));
  EXPECT_EQ(summary.slivers, 1);
  EXPECT_EQ(summary.degenerate, 0);
  EXPECT_EQ(summary.inverted, 0);
  EXPECT_TRUE(summary.valid());
  EXPECT_NEAR(summary.min_radius_ratio, radius_ratio(a, b, c, d), 1e-15);
  EXPECT_NEAR(summary.mean_radius_ratio, 0.5 * (1.0 + radius_ratio(a, b, c, d)), 1e-15);
  EXPECT_NEAR(summary.min_dihedral_angle, min_dihedral_angle(a, b, c, d), 1e-15);
}

TEST(TetQuality, EmptyMesh) {
  const TetQualitySummary summary = tet_quality_summary(TetMesh{});
  EXPECT_EQ(summary.tet_count, 0);
  EXPECT_TRUE(summary.valid());
}

TEST(TetQuality, MeasuresAgreeWithSecondMethodOnRandomTetrahedra) {
  std::mt19937 random(42);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int n = 0; n < 500; ++n) {
    std::array<Vec, 4> p;
    for (auto& v : p) v = Vec(uniform(random), uniform(random), uniform(random));
    const double h = 2.0;
    if (std::abs(signed_volume(p[0], p[1], p[2], p[3])) < 1e-3 * h * h * h) continue; // well conditioned only
    double smallest = pi;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) smallest = std::min(smallest, dihedral_by_projection(p, i, j));
    EXPECT_NEAR(min_dihedral_angle(p[0], p[1], p[2], p[3]), smallest, 1e-9);
    EXPECT_NEAR(radius_ratio(p[0], p[1], p[2], p[3]), radius_ratio_by_solve(p), 1e-9);
  }
}

TEST(TetQuality, InvariantUnderSimilarityTransforms) {
  // Angles and the radius ratio are invariant under rotation, translation and scaling; the volume
  // scales with s^3. Checked from 1e-6 m to 1e3 m.
  const auto p = regular_tet();
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Vec(1, 2, 3).normalized()).toRotationMatrix();
  for (const double s : {1e-6, 1e-3, 1.0, 1e3}) {
    std::array<Vec, 4> q;
    for (int i = 0; i < 4; ++i) q[i] = s * (rotation * p[i]) + Vec(5, -3, 2);
    EXPECT_NEAR(min_dihedral_angle(q[0], q[1], q[2], q[3]), std::acos(1.0 / 3.0), 1e-9);
    EXPECT_NEAR(radius_ratio(q[0], q[1], q[2], q[3]), 1.0, 1e-9);
    EXPECT_NEAR(signed_volume(q[0], q[1], q[2], q[3]) / (s * s * s), 8.0 / 3.0, 1e-6);
  }
}

TEST(TetQuality, NearDegenerateSweepNeverProducesNaN) {
  // Collapse a random tetrahedron towards a plane, a line and a point by factors 10^-k, plus
  // exactly coincident, collinear and coplanar vertices and extreme scales: every measure stays
  // finite and in range, and the summary classifies the element as something.
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const auto check = [](const std::array<Vec, 4>& p) {
    const double volume = signed_volume(p[0], p[1], p[2], p[3]);
    const double dihedral = min_dihedral_angle(p[0], p[1], p[2], p[3]);
    const double ratio = radius_ratio(p[0], p[1], p[2], p[3]);
    EXPECT_TRUE(std::isfinite(volume));
    EXPECT_TRUE(std::isfinite(dihedral));
    EXPECT_TRUE(std::isfinite(ratio));
    EXPECT_GE(dihedral, 0.0);
    EXPECT_LE(dihedral, pi);
    EXPECT_GE(ratio, 0.0);
    EXPECT_LE(ratio, 1.0);
    const TetQualitySummary summary = tet_quality_summary(mesh_of({p}));
    EXPECT_TRUE(std::isfinite(summary.mean_radius_ratio));
    EXPECT_TRUE(std::isfinite(summary.min_dihedral_angle));
  };
  for (int n = 0; n < 20; ++n) {
    std::array<Vec, 4> p;
    for (auto& v : p) v = Vec(uniform(random), uniform(random), uniform(random));
    for (int k = 0; k <= 20; ++k) {
      const double f = std::pow(10.0, -k);
      check({p[0], p[1], p[2], p[2] + f * (p[3] - p[2])});                               // d towards c (a short edge)
      check({p[0], p[1], p[1] + f * (p[2] - p[1]), p[1] + f * (p[3] - p[1])});           // towards an edge
      check({p[0], p[0] + f * (p[1] - p[0]), p[0] + f * (p[2] - p[0]), p[0] + f * (p[3] - p[0])}); // towards a point
      Vec d = p[3];
      const Vec normal = (p[1] - p[0]).cross(p[2] - p[0]).normalized();
      d -= (1.0 - f) * normal.dot(d - p[0]) * normal; // towards the plane of (p0, p1, p2)
      check({p[0], p[1], p[2], d});
    }
    check({p[0], p[0], p[0], p[0]});
    check({p[0], p[1], p[0], p[1]});
    check({p[0], p[1], 0.5 * (p[0] + p[1]), 2.0 * p[1] - p[0]});
    check({p[0], p[1], p[2], p[0] + p[1] - p[2]});
    // Extreme but representable scales (at 1e150 m the volume itself overflows a double).
    for (const double s : {1e-100, 1e100}) check({s * p[0], s * p[1], s * p[2], s * p[3]});
  }
  // A collapsed element is degenerate, not a sliver.
  const auto q = regular_tet();
  const TetQualitySummary flat = tet_quality_summary(mesh_of({{q[0], q[1], q[2], q[2] + 1e-12 * (q[3] - q[2])}}));
  EXPECT_EQ(flat.degenerate, 1);
}

} // namespace
} // namespace kerf
