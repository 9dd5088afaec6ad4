// SplitCorrection: the kept factor of a system with room for splits (coupled or decoupled
// shadows), corrected for vertex splits made after its matrix was assembled, solves like a fresh
// factorisation of the torn network's matrix (the same state, the same tangent). The second
// method is that fresh factorisation. And a system with decoupled shadows analysed on a torn
// network (what the factor refresh's worker builds) solves like the torn network's plain system.

#include "tests/realtime/springs/network_fixtures.hpp"

#include "realtime/springs/network_system.hpp"
#include "realtime/springs/newton_stepper.hpp"
#include "realtime/springs/split_correction.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <string>

namespace kerf {
namespace {

/// Splits the node at lattice point g: the cells whose grid index along `axis` is at least g's
/// take a copy (the node keeps the others), masses shared by cell count as VertexTearing does.
int split_at(SpringNetwork& net, const Eigen::Vector3i& g, int axis) {
  int original = -1;
  for (int n = 0; n < net.node_count; ++n)
    if (test::grid_of(net, n) == g) original = n;
  if (original < 0) return -1;
  const int copy = net.node_count++;
  net.rest.col(copy) = net.rest.col(original);
  net.constraint[static_cast<std::size_t>(copy)] = net.constraint[static_cast<std::size_t>(original)];
  int moved = 0, total = 0;
  for (int c = 0; c < net.cell_count(); ++c)
    for (int& id : net.cell_nodes[static_cast<std::size_t>(c)])
      if (id == original) {
        ++total;
        if (net.cell_index[static_cast<std::size_t>(c)][axis] >= g[axis]) id = copy, ++moved;
      }
  net.mass[static_cast<std::size_t>(copy)] = moved * net.cell_mass / 8.0;
  net.mass[static_cast<std::size_t>(original)] = (total - moved) * net.cell_mass / 8.0;
  merge_springs(net);
  return original;
}

Eigen::Matrix3Xd by_node(const NetworkSystem& system, const SpringNetwork& net, const Eigen::VectorXd& u) {
  Eigen::Matrix3Xd out = Eigen::Matrix3Xd::Zero(3, net.node_count);
  for (int n = 0; n < net.node_count; ++n)
    for (int i = 0; i < 3; ++i)
      if (const int d = system.dof_of()[static_cast<std::size_t>(3 * n + i)]; d >= 0) out(i, n) = u[d];
  return out;
}

/// A right-hand side given per node, in `system`'s numbering (zero on unused shadows).
Eigen::VectorXd in_dofs(const NetworkSystem& system, const SpringNetwork& net, const Eigen::Matrix3Xd& b) {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(system.dof_count());
  for (int n = 0; n < net.node_count; ++n)
    for (int i = 0; i < 3; ++i)
      if (const int d = system.dof_of()[static_cast<std::size_t>(3 * n + i)]; d >= 0) out[d] = b(i, n);
  return out;
}

/// A 4^3 clay block on its fixed base, its free nodes moved at random by 3 % of a cell.
struct Block {
  double h = 2.5e-3, dt = 1e-3;
  SpringNetwork net;
  Eigen::Matrix3Xd x;
  Block() : net(test::full_block(4, h, identify_cell_stiffness(0.5e6, 0.45, h, true).stiffness, 1700.0)) {
    for (int n = 0; n < net.node_count; ++n)
      if (test::grid_of(net, n).z() == 0) net.constraint[static_cast<std::size_t>(n)] = fix_all;
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    x = net.rest;
    for (int n = 0; n < net.node_count; ++n)
      for (int i = 0; i < 3; ++i)
        if (!(net.constraint[static_cast<std::size_t>(n)] & (1u << i))) x(i, n) += 0.03 * h * u(rng);
  }
};

class SplitCorrectionIn : public testing::TestWithParam<NetworkSystem::SplitRoom> {};

TEST_P(SplitCorrectionIn, KeptFactorCorrectedForSplitsSolvesLikeAFreshFactor) {
  const Block block;
  const SpringNetwork& net = block.net;
  const Eigen::Matrix3Xd& x = block.x;
  const double wm = 1.0 / (block.dt * block.dt), wk = 1.02;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const CellTangent tangent : {CellTangent::projected, CellTangent::exact}) {
    SpringNetwork torn = net;
    Eigen::Matrix3Xd xt = x;
    NetworkSystem kept(NetworkSystem::SolvePrecision::single_precision);
    kept.rebuild(torn, GetParam());
    kept.assemble(torn, xt, wm, wk, tangent);
    ASSERT_TRUE(kept.factorize());
    // Corrected as each split is made, and (a factor adopted after both) for both afterwards,
    // the first with the second's copy taken back at its original.
    SplitCorrection correction, afterwards;
    correction.reserve(kept.dof_count());
    afterwards.reserve(kept.dof_count());
    SplitCorrection::NodePair made[2];
    double before[2] = {};
    // Two splits, the second at a neighbour of the first (its cells already re-pointed once).
    int n = 0;
    for (const auto& [g, axis] : {std::pair{Eigen::Vector3i(2, 2, 2), 0}, std::pair{Eigen::Vector3i(2, 2, 3), 0}}) {
      const int copy = torn.node_count;
      const int original = split_at(torn, g, axis);
      ASSERT_GE(original, 0);
      xt.col(copy) = xt.col(original);
      ASSERT_TRUE(kept.bind_split_vertices(torn));
      before[n] = torn.mass[static_cast<std::size_t>(original)] + torn.mass[static_cast<std::size_t>(copy)];
      made[n++] = {copy, original};
      ASSERT_TRUE(correction.add(kept, torn, xt, original, copy, before[n - 1], wm, wk, tangent));
    }
    EXPECT_EQ(correction.splits(), 2);
    ASSERT_TRUE(afterwards.add(kept, torn, xt, made[0].original, made[0].copy, before[0], wm, wk, tangent, &made[1], 1));
    ASSERT_TRUE(afterwards.add(kept, torn, xt, made[1].original, made[1].copy, before[1], wm, wk, tangent));
    // With decoupled shadows the system cannot be assembled torn until it is analysed again.
    if (GetParam() == NetworkSystem::SplitRoom::decoupled_shadows) {
      EXPECT_FALSE(kept.factorize());
    }
    // The fresh factor of the torn network at the same state (its own tear-ready analysis).
    NetworkSystem fresh(NetworkSystem::SolvePrecision::single_precision);
    fresh.rebuild(net, true);
    ASSERT_TRUE(fresh.bind_split_vertices(torn));
    fresh.assemble(torn, xt, wm, wk, tangent);
    ASSERT_TRUE(fresh.factorize());
    Eigen::Matrix3Xd b_node(3, torn.node_count);
    for (int n = 0; n < torn.node_count; ++n)
      for (int i = 0; i < 3; ++i) b_node(i, n) = u(rng);
    const Eigen::VectorXd b = in_dofs(kept, torn, b_node), bf = in_dofs(fresh, torn, b_node);
    Eigen::VectorXd a(kept.dof_count()), e(fresh.dof_count()), plain(kept.dof_count()), late(kept.dof_count());
    correction.solve(kept, b, a);
    afterwards.solve(kept, b, late);
    fresh.solve(bf, e);
    kept.solve(b, plain);
    const Eigen::Matrix3Xd corrected = by_node(kept, torn, a), expected = by_node(fresh, torn, e),
                           uncorrected = by_node(kept, torn, plain), corrected_late = by_node(kept, torn, late);
    const double scale = expected.cwiseAbs().maxCoeff();
    // Single-precision solves: a relative error of κ(A) 10⁻⁷ at most.
    EXPECT_LT((corrected - expected).cwiseAbs().maxCoeff(), 1e-4 * scale) << "tangent " << static_cast<int>(tangent);
    EXPECT_LT((corrected_late - expected).cwiseAbs().maxCoeff(), 1e-4 * scale) << "tangent " << static_cast<int>(tangent);
    // and the correction matters: the kept factor alone is off by far more.
    EXPECT_GT((uncorrected - expected).cwiseAbs().maxCoeff(), 1e-2 * scale);
  }
}

INSTANTIATE_TEST_SUITE_P(Room, SplitCorrectionIn,
                         testing::Values(NetworkSystem::SplitRoom::coupled_shadows, NetworkSystem::SplitRoom::decoupled_shadows),
                         [](const testing::TestParamInfo<NetworkSystem::SplitRoom>& info) {
                           return info.param == NetworkSystem::SplitRoom::coupled_shadows ? std::string("CoupledShadows")
                                                                                          : std::string("DecoupledShadows");
                         });

TEST(SplitRoom, DecoupledShadowsOfATornNetworkSolveLikeItsOwnSystemAndStayOutOfTheFactor) {
  // What the factor refresh's worker builds: a torn network analysed again with decoupled
  // shadows, against the same torn network's plain system (no room), in double precision.
  Block block;
  SpringNetwork& torn = block.net;
  const int copy = torn.node_count;
  const int original = split_at(torn, Eigen::Vector3i(2, 2, 2), 0);
  ASSERT_GE(original, 0);
  block.x.col(copy) = block.x.col(original);
  const double wm = 1.0 / (block.dt * block.dt), wk = 1.02;
  NetworkSystem room, plain;
  room.rebuild(torn, NetworkSystem::SplitRoom::decoupled_shadows);
  plain.rebuild(torn, NetworkSystem::SplitRoom::none);
  // The split pair has no shadow (a vertex splits once), every other free node one.
  int free_dofs = 0, free_dofs_alone = 0;
  for (int n = 0; n < torn.node_count; ++n)
    for (int i = 0; i < 3; ++i)
      if (!(torn.constraint[static_cast<std::size_t>(n)] & (1u << i))) {
        ++free_dofs;
        free_dofs_alone += n == original || n == copy ? 0 : 1;
      }
  EXPECT_EQ(plain.dof_count(), free_dofs);
  EXPECT_EQ(room.factor_dofs(), free_dofs);
  EXPECT_EQ(room.dof_count(), free_dofs + free_dofs_alone);
  // The factor is the torn network's own: as many entries as the plain one's, plus one per shadow.
  EXPECT_EQ(room.factor_entries(), plain.factor_entries() + free_dofs_alone);
  for (NetworkSystem* s : {&room, &plain}) {
    s->assemble(torn, block.x, wm, wk, CellTangent::exact);
    ASSERT_TRUE(s->factorize());
  }
  Eigen::Matrix3Xd b_node(3, torn.node_count);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n = 0; n < torn.node_count; ++n)
    for (int i = 0; i < 3; ++i) b_node(i, n) = u(rng);
  const Eigen::VectorXd b = in_dofs(room, torn, b_node), bp = in_dofs(plain, torn, b_node);
  Eigen::VectorXd a(room.dof_count()), e(plain.dof_count());
  room.solve(b, a);
  plain.solve(bp, e);
  const Eigen::Matrix3Xd got = by_node(room, torn, a), expected = by_node(plain, torn, e);
  EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 1e-10 * expected.cwiseAbs().maxCoeff());
  // An unused shadow's equation is decoupled with a zero right-hand side: its solution is zero.
  for (int d = room.factor_dofs(); d < room.dof_count(); ++d) EXPECT_EQ(a[d], 0.0);
}

TEST(NewtonStepperSplit, KeptFactorIsCorrectedAtTheStateItWasAssembledAt) {
  // The kept factor is assembled at one state (the block at rest) and a vertex split is made at
  // another (the block's top sheared by 20 % of its height along x and 10 % along y, where its
  // springs' lateral stiffness (1 − L/l) k is far from the zero it has at rest). The correction
  // makes the kept factor exact for the new topology at the kept factor's own state, so the
  // stepper's first step after the split must be the one a factor of the torn network at that
  // state gives: the second method is a stepper built on the torn network and primed there.
  // Taking the moved cells' stiffness at the state of the split instead would remove from the
  // original's rows a stiffness the kept matrix never held (a matrix of no one state).
  Block block;
  const SpringNetwork& net = block.net;
  const double dt = block.dt, height = 4 * block.h;
  const Eigen::Matrix3Xd at_rest = net.rest;
  Eigen::Matrix3Xd sheared = net.rest;
  for (int n = 0; n < net.node_count; ++n) {
    const double z = net.rest(2, n) - net.block.origin.z();
    sheared(0, n) += 0.2 * z * z / height;
    sheared(1, n) += 0.1 * z * z / height;
  }
  FactorRefreshPolicy policy;
  policy.delay = 1000; // no fresh factor is adopted within the test: the kept one steps
  const int copy = net.node_count;
  SpringNetwork torn = net;
  const int original = split_at(torn, Eigen::Vector3i(2, 2, 2), 0);
  ASSERT_GE(original, 0);
  const auto with_copy = [&](Eigen::Matrix3Xd x) {
    x.col(copy) = x.col(original);
    return x;
  };
  const Eigen::Matrix3Xd start = with_copy(sheared);
  const Eigen::Matrix3Xd zero = Eigen::Matrix3Xd::Zero(3, start.cols());

  NewtonStepper kept(net, NewtonStepper::Mode::implicit_euler, 1, 1e-5, true, policy);
  ASSERT_TRUE(kept.prime(net, at_rest, dt));
  Eigen::Matrix3Xd x = start, v = zero;
  ASSERT_TRUE(kept.retopologise(torn, x));
  const NewtonReport report = kept.advance(torn, x, v, dt);
  EXPECT_EQ(report.factorisations, 0); // the kept factor, corrected: nothing factorised here

  NewtonStepper fresh(torn, NewtonStepper::Mode::implicit_euler, 1, 1e-5, true, policy);
  ASSERT_TRUE(fresh.prime(torn, with_copy(at_rest), dt));
  Eigen::Matrix3Xd xf = start, vf = zero;
  fresh.advance(torn, xf, vf, dt);

  // The same step to single precision's reach (both factors are read in single precision).
  const int n = torn.node_count;
  const Eigen::Matrix3Xd step = x.leftCols(n) - start.leftCols(n), expected = xf.leftCols(n) - start.leftCols(n);
  const double scale = expected.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0.0);
  EXPECT_LT((step - expected).cwiseAbs().maxCoeff(), 1e-4 * scale);

  // The states are far enough apart to tell: the torn network's factor at the sheared state
  // steps differently by far more than that.
  NewtonStepper now(torn, NewtonStepper::Mode::implicit_euler, 1, 1e-5, true, policy);
  ASSERT_TRUE(now.prime(torn, start, dt));
  Eigen::Matrix3Xd xn = start, vn = zero;
  now.advance(torn, xn, vn, dt);
  EXPECT_GT((xn.leftCols(n) - xf.leftCols(n)).cwiseAbs().maxCoeff(), 1e-2 * scale);
}

TEST(SplitCorrection, ASplitItCannotTakeLeavesTheSplitsBeforeItCorrectedFor) {
  // Two splits corrected for, then a third whose H cannot be factorised (a mass that is not a
  // number makes H not finite): `add` refuses it, and the correction must solve as one that
  // holds the first two alone (the second method) — the refused attempt factorised H in place.
  const Block block;
  const double wm = 1.0 / (block.dt * block.dt), wk = 1.02;
  SpringNetwork torn = block.net;
  Eigen::Matrix3Xd xt = block.x;
  NetworkSystem kept(NetworkSystem::SolvePrecision::single_precision);
  kept.rebuild(torn, NetworkSystem::SplitRoom::decoupled_shadows);
  kept.assemble(torn, xt, wm, wk, CellTangent::projected);
  ASSERT_TRUE(kept.factorize());
  SplitCorrection::NodePair made[3];
  double before[3] = {};
  int n = 0;
  for (const Eigen::Vector3i& g : {Eigen::Vector3i(1, 1, 2), Eigen::Vector3i(3, 2, 2), Eigen::Vector3i(2, 3, 3)}) {
    const int copy = torn.node_count;
    const int original = split_at(torn, g, 0);
    ASSERT_GE(original, 0);
    xt.col(copy) = xt.col(original);
    before[n] = torn.mass[static_cast<std::size_t>(original)] + torn.mass[static_cast<std::size_t>(copy)];
    made[n++] = {copy, original};
  }
  ASSERT_TRUE(kept.bind_split_vertices(torn));
  const auto add = [&](SplitCorrection& c, int k, double mass_before) {
    return c.add(kept, torn, xt, made[k].original, made[k].copy, mass_before, wm, wk, CellTangent::projected, made + k + 1,
                 2 - k);
  };
  SplitCorrection two;
  two.reserve(kept.dof_count());
  ASSERT_TRUE(add(two, 0, before[0]));
  ASSERT_TRUE(add(two, 1, before[1]));
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd b(kept.dof_count()), expected(kept.dof_count()), got(kept.dof_count());
  for (int d = 0; d < kept.dof_count(); ++d) b[d] = d < kept.factor_dofs() ? u(rng) : 0.0;
  two.solve(kept, b, expected);
  ASSERT_TRUE(expected.allFinite());
  SplitCorrection three;
  three.reserve(kept.dof_count());
  ASSERT_TRUE(add(three, 0, before[0]));
  ASSERT_TRUE(add(three, 1, before[1]));
  EXPECT_FALSE(add(three, 2, std::numeric_limits<double>::quiet_NaN()));
  EXPECT_EQ(three.splits(), 2);
  three.solve(kept, b, got);
  EXPECT_EQ((got - expected).cwiseAbs().maxCoeff(), 0.0);
}

} // namespace
} // namespace kerf
