// LatticeForces (the vectorised lattice loops) against the independent cell-by-cell sum of
// cell_forces, and NetworkSystem's own supernodal solves against a dense solve of its matrix.

#include "realtime/springs/lattice_forces.hpp"
#include "realtime/springs/network_system.hpp"
#include "realtime/springs/symplectic_euler.hpp"
#include "tests/realtime/springs/network_fixtures.hpp"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <random>

namespace kerf {
namespace {

/// Σ over cells of cell_forces (each cell's own 28 springs and volume term): the reference.
double cell_sum(const SpringNetwork& net, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v, Eigen::Matrix3Xd& f) {
  f.setZero();
  double energy = 0.0;
  Eigen::Matrix<double, 3, 8> xc, vc, fc;
  for (int c = 0; c < net.cell_count(); ++c) {
    const auto& nodes = net.cell_nodes[static_cast<std::size_t>(c)];
    for (int a = 0; a < 8; ++a) xc.col(a) = x.col(nodes[static_cast<std::size_t>(a)]), vc.col(a) = v.col(nodes[static_cast<std::size_t>(a)]);
    energy += cell_forces(net, c, xc, vc, fc);
    for (int a = 0; a < 8; ++a) f.col(nodes[static_cast<std::size_t>(a)]) += fc.col(a);
  }
  return energy;
}

/// A 5 x 3 x 4 block (h = 2.5 mm, clay with the volume term, τ = 20 µs) with a third of its
/// cells pruned, every node displaced by up to 5% of h and given a random velocity.
struct Scattered {
  SpringNetwork net;
  Eigen::Matrix3Xd x, v;
};
Scattered scattered_block(unsigned seed, bool margin = false) {
  const double h = 2.5e-3;
  NetworkBlock block;
  block.origin = {0.01, -0.02, 0.003};
  block.cell_size = h;
  block.cells = {5, 3, 4};
  std::vector<bool> keep(60);
  for (std::size_t c = 0; c < keep.size(); ++c) keep[c] = c % 3 != 1;
  // With a margin: the block's last x column and its top layer pruned, so that the kept cells'
  // box (4 x 3 x 3 cells) is smaller than the block.
  if (margin)
    for (std::size_t c = 0; c < keep.size(); ++c)
      if (c % 5 == 4 || c / 15 == 3) keep[c] = false;
  Scattered s{build_spring_network(block, keep, identify_cell_stiffness(0.5e6, 0.45, h, true).stiffness, 1700.0, 2e-5), {}, {}};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  s.x = s.net.rest;
  s.v.setZero(3, s.net.node_capacity());
  for (int n = 0; n < s.net.node_count; ++n)
    for (int i = 0; i < 3; ++i) s.x(i, n) += 0.05 * h * u(rng), s.v(i, n) = 1e-2 * u(rng);
  return s;
}

TEST(LatticeForces, EqualTheCellSum) {
  for (const unsigned seed : {1u, 2u, 3u, 4u, 5u}) {
    Scattered s = scattered_block(seed, seed > 3);
    LatticeForces lattice(s.net);
    ASSERT_TRUE(lattice.applies(s.net));
    Eigen::Matrix3Xd expected(3, s.net.node_capacity()), f(3, s.net.node_capacity());
    const double expected_energy = cell_sum(s.net, s.x, s.v, expected);
    const double energy = lattice.evaluate(s.net, s.x, s.v, f);
    const double scale = expected.leftCols(s.net.node_count).cwiseAbs().maxCoeff();
    EXPECT_LT((f - expected).leftCols(s.net.node_count).cwiseAbs().maxCoeff(), 1e-12 * scale) << "seed " << seed;
    EXPECT_NEAR(energy, expected_energy, 1e-12 * expected_energy) << "seed " << seed;
  }
}

/// Splits `node` of `s` (paper 000 §2.2's vertex split, by hand): its cells after the first
/// move to a copy appended to the nodes, placed `offset` from it; the springs merged again.
/// Returns the cells moved.
int split_by_hand(Scattered& s, int node, const Eigen::Vector3d& offset) {
  const int copy = s.net.node_count++;
  s.x.col(copy) = s.x.col(node) + offset;
  s.v.col(copy) = s.v.col(node);
  s.net.rest.col(copy) = s.net.rest.col(node);
  bool first = true;
  int moved = 0;
  for (auto& nodes : s.net.cell_nodes) {
    bool here = false;
    for (int& id : nodes)
      if (id == node) {
        if (!first) id = copy, here = true;
        first = false;
      }
    moved += here ? 1 : 0;
  }
  merge_springs(s.net);
  return moved;
}

/// The nodes of `s` shared by two cells or more, in order.
std::vector<int> shared_nodes(const Scattered& s) {
  std::vector<int> cells(static_cast<std::size_t>(s.net.node_count), 0), shared;
  for (const auto& nodes : s.net.cell_nodes)
    for (int id : nodes) ++cells[static_cast<std::size_t>(id)];
  for (int n = 0; n < s.net.node_count; ++n)
    if (cells[static_cast<std::size_t>(n)] >= 2) shared.push_back(n);
  return shared;
}

TEST(LatticeForces, EvaluatesATornNetworkWithItsSplitCellsAsExceptions) {
  // After vertex splits (two nodes on one lattice point: no lattice of its own, as a network
  // built torn shows) the lattice built before them evaluates the torn network with the cells at
  // a copy as exceptions. Reference: the cell-by-cell sum of cell_forces on the torn cells.
  Scattered s = scattered_block(4);
  const SpringNetwork untorn = s.net;
  const Eigen::Matrix3Xd x_untorn = s.x, v_untorn = s.v;
  LatticeForces lattice(s.net);
  const std::vector<int> shared = shared_nodes(s);
  ASSERT_GE(shared.size(), 6u);
  Eigen::Matrix3Xd expected(3, s.net.node_capacity()), f(3, s.net.node_capacity());
  const auto agrees = [&](const char* what) {
    EXPECT_FALSE(lattice.applies(s.net)) << what;
    EXPECT_TRUE(lattice.applies_torn(s.net)) << what;
    const double expected_energy = cell_sum(s.net, s.x, s.v, expected);
    f.setConstant(1e9); // every node's force is written
    const double energy = lattice.evaluate(s.net, s.x, s.v, f);
    const double scale = expected.leftCols(s.net.node_count).cwiseAbs().maxCoeff();
    EXPECT_LT((f - expected).leftCols(s.net.node_count).cwiseAbs().maxCoeff(), 1e-12 * scale) << what;
    EXPECT_NEAR(energy, expected_energy, 1e-12 * expected_energy) << what;
  };
  const int moved = split_by_hand(s, shared[0], {2e-5, 0, 0});
  EXPECT_FALSE(LatticeForces(s.net).applies(s.net)); // a lattice built on the torn network is none
  agrees("one split");
  EXPECT_EQ(lattice.exception_count(), moved);
  // The network as it was before the tear, torn once elsewhere: the exceptions found for the
  // first tear are not kept (each merge gives a topology no network had before; a count
  // incremented per merge would repeat the first tear's here).
  s.net = untorn;
  s.x = x_untorn;
  s.v = v_untorn;
  Eigen::Matrix3Xd untorn_f(3, s.net.node_capacity());
  lattice.evaluate(s.net, s.x, s.v, untorn_f);
  const int moved_elsewhere = split_by_hand(s, shared[3], {0, 0, 5e-5});
  agrees("the untorn network torn elsewhere");
  EXPECT_EQ(lattice.exception_count(), moved_elsewhere);
  // More splits, one of them of a copy (the copy's cells split again), the copy far off.
  for (const int node : {shared[2], shared[5], s.net.node_count - 1}) {
    split_by_hand(s, node, {-3e-5, 4e-5, 1e-5});
    agrees("further splits");
  }
}

/// The scattered block with its lowest layer of nodes fixed and one node fixed along x only.
Scattered constrained_block(unsigned seed) {
  Scattered s = scattered_block(seed);
  const double bottom = s.net.rest.row(2).leftCols(s.net.node_count).minCoeff();
  for (int n = 0; n < s.net.node_count; ++n)
    if (s.net.rest(2, n) < bottom + 1e-9) s.net.constraint[static_cast<std::size_t>(n)] = fix_all;
  s.net.constraint[static_cast<std::size_t>(s.net.node_count - 1)] = fix_x;
  return s;
}

TEST(LatticeForces, GershgorinBoundEqualsTheFlatArrays) {
  // The lattice's row sums against gershgorin_frequency_bound over the merged flat spring arrays
  // and the cells one by one (the same bound summed in another order).
  for (const unsigned seed : {1u, 2u}) {
    Scattered s = constrained_block(seed);
    LatticeForces lattice(s.net);
    std::vector<double> work(static_cast<std::size_t>(s.net.node_capacity()));
    const double expected = gershgorin_frequency_bound(s.net, s.x, work);
    EXPECT_NEAR(lattice.gershgorin_bound(s.net, s.x), expected, 1e-12 * expected) << "seed " << seed;
    // A crushed spring (the top edge of the last cell, its nodes 1e-3 h apart) raises the bound
    // the same way on both.
    const auto& top = s.net.cell_nodes.back();
    ASSERT_NE(s.net.constraint[static_cast<std::size_t>(top[7])], fix_all);
    s.x.col(top[7]) = s.x.col(top[6]) + Eigen::Vector3d(2.5e-6, 0, 0);
    const double crushed = gershgorin_frequency_bound(s.net, s.x, work);
    EXPECT_GT(crushed, 10.0 * expected);
    EXPECT_NEAR(lattice.gershgorin_bound(s.net, s.x), crushed, 1e-12 * crushed) << "seed " << seed;
  }
}

/// A moving, damped trajectory of 200 sub-steps of half the stability limit from a displaced
/// state (node 0 of the fixed layer raised 10 µm a step): symplectic_euler_step over
/// network_forces (x, v) and the lattice's own sub-steps in `precision` (y, w).
struct TwoTrajectories {
  Scattered s;
  Eigen::Matrix3Xd x, v, y, w;
};
TwoTrajectories step_both_ways(LatticeForces::ForcePrecision precision) {
  TwoTrajectories t{constrained_block(3), {}, {}, {}, {}};
  Scattered& s = t.s;
  const double h = 0.5 * symplectic_euler_stability_limit(highest_angular_frequency(s.net), s.net.damping_time);
  LatticeForces lattice(s.net);
  t.x = s.x, t.v = s.v;
  Eigen::Matrix3Xd f(3, s.net.node_capacity());
  const int fixed = 0; // a node of the fixed layer, moved by the caller every step
  EXPECT_EQ(s.net.constraint[fixed], fix_all);
  lattice.gather(s.x, s.v);
  for (int k = 1; k <= 200; ++k) {
    const Eigen::Vector3d target = s.net.rest.col(fixed) + Eigen::Vector3d(0, 0, 1e-5 * k), rate(0, 0, 1e-5 / h);
    t.x.col(fixed) = target, t.v.col(fixed) = rate;
    symplectic_euler_step(s.net, t.x, t.v, h, f);
    lattice.place(fixed, target, rate);
    lattice.substep(s.net, h, precision);
  }
  t.y.resize(3, s.net.node_capacity()), t.w.resize(3, s.net.node_capacity());
  lattice.scatter(t.y, t.w);
  return t;
}

TEST(LatticeForces, SubstepsEqualSymplecticEulerSteps) {
  // Sub-steps kept on the lattice (gather, place a prescribed node, substep, scatter) against
  // symplectic_euler_step over network_forces, from a displaced, moving, damped state: the same
  // trajectory to round-off.
  const TwoTrajectories t = step_both_ways(LatticeForces::ForcePrecision::double_precision);
  const int n = t.s.net.node_count;
  EXPECT_LT((t.y - t.x).leftCols(n).cwiseAbs().maxCoeff(), 1e-12 * (t.x - t.s.net.rest).leftCols(n).cwiseAbs().maxCoeff());
  EXPECT_LT((t.w - t.v).leftCols(n).cwiseAbs().maxCoeff(), 1e-10 * t.v.leftCols(n).cwiseAbs().maxCoeff());
  EXPECT_GT((t.x - t.s.x).leftCols(n).cwiseAbs().maxCoeff(), 1e-6); // it did move
}

TEST(LatticeForces, SinglePrecisionSubstepsFollowTheDoubleOnes) {
  // The same moving, damped trajectory as above with the force loops in single precision
  // (positions and velocities in double): it follows symplectic_euler_step's double-precision
  // trajectory to the single-precision round-off of the forces (~10⁻⁷ relative per sub-step).
  const TwoTrajectories t = step_both_ways(LatticeForces::ForcePrecision::single_precision);
  const int n = t.s.net.node_count;
  const double moved = (t.x - t.s.net.rest).leftCols(n).cwiseAbs().maxCoeff();
  const double deviation = (t.y - t.x).leftCols(n).cwiseAbs().maxCoeff();
  EXPECT_LT(deviation, 1e-5 * moved);
  EXPECT_GT(deviation, 0.0); // the single-precision path was taken
  EXPECT_LT((t.w - t.v).leftCols(n).cwiseAbs().maxCoeff(), 1e-4 * t.v.leftCols(n).cwiseAbs().maxCoeff());
}

TEST(NetworkSystem, SolvesAgainstADenseFactorisation) {
  // A = M/h² + K_T at a displaced state of the pruned block (two corner nodes fixed), solved by
  // the supernodal solves on CHOLMOD's factor (double) and with the supernodes' inverted blocks
  // W_s = [T⁻¹; −R T⁻¹] in single precision, against Eigen's dense LLᵀ of the same assembled
  // matrix.
  Scattered s = scattered_block(5);
  s.net.constraint[0] = fix_all;
  s.net.constraint[static_cast<std::size_t>(s.net.node_count - 1)] = fix_x | fix_z;
  for (const auto precision : {NetworkSystem::SolvePrecision::double_precision, NetworkSystem::SolvePrecision::single_precision}) {
    NetworkSystem system(s.net, precision);
    const double dt = 1e-3;
    system.assemble(s.net, s.x, 1.0 / (dt * dt), 1.0);
    ASSERT_TRUE(system.factorize());
    const Eigen::MatrixXd dense = Eigen::MatrixXd(system.matrix()).selfadjointView<Eigen::Lower>();
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Eigen::VectorXd rhs(system.dof_count()), out(system.dof_count());
    for (Eigen::Index k = 0; k < rhs.size(); ++k) rhs[k] = u(rng);
    system.solve(rhs, out);
    const Eigen::VectorXd expected = dense.llt().solve(rhs);
    // Double: round-off of a well-conditioned solve; single: the float blocks' 6e-8 relative
    // entries amplified by the condition number of A (~1e3 here).
    const double tolerance = precision == NetworkSystem::SolvePrecision::double_precision ? 1e-10 : 1e-4;
    EXPECT_LT((out - expected).norm(), tolerance * expected.norm());
  }
}

TEST(NetworkSystem, SinglePrecisionSolveFollowsTheDoubleOneOnAnEightCubedBlock) {
  // The single-precision solve (each supernode's T⁻¹ and R, or the whole [T⁻¹; −R T⁻¹] for
  // supernodes of ≤ 48 columns) against the double-precision supernodal solve on CHOLMOD's
  // factor (checked against a dense LLᵀ above), on the 8³ clay block of the benchmark with
  // its base fixed (1944 dofs): its factor has narrow supernodes and wide ones with rows below
  // them (49–96 columns) and without (the 243-column top separator), so every path of both
  // layouts runs. A = M/h² + (1 + τ/h) K_T at a displaced state.
  const double h = 2.5e-3;
  SpringNetwork net = test::full_block(8, h, identify_cell_stiffness(0.5e6, 0.45, h, true).stiffness, 1700.0, 2e-5);
  for (int q = 0; q < net.node_count; ++q)
    if (net.rest(2, q) < 1e-9) net.constraint[static_cast<std::size_t>(q)] = fix_all;
  Eigen::Matrix3Xd x = net.rest;
  for (int q = 0; q < net.node_count; ++q) x(2, q) += 1e-4 * std::sin(x(0, q) * 400.0), x(0, q) += 5e-5 * std::cos(x(1, q) * 300.0);
  const double dt = 1e-3;
  NetworkSystem single(net, NetworkSystem::SolvePrecision::single_precision), reference(net, NetworkSystem::SolvePrecision::double_precision);
  for (NetworkSystem* system : {&single, &reference}) {
    system->assemble(net, x, 1.0 / (dt * dt), 1.0 + net.damping_time / dt);
    ASSERT_TRUE(system->factorize());
  }
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd rhs(single.dof_count()), out(single.dof_count()), expected(single.dof_count());
  for (Eigen::Index k = 0; k < rhs.size(); ++k) rhs[k] = u(rng);
  single.solve(rhs, out);
  reference.solve(rhs, expected);
  // Single-precision blocks (6e-8 relative) amplified by the condition number of A: measured
  // 2.6e-7 relative at rest (a /tmp program); 1e-4 as in the dense comparison above.
  EXPECT_LT((out - expected).norm(), 1e-4 * expected.norm());
}

TEST(NetworkSystem, TearReadyPatternTakesASplitLikeAFreshAnalysis) {
  // A vertex split bound into the tear-ready pattern (no new analysis) against a fresh analysis of
  // the torn network: the same solution of A u = b node by node (A = M/h² + K_T at a displaced
  // state), the unused shadows decoupled.
  const double h = 2.5e-3;
  SpringNetwork net = test::full_block(3, h, identify_cell_stiffness(0.5e6, 0.45, h, true).stiffness, 1700.0);
  for (int n = 0; n < net.node_count; ++n)
    if (test::grid_of(net, n).z() == 0) net.constraint[static_cast<std::size_t>(n)] = fix_all;
  NetworkSystem ready;
  ready.rebuild(net, true);
  // Split the node at lattice point (1, 1, 1): cells with grid x = 1 take the copy.
  int centre = -1;
  for (int n = 0; n < net.node_count; ++n)
    if (test::grid_of(net, n) == Eigen::Vector3i(1, 1, 1)) centre = n;
  ASSERT_GE(centre, 0);
  const int copy = net.node_count++;
  net.rest.col(copy) = net.rest.col(centre);
  net.constraint[static_cast<std::size_t>(copy)] = net.constraint[static_cast<std::size_t>(centre)];
  for (int c = 0; c < net.cell_count(); ++c)
    if (net.cell_index[static_cast<std::size_t>(c)].x() == 1)
      for (int& id : net.cell_nodes[static_cast<std::size_t>(c)]) id = id == centre ? copy : id;
  net.mass[static_cast<std::size_t>(copy)] = 4 * net.cell_mass / 8.0;
  net.mass[static_cast<std::size_t>(centre)] = 4 * net.cell_mass / 8.0;
  merge_springs(net);
  ASSERT_TRUE(ready.bind_split_vertices(net));
  EXPECT_TRUE(ready.bind_split_vertices(net)); // binding again with nothing new changes nothing
  NetworkSystem fresh(net);

  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Matrix3Xd x = net.rest, b = Eigen::Matrix3Xd::Zero(3, net.node_capacity());
  for (int n = 0; n < net.node_count; ++n)
    for (int i = 0; i < 3; ++i) x(i, n) += 0.02 * h * u(rng), b(i, n) = u(rng);
  const auto solve = [&](NetworkSystem& system) {
    system.assemble(net, x, 1e6, 1.0);
    EXPECT_TRUE(system.factorize());
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(system.dof_count()), out(system.dof_count());
    for (int n = 0; n < net.node_count; ++n)
      for (int i = 0; i < 3; ++i)
        if (const int d = system.dof_of()[static_cast<std::size_t>(3 * n + i)]; d >= 0) rhs[d] = b(i, n);
    system.solve(rhs, out);
    Eigen::Matrix3Xd solution = Eigen::Matrix3Xd::Zero(3, net.node_count);
    for (int n = 0; n < net.node_count; ++n)
      for (int i = 0; i < 3; ++i)
        if (const int d = system.dof_of()[static_cast<std::size_t>(3 * n + i)]; d >= 0) solution(i, n) = out[d];
    return solution;
  };
  EXPECT_GT(ready.dof_count(), fresh.dof_count()); // the unused shadows
  const Eigen::Matrix3Xd a = solve(ready), e = solve(fresh);
  EXPECT_LT((a - e).cwiseAbs().maxCoeff(), 1e-10 * e.cwiseAbs().maxCoeff());
}

} // namespace
} // namespace kerf
