// SegmentLengthInBody against the closed-form length of a segment inside a box (Liang–Barsky
// clipping of the segment to the box: an independent method, no tetrahedra involved).

#include "meshes/box_tet_mesh.hpp"
#include "realtime/fracture/contact_length.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace kerf;

namespace {

const Eigen::Vector3d lower(0.0, -0.010, 0.0);
const Eigen::Vector3d upper(0.040, 0.010, 0.015);

/// Length of [a, b] inside the box [lower, upper] by slab clipping (closed form).
double box_clip_length(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  double t0 = 0.0, t1 = 1.0;
  const Eigen::Vector3d d = b - a;
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0.0) {
      if (a[i] < lower[i] || a[i] > upper[i]) return 0.0;
      continue;
    }
    double s0 = (lower[i] - a[i]) / d[i], s1 = (upper[i] - a[i]) / d[i];
    if (s0 > s1) std::swap(s0, s1);
    t0 = std::max(t0, s0);
    t1 = std::min(t1, s1);
  }
  return t1 > t0 ? (t1 - t0) * d.norm() : 0.0;
}

} // namespace

TEST(ContactLength, BladeEdgeAcrossTheWidthInAMeshPlane) {
  // The edge lies in the grid plane x = 20 mm, i.e. in faces shared by two tetrahedra: the
  // union of intervals must count it once. Expected: the box width, 20 mm.
  SegmentLengthInBody length(box_tet_mesh(lower, upper, 8, 4, 3));
  for (double z : {0.0, 0.001, 0.005, 0.0075, 0.0149, 0.015}) {
    EXPECT_NEAR(length.length({0.020, -0.015, z}, {0.020, 0.015, z}), 0.020, 1e-10) << "z = " << z;
  }
  EXPECT_NEAR(length.length({0.020, -0.015, 0.0151}, {0.020, 0.015, 0.0151}), 0.0, 1e-12); // above the top
}

TEST(ContactLength, AlongMeshEdgesAndOnTheBoundary) {
  SegmentLengthInBody length(box_tet_mesh(lower, upper, 8, 4, 3));
  // Along a grid line (edges of many tetrahedra) and along a boundary edge of the box.
  EXPECT_NEAR(length.length({-0.01, 0.0, 0.005}, {0.05, 0.0, 0.005}), 0.040, 1e-10);
  EXPECT_NEAR(length.length({-0.01, 0.010, 0.015}, {0.05, 0.010, 0.015}), 0.040, 1e-10);
}

TEST(ContactLength, RandomSegmentsMatchTheClosedForm) {
  SegmentLengthInBody length(box_tet_mesh(lower, upper, 5, 3, 4));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.02, 0.06);
  for (int trial = 0; trial < 500; ++trial) {
    const Eigen::Vector3d a(u(rng), u(rng) - 0.02, u(rng) - 0.02), b(u(rng), u(rng) - 0.02, u(rng) - 0.02);
    EXPECT_NEAR(length.length(a, b), box_clip_length(a, b), 1e-10) << "trial " << trial;
  }
}

TEST(ContactLength, PerRegionLengthsOfALayeredBox) {
  // Two regions split at z = 9 mm (a grid plane for nz = 5): a vertical segment through the
  // whole depth has 9 mm in the lower region and 6 mm in the upper one.
  TetMesh mesh = box_tet_mesh(lower, upper, 4, 2, 5);
  add_height_layers(mesh, 0.009);
  SegmentLengthInBody length(mesh, {"layer_upper", "layer_lower"});
  double l[2];
  const double total = length.lengths({0.013, 0.001, -0.01}, {0.013, 0.001, 0.03}, l);
  EXPECT_NEAR(l[0], 0.006, 1e-10);
  EXPECT_NEAR(l[1], 0.009, 1e-10);
  EXPECT_NEAR(total, 0.015, 1e-10);
}

TEST(ContactLength, MissingRegionIsAnError) {
  EXPECT_ANY_THROW(SegmentLengthInBody(box_tet_mesh(lower, upper, 1, 1, 1), {"no_such_group"}));
}

TEST(ContactLengthTable, EqualsTheDirectMeasurementAlongTheAxis) {
  // An edge 30 mm long along y, tilted 10° about the cutting axis' normal, and one along y in
  // the mesh plane x = 20 mm, moved along a cutting axis (down −z, and slanting in x and z) over
  // the box and beyond: the table's l(s) against SegmentLengthInBody at 2000 random s and at
  // on the box's face planes (second method: the direct clipping, itself checked against the
  // closed form above). Round-off and the clipping's own tolerance (10⁻¹² of a tetrahedron's
  // size) only: 10⁻¹² of the edge's length.
  SegmentLengthInBody body(box_tet_mesh(lower, upper, 8, 4, 3));
  const double tilt = 10.0 * M_PI / 180.0;
  struct Axis {
    Eigen::Vector3d p0, e, half;
  };
  const Axis axes[] = {
      {{0.020, 0.0, 0.016}, -Eigen::Vector3d::UnitZ(), 0.015 * Eigen::Vector3d::UnitY()},
      {{0.013, 0.001, 0.017}, Eigen::Vector3d(0.6, 0.0, -0.8), 0.015 * Eigen::Vector3d(0.0, std::cos(tilt), std::sin(tilt))},
  };
  std::mt19937 rng(7);
  for (const Axis& a : axes) {
    ContactLengthTable table(body, a.p0, a.e, a.half, -0.005, 0.030);
    EXPECT_GT(table.intervals(), 2);
    std::uniform_real_distribution<double> u(-0.005, 0.030);
    double out[1];
    for (int k = 0; k < 2000; ++k) {
      const double s = u(rng);
      const Eigen::Vector3d p = a.p0 + s * a.e;
      const double direct = body.length(p - a.half, p + a.half);
      EXPECT_NEAR(table.lengths(s, out), direct, 1e-12 * 0.03) << "s = " << s;
      EXPECT_NEAR(table.parameter(p), s, 1e-15);
    }
    // The first axis crosses the top face and the grid planes z = 10, 5, 0 mm exactly.
    for (const double s : {0.001, 0.006, 0.011, 0.016}) {
      const Eigen::Vector3d p = a.p0 + s * a.e;
      EXPECT_NEAR(table.lengths(s, out), body.length(p - a.half, p + a.half), 1e-12 * 0.03) << "s = " << s;
    }
    EXPECT_TRUE(std::isnan(table.parameter(a.p0 + 0.01 * a.e + Eigen::Vector3d(0.0, 1e-9, 0.0)))); // off the axis
    EXPECT_TRUE(std::isnan(table.parameter(a.p0 + 0.05 * a.e)));                               // beyond the range
  }
}

TEST(ContactLengthTable, PerRegionAtTheLayersInterface) {
  // A layered box (two regions), the edge moved down through both: each region's length from
  // the table equals the direct one, on the interface plane too.
  TetMesh mesh = box_tet_mesh(lower, upper, 8, 4, 5);
  add_height_layers(mesh, 0.009); // a grid plane for nz = 5
  SegmentLengthInBody body(mesh, {"layer_upper", "layer_lower"});
  const Eigen::Vector3d p0(0.020, 0.0, 0.016), e = -Eigen::Vector3d::UnitZ(), half = 0.015 * Eigen::Vector3d::UnitY();
  ContactLengthTable table(body, p0, e, half, 0.0, 0.016);
  for (const double s : {0.0005, 0.001, 0.004, 0.007, 0.007 + 1e-7, 0.012, 0.0159}) {
    double from_table[2], direct[2];
    const Eigen::Vector3d p = p0 + s * e;
    table.lengths(s, from_table);
    body.lengths(p - half, p + half, direct);
    for (int r = 0; r < 2; ++r) EXPECT_NEAR(from_table[r], direct[r], 1e-12 * 0.03) << "s = " << s << ", region " << r;
  }
}
