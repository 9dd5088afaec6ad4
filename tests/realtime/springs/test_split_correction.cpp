// SplitCorrection: the kept factor of a tear-ready system, corrected for vertex splits made
// after its matrix was assembled, solves like a fresh factorisation of the torn network's matrix
// (the same state, the same tangent). The second method is that fresh factorisation.

#include "tests/realtime/springs/network_fixtures.hpp"

#include "realtime/springs/network_system.hpp"
#include "realtime/springs/split_correction.hpp"

#include <gtest/gtest.h>

#include <random>

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

TEST(SplitCorrection, KeptFactorCorrectedForSplitsSolvesLikeAFreshFactor) {
  const double h = 2.5e-3, dt = 1e-3;
  SpringNetwork net = test::full_block(4, h, identify_cell_stiffness(0.5e6, 0.45, h, true).stiffness, 1700.0);
  for (int n = 0; n < net.node_count; ++n)
    if (test::grid_of(net, n).z() == 0) net.constraint[static_cast<std::size_t>(n)] = fix_all;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Matrix3Xd x = net.rest;
  for (int n = 0; n < net.node_count; ++n)
    for (int i = 0; i < 3; ++i)
      if (!(net.constraint[static_cast<std::size_t>(n)] & (1u << i))) x(i, n) += 0.03 * h * u(rng);
  const double wm = 1.0 / (dt * dt), wk = 1.02;
  for (const CellTangent tangent : {CellTangent::projected, CellTangent::exact}) {
    SpringNetwork torn = net;
    Eigen::Matrix3Xd xt = x;
    NetworkSystem kept(NetworkSystem::SolvePrecision::single_precision);
    kept.rebuild(torn, true);
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
    // The fresh factor of the torn network at the same state (its own tear-ready analysis).
    NetworkSystem fresh(NetworkSystem::SolvePrecision::single_precision);
    fresh.rebuild(net, true);
    ASSERT_TRUE(fresh.bind_split_vertices(torn));
    fresh.assemble(torn, xt, wm, wk, tangent);
    ASSERT_TRUE(fresh.factorize());
    Eigen::VectorXd b = Eigen::VectorXd::Zero(fresh.dof_count());
    for (int n = 0; n < torn.node_count; ++n)
      for (int i = 0; i < 3; ++i)
        if (const int d = fresh.dof_of()[static_cast<std::size_t>(3 * n + i)]; d >= 0) b[d] = u(rng);
    Eigen::VectorXd a(kept.dof_count()), e(fresh.dof_count()), plain(kept.dof_count()), late(kept.dof_count());
    correction.solve(kept, b, a);
    afterwards.solve(kept, b, late);
    fresh.solve(b, e);
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

} // namespace
} // namespace kerf
