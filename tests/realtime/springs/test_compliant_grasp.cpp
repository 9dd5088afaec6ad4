// The compliant grasp (docs/spring-network.md §3, "Compliant grasp"): the layer k(r) = k (1 − r²/a²)
// lumped onto anchor springs K_p = ∫ N_p k dA, checked against the continuous layer's integrals,
// a laterally confined column (the layer and the network in series), the rigid grasp as k → ∞,
// the forces and stiffness of every force path, and the explicit stability limit with anchors.

#include "realtime/springs/compliant_grasp.hpp"
#include "realtime/springs/lattice_forces.hpp"
#include "realtime/springs/network_system.hpp"
#include "realtime/springs/symplectic_euler.hpp"
#include "tests/realtime/springs/model_fixtures.hpp"
#include "tests/realtime/springs/network_fixtures.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace kerf {
namespace {

constexpr double clay_k = 1.9e9; // N/m³: a 1 mm layer of the clay (docs/scenes.md, "Choosing k")

/// Σ K_p, Σ K_p X_p and Σ K_p |X_p − c|² of a lumped layer.
struct Moments {
  double sum = 0.0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  double second = 0.0;
};
Moments moments(const SpringNetwork& net, const LumpedGraspLayer& lumped, const Eigen::Vector3d& centre) {
  Moments m;
  for (std::size_t i = 0; i < lumped.node.size(); ++i) {
    const Eigen::Vector3d X = net.rest.col(lumped.node[i]);
    m.sum += lumped.stiffness[i];
    m.first += lumped.stiffness[i] * X;
    m.second += lumped.stiffness[i] * (X - centre).squaredNorm();
  }
  return m;
}

TEST(CompliantGrasp, LumpedLayerHasTheContinuousLayersForceCentreAndSecondMoment) {
  // Independent values, the continuous layer's integrals over the disc (polar coordinates):
  //   ∫ k(r) dA = k π a²/2,  ∫ k(r) X dA = c k π a²/2 (the disc is symmetric about its centre c),
  //   ∫ k(r) r² dA = k π a⁴/6.
  // Σ_p N_p = 1 and Σ_p N_p X_p = X on the face (bilinear shape functions), so the first two
  // hold for the lumped layer at every cell size, to the quadrature's accuracy. The bilinear
  // interpolant of r² exceeds r² by (x − x_i)(x_{i+1} − x) + (y − y_j)(y_{j+1} − y) ∈ [0, h²/2], so
  //   k π a⁴/6 ≤ Σ K_p |X_p − c|² ≤ k π a⁴/6 + (h²/2) k π a²/2:
  // the lumped layer's spread converges to the continuous one's at second order in h.
  const double a = 4e-3;
  const double sum = clay_k * M_PI * a * a / 2.0, second = clay_k * M_PI * std::pow(a, 4) / 6.0;
  for (const int n : {4, 8, 16}) {
    const double h = 0.02 / n;
    const SpringNetwork net = test::full_block(n, h, CellStiffness{1.0, 1.0, 1.0, 0.0});
    // The disc on the top face, centred on the middle node and off the nodes.
    for (const Eigen::Vector3d& offset : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.3 * h, 0.45 * h, 0)}) {
      const Eigen::Vector3d centre = Eigen::Vector3d(0.01, 0.01, 0.02) + offset;
      const LumpedGraspLayer lumped = lump_grasp_layer(net, GraspLayer{centre, Eigen::Vector3d::UnitZ(), a, clay_k});
      const Moments m = moments(net, lumped, centre);
      // The quadrature's error (the quadtree's Gauss points on squares cut by the rim): ~10⁻¹⁰.
      EXPECT_NEAR(m.sum, sum, 1e-8 * sum) << "h " << h;
      EXPECT_LT((m.first / m.sum - centre).norm(), 1e-8 * a) << "h " << h;
      EXPECT_GT(m.second, second * (1.0 - 1e-6)) << "h " << h;
      EXPECT_LT(m.second, (second + 0.5 * h * h * sum) * (1.0 + 1e-6)) << "h " << h;
      for (const int p : lumped.node) EXPECT_NEAR(net.rest(2, p), 0.02, 1e-12); // the top face's nodes only
    }
  }
}

TEST(CompliantGrasp, CentreNodeStiffnessHasItsClosedForm) {
  // A node at the disc's centre whose four face squares lie inside the disc (√2 h ≤ a):
  //   K = ∫ N k (1 − r²/a²) dA = k (h² − (1/a²) ∫ N r² dA) = k h² (1 − h²/(3 a²)),
  // since ∫ N dA = h² and ∫ N r² dA = 2 ∫(1 − |x|/h) x² dx ∫(1 − |y|/h) dy = 2 (h³/6) h = h⁴/3.
  // The nodal rule k(r_p) h² = k h² is its limit as h → 0.
  const double a = 4e-3;
  for (const int n : {8, 16}) {
    const double h = 0.02 / n;
    const SpringNetwork net = test::full_block(n, h, CellStiffness{1.0, 1.0, 1.0, 0.0});
    const Eigen::Vector3d centre(0.01, 0.01, 0.02);
    const LumpedGraspLayer lumped = lump_grasp_layer(net, GraspLayer{centre, Eigen::Vector3d::UnitZ(), a, clay_k});
    double K = -1.0;
    for (std::size_t i = 0; i < lumped.node.size(); ++i)
      if ((net.rest.col(lumped.node[i]) - centre).norm() < 1e-12) K = lumped.stiffness[i];
    const double expected = clay_k * h * h * (1.0 - h * h / (3.0 * a * a));
    EXPECT_NEAR(K, expected, 1e-9 * expected) << "h " << h;
  }
}

TEST(CompliantGrasp, TakesTheNetworksFaceAndRefusesADiscBeyondIt) {
  const SpringNetwork net = test::full_block(4, 5e-3, CellStiffness{1.0, 1.0, 1.0, 0.0});
  // The disc reaches past the block's edge.
  EXPECT_THROW(lump_grasp_layer(net, GraspLayer{{0.001, 0.01, 0.02}, Eigen::Vector3d::UnitZ(), 4e-3, clay_k}), std::invalid_argument);
  // A centre more than half a cell from the network's face.
  EXPECT_THROW(lump_grasp_layer(net, GraspLayer{{0.01, 0.01, 0.017}, Eigen::Vector3d::UnitZ(), 4e-3, clay_k}), std::invalid_argument);
  // Within half a cell: the layer sits on the network's face (z = 20 mm), the same as a centre on it.
  const LumpedGraspLayer below = lump_grasp_layer(net, GraspLayer{{0.01, 0.01, 0.018}, Eigen::Vector3d::UnitZ(), 4e-3, clay_k});
  const LumpedGraspLayer on = lump_grasp_layer(net, GraspLayer{{0.01, 0.01, 0.02}, Eigen::Vector3d::UnitZ(), 4e-3, clay_k});
  EXPECT_EQ(below.node, on.node);
  EXPECT_EQ(below.stiffness, on.stiffness);
  // A normal off the axes.
  EXPECT_THROW(lump_grasp_layer(net, GraspLayer{{0.01, 0.01, 0.02}, Eigen::Vector3d(1, 0, 1).normalized(), 4e-3, clay_k}),
               std::invalid_argument);
}

/// A laterally confined column 5 x 5 x 20 mm (clay, no damping): base bonded, the faces x = 0, 5 mm
/// sliding along x and y = 0, 5 mm along y, so every node moves along z only.
TetMesh confined_column_mesh() {
  TetMesh mesh = box_tet_mesh({0.0, 0.0, 0.0}, {0.005, 0.005, 0.02}, 1, 1, 4);
  const SurfaceGroup* sides = mesh.find_surface_group("sides");
  SurfaceGroup side_x{"side_x", 5, Eigen::MatrixX3i(0, 3)}, side_y{"side_y", 6, Eigen::MatrixX3i(0, 3)};
  for (Eigen::Index t = 0; t < sides->triangles.rows(); ++t) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) centroid += mesh.nodes.row(sides->triangles(t, k)).transpose() / 3.0;
    const bool on_x = std::abs(centroid.x()) < 1e-9 || std::abs(centroid.x() - 0.005) < 1e-9;
    SurfaceGroup& g = on_x ? side_x : side_y;
    g.triangles.conservativeResize(g.triangles.rows() + 1, 3);
    g.triangles.row(g.triangles.rows() - 1) = sides->triangles.row(t);
  }
  mesh.surface_groups.push_back(side_x);
  mesh.surface_groups.push_back(side_y);
  return mesh;
}

/// The quasi-static force on the stylus after pulling it up by `delta` [m] from `start`.
double pulled_force(const TetMesh& mesh, const SpringNetworkSetup& setup, double delta) {
  SpringNetworkModel model(mesh, setup);
  std::array<ToolState, 1> tool;
  std::array<ForceSample, 1> force;
  tool[0].position = setup.styluses[0].start;
  model.step(tool, 1e-3, force);
  tool[0].position += Eigen::Vector3d(0, 0, delta);
  model.step(tool, 1e-3, force);
  EXPECT_FALSE(force[0].over_budget);
  return force[0].force.z();
}

TEST(CompliantGrasp, ConfinedColumnIsTheLayerAndTheNetworkInSeries) {
  // Independent value: under uniaxial strain the column (height H, section A) is a spring of
  // stiffness E_oed A / H, E_oed = E (1 − ν) / ((1 + ν)(1 − 2ν)) the network's C11 (E and ν are
  // identified exactly, docs/spring-network.md §1); the layer on a disc of radius a = 2.5 mm
  // centred on the 5 mm face lies inside it, ∫ k(r) dA = k π a²/2, and its four corner nodes take
  // equal shares, so the pull stays uniform and the two are in series:
  //   F = δ / (1/(k π a²/2) + H / (E_oed A)).
  // The rigid grasp of the same four nodes gives the column alone, F = E_oed A δ / H.
  const TetMesh mesh = confined_column_mesh();
  SpringNetworkSetup s = test::clay_pull_setup(SpringIntegrator::quasi_static);
  s.damping = 0.0;
  s.cells = 4;
  s.cell_size = 5e-3; // the block (20 mm cubed) keeps the column's 1 x 1 x 4 cells
  s.supports = {{"support", false}, {"side_x", true}, {"side_y", true}};
  s.styluses = {{Eigen::Vector3d(0.0025, 0.0025, 0.021), 0.001}};
  s.styluses[0].grasp_stiffness = clay_k;
  s.styluses[0].grasp_disc_radius = 2.5e-3;
  const double E = s.youngs_modulus, nu = s.poisson_ratio;
  const double E_oed = E * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
  const double A = 25e-6, H = 0.02, delta = 2e-5;
  const double column = E_oed * A / H, layer = clay_k * M_PI * 2.5e-3 * 2.5e-3 / 2.0;
  {
    SpringNetworkModel model(mesh, s);
    ASSERT_EQ(model.network().cell_count(), 4);
    EXPECT_EQ(model.anchored_nodes(0), 4);
    EXPECT_EQ(model.attached_nodes(0), 0);
    EXPECT_NEAR(model.anchor_stiffness(0), layer, 1e-6 * layer);
  }
  const double compliant = pulled_force(mesh, s, delta);
  // The body pulls the stylus back (−z); the column and the layer in series. Tolerance: the
  // springs' geometric nonlinearity at a strain of δ/H = 10⁻³ and the Newton tolerance
  // (10⁻⁵ k₁ h = 1.5·10⁻⁵ N per node against a 0.04 N pull).
  EXPECT_NEAR(-compliant, delta / (1.0 / layer + 1.0 / column), 1e-3 * delta / (1.0 / layer + 1.0 / column));
  s.styluses[0].grasp_stiffness = 0.0;
  s.grasp_radius = 4e-3; // the four top nodes (3.7 mm from the tip centre), not the next layer's (7.0 mm)
  const double rigid = pulled_force(mesh, s, delta);
  EXPECT_NEAR(-rigid, column * delta, 1e-3 * column * delta);
  // The layer matters here: 11 % less force than the rigid grasp.
  EXPECT_LT(-compliant, 0.92 * -rigid);
}

TEST(CompliantGrasp, AStiffLayerRecoversTheRigidGrasp) {
  // As k → ∞ the anchors become the rigid tie of the same nodes, and the force's difference from
  // the rigid grasp falls as 1/k (the layer's compliance in series, ∝ 1/k, to first order). The
  // disc a = 2 mm on the 2.5 mm cells touches the four squares around the centre node: its nine
  // nodes, the same nine the rigid grasp of radius 4.2 mm takes (top nodes up to 4.06 mm from the
  // tip centre; the node below the centre is 4.5 mm away).
  const TetMesh mesh = test::clay_pull_mesh();
  SpringNetworkSetup s = test::clay_pull_setup(SpringIntegrator::quasi_static);
  s.grasp_radius = 4.2e-3;
  const double delta = 2.5e-4;
  {
    const SpringNetworkModel rigid_model(mesh, s);
    EXPECT_EQ(rigid_model.attached_nodes(0), 9);
  }
  const double rigid = pulled_force(mesh, s, delta);
  std::vector<double> gap;
  for (const double k : {1e11, 1e12, 1e13}) {
    s.styluses[0].grasp_stiffness = k;
    s.styluses[0].grasp_disc_radius = 2e-3;
    {
      const SpringNetworkModel model(mesh, s);
      EXPECT_EQ(model.anchored_nodes(0), 9);
    }
    const double compliant = pulled_force(mesh, s, delta);
    EXPECT_LT(std::abs(compliant), std::abs(rigid)); // a compliant grasp holds less
    gap.push_back(std::abs(rigid) - std::abs(compliant));
  }
  EXPECT_NEAR(gap[0] / gap[1], 10.0, 1.0);
  EXPECT_NEAR(gap[1] / gap[2], 10.0, 1.0);
}

/// A 3 x 3 x 3 block (clay, h = 2.5 mm, τ = 20 µs), base fixed, with anchors of stiffness
/// `anchor` [N/m] on its top nodes, moved and moving, and a random state.
struct Anchored {
  SpringNetwork net;
  Eigen::Matrix3Xd x, v;
};
Anchored anchored_block(double anchor, double damping_time, unsigned seed) {
  const double h = 2.5e-3;
  Anchored b{test::full_block(3, h, identify_cell_stiffness(0.5e6, 0.45, h, true).stiffness, 1700.0, damping_time), {}, {}};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  NodeAnchors& anchors = b.net.anchors;
  for (int p = 0; p < b.net.node_count; ++p) {
    const Eigen::Vector3i g = test::grid_of(b.net, p);
    if (g.z() == 0) b.net.constraint[static_cast<std::size_t>(p)] = fix_all;
    if (g.z() == 3) {
      anchors.node.push_back(p);
      anchors.stiffness.push_back(anchor * (1.0 + 0.5 * u(rng)));
    }
  }
  anchors.position.resize(3, anchors.count());
  anchors.velocity.resize(3, anchors.count());
  for (int i = 0; i < anchors.count(); ++i)
    for (int r = 0; r < 3; ++r)
      anchors.position(r, i) = b.net.rest(r, anchors.node[static_cast<std::size_t>(i)]) + 0.02 * h * u(rng),
      anchors.velocity(r, i) = 1e-2 * u(rng);
  b.x = b.net.rest;
  b.v.setZero(3, b.net.node_capacity());
  for (int p = 0; p < b.net.node_count; ++p)
    if (!b.net.constraint[static_cast<std::size_t>(p)])
      for (int r = 0; r < 3; ++r) b.x(r, p) += 0.01 * h * u(rng), b.v(r, p) = 1e-2 * u(rng);
  return b;
}

TEST(CompliantGrasp, EveryForcePathAndTheStiffnessIncludeTheAnchors) {
  // Independent value: the network's forces without anchors (network_forces on a copy with none)
  // plus each anchor's K (a − x) + τ K (ȧ − v) written out here; the lattice loops (double and
  // single precision) must give the same, and the assembled stiffness must be the forces'
  // derivative (central differences of the quasi-static forces, τ = 0).
  Anchored b = anchored_block(1e5, 2e-5, 5);
  SpringNetwork bare = b.net;
  bare.anchors = NodeAnchors{};
  Eigen::Matrix3Xd expected(3, b.net.node_capacity()), f(3, b.net.node_capacity());
  network_forces(bare, b.x, b.v, expected);
  for (int i = 0; i < b.net.anchors.count(); ++i) {
    const int p = b.net.anchors.node[static_cast<std::size_t>(i)];
    const double K = b.net.anchors.stiffness[static_cast<std::size_t>(i)];
    expected.col(p) += K * (b.net.anchors.position.col(i) - b.x.col(p)) +
                       b.net.damping_time * K * (b.net.anchors.velocity.col(i) - b.v.col(p));
  }
  const double scale = expected.leftCols(b.net.node_count).cwiseAbs().maxCoeff();
  network_forces(b.net, b.x, b.v, f);
  EXPECT_LT((f - expected).leftCols(b.net.node_count).cwiseAbs().maxCoeff(), 1e-12 * scale);
  LatticeForces lattice(b.net);
  ASSERT_TRUE(lattice.applies(b.net));
  lattice.evaluate(b.net, b.x, b.v, f);
  EXPECT_LT((f - expected).leftCols(b.net.node_count).cwiseAbs().maxCoeff(), 1e-12 * scale);
  lattice.evaluate(b.net, b.x, b.v, f, LatticeForces::ForcePrecision::single_precision);
  EXPECT_LT((f - expected).leftCols(b.net.node_count).cwiseAbs().maxCoeff(), 1e-5 * scale);
  // Gershgorin: an anchor adds K to its row in both bounds.
  std::vector<double> work(static_cast<std::size_t>(b.net.node_capacity()));
  const double flat = gershgorin_frequency_bound(b.net, b.x, work);
  EXPECT_NEAR(lattice.gershgorin_bound(b.net, b.x), flat, 1e-12 * flat);
  EXPECT_GT(flat, gershgorin_frequency_bound(bare, b.x, work));

  // The stiffness: A = K_T (the assembled matrix at x, lower triangle) against −∂f/∂x.
  b.net.damping_time = 0.0;
  NetworkSystem system(b.net);
  system.assemble(b.net, b.x, 0.0, 1.0);
  const Eigen::Matrix3Xd zero = Eigen::Matrix3Xd::Zero(3, b.net.node_capacity());
  for (int i = 0; i < b.net.anchors.count(); ++i) {
    const int p = b.net.anchors.node[static_cast<std::size_t>(i)];
    const int d = system.dof_of()[static_cast<std::size_t>(3 * p + 2)];
    ASSERT_GE(d, 0);
    const double step = 1e-9;
    Eigen::Matrix3Xd xp = b.x, xm = b.x, fp(3, b.net.node_capacity()), fm(3, b.net.node_capacity());
    xp(2, p) += step, xm(2, p) -= step;
    network_forces(b.net, xp, zero, fp);
    network_forces(b.net, xm, zero, fm);
    // The diagonal entry ∂(−f_pz)/∂x_pz: K_T is exact for the spring stretch and the anchor; the
    // projected transverse and the volume terms differ at O(strain) (1 % here): 10⁻⁴ of it.
    const double derivative = -(fp(2, p) - fm(2, p)) / (2.0 * step);
    const double diagonal = system.matrix().coeff(d, d);
    EXPECT_NEAR(diagonal, derivative, 1e-3 * derivative);
    EXPECT_GT(diagonal, b.net.anchors.stiffness[static_cast<std::size_t>(i)]);
  }
}

/// The largest energy over the initial one in `steps` symplectic Euler steps of `ratio` times
/// the computed stability limit, with anchors held still and no damping.
double anchored_energy_growth(double ratio, int steps) {
  Anchored b = anchored_block(2e4, 0.0, 9);
  b.net.anchors.velocity.setZero();
  b.v.setZero();
  const double limit = symplectic_euler_stability_limit(highest_angular_frequency(b.net), 0.0);
  Eigen::Matrix3Xd f(3, b.net.node_capacity());
  const Eigen::Matrix3Xd zero = Eigen::Matrix3Xd::Zero(3, b.net.node_capacity());
  const auto energy = [&] {
    double e = network_forces(b.net, b.x, zero, f);
    for (int p = 0; p < b.net.node_count; ++p) e += 0.5 * b.net.mass[static_cast<std::size_t>(p)] * b.v.col(p).squaredNorm();
    return e;
  };
  const double e0 = energy();
  double worst = 1.0;
  for (int k = 0; k < steps && worst < 1e6; ++k) {
    symplectic_euler_step(b.net, b.x, b.v, ratio * limit, f);
    const double e = energy();
    if (!std::isfinite(e)) return INFINITY;
    worst = std::max(worst, e / e0);
  }
  return worst;
}

TEST(CompliantGrasp, ExplicitLimitIncludesTheAnchors) {
  // Anchors of ~2·10⁴ N/m (the clay layer on 2.5 mm cells: k h² ≈ 1.2·10⁴ N/m) on the top nodes
  // of a 3³ block, stiffer than its springs (k₁ ≈ 150 N/m summed over up to 4 cells): the
  // computed limit (power iteration on the assembled stiffness, anchors included) is within 15 %
  // of the measured one — bounded at 0.85 of it, unbounded at 1.15 — and shorter than without them.
  EXPECT_LT(anchored_energy_growth(0.85, 20000), 10.0);
  EXPECT_GT(anchored_energy_growth(1.15, 20000), 1e6);
  Anchored b = anchored_block(2e4, 0.0, 9);
  SpringNetwork bare = b.net;
  bare.anchors = NodeAnchors{};
  EXPECT_GT(highest_angular_frequency(b.net), 1.2 * highest_angular_frequency(bare));
}

TEST(CompliantGrasp, EveryIntegratorSettlesOnTheStaticForce) {
  // clay_pull with the compliant grasp (k = 1.9·10⁹ N/m³, a = 4 mm): pull 0.5 mm at 5 mm/s and
  // hold 0.2 s; the dynamic integrators settle on the static equilibrium (the independent value;
  // η = 10 Pa s damps them), and the compliant grasp holds less than the rigid one would at the
  // same nodes (checked in AStiffLayerRecoversTheRigidGrasp).
  const TetMesh mesh = test::clay_pull_mesh();
  std::vector<double> final_force;
  for (const SpringIntegrator integrator : test::every_spring_integrator) {
    SpringNetworkSetup s = test::clay_pull_setup(integrator);
    s.styluses[0].grasp_stiffness = clay_k;
    s.styluses[0].grasp_disc_radius = 4e-3;
    SpringNetworkModel model(mesh, s);
    EXPECT_EQ(model.attached_nodes(0), 0);
    EXPECT_EQ(model.anchored_nodes(0), 25); // the nodes of the face squares the disc meets (|i|, |j| <= 2)
    std::array<ToolState, 1> tool;
    std::array<ForceSample, 1> force;
    const double dt = 1e-3;
    for (int k = 0; k <= 300; ++k) {
      tool[0].position = Eigen::Vector3d(0.02, 0.0, 0.022 + 5e-3 * dt * std::min(k, 100));
      model.step(tool, dt, force);
      ASSERT_TRUE(force[0].force.allFinite());
      EXPECT_FALSE(force[0].over_budget) << to_string(integrator) << " sample " << k;
    }
    EXPECT_LT(force[0].force.z(), 0.0);
    EXPECT_NEAR(force[0].force.x(), 0.0, 1e-5 * std::abs(force[0].force.z())) << to_string(integrator);
    final_force.push_back(force[0].force.z());
  }
  // Measured: all four within 2·10⁻⁶ of the static force.
  for (std::size_t i = 1; i < final_force.size(); ++i) EXPECT_NEAR(final_force[i], final_force[0], 1e-3 * std::abs(final_force[0])) << i;
}

} // namespace
} // namespace kerf
