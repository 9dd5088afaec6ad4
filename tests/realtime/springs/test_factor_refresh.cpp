// The kept factor and its refresh (docs/spring-network.md §2, "The kept factor and its
// refresh"): the exact tangent is the forces' derivative (central differences are the second
// method); a refreshed run is reproducible and agrees with the run that factorises on the
// stepping thread wherever both converged (to the Newton tolerance); a blade pressed through
// the snap-through of potato_rect_cut's crushed cells converges with the exact tangent.

#include "tests/realtime/springs/model_fixtures.hpp"
#include "tests/realtime/springs/network_fixtures.hpp"

#include "meshes/box_tet_mesh.hpp"
#include "realtime/springs/spring_network_model.hpp"

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <random>

namespace kerf {
namespace {

TEST(CellTangent, ExactIsTheDerivativeOfTheForcesAndProjectedIsPositiveSemiDefinite) {
  // One cell crushed along z (its springs compressed, J ≈ 0.6) and sheared, with the volume
  // term: K_exact = −∂f/∂x by central differences (h = 10⁻⁷ of the cell; truncation O(h²)).
  const double h = 2.5e-3;
  const SpringNetwork net = test::full_block(1, h, identify_cell_stiffness(3e6, 0.45, h, true).stiffness, 1080.0);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Matrix<double, 3, 8> x;
  for (int a = 0; a < 8; ++a) {
    x.col(a) = net.rest.col(net.cell_nodes[0][static_cast<std::size_t>(a)]);
    x(2, a) *= 0.6;
    x(0, a) += 0.2 * x(2, a) + 0.05 * h * u(rng);
    x(1, a) += 0.05 * h * u(rng);
  }
  Eigen::Matrix<double, 24, 24> exact, projected, numeric;
  cell_stiffness_matrix(net, 0, x, exact, CellTangent::exact);
  cell_stiffness_matrix(net, 0, x, projected, CellTangent::projected);
  const Eigen::Matrix<double, 3, 8> v = Eigen::Matrix<double, 3, 8>::Zero();
  Eigen::Matrix<double, 3, 8> fp, fm;
  const double step = 1e-7 * h;
  for (int j = 0; j < 24; ++j) {
    Eigen::Matrix<double, 3, 8> xp = x, xm = x;
    xp(j % 3, j / 3) += step;
    xm(j % 3, j / 3) -= step;
    cell_forces(net, 0, xp, v, fp);
    cell_forces(net, 0, xm, v, fm);
    for (int i = 0; i < 24; ++i) numeric(i, j) = -(fp(i % 3, i / 3) - fm(i % 3, i / 3)) / (2.0 * step);
  }
  EXPECT_LT((exact - numeric).cwiseAbs().maxCoeff(), 1e-6 * numeric.cwiseAbs().maxCoeff());
  // The projection leaves out what the crushed cell needs: it differs from the derivative.
  EXPECT_GT((projected - numeric).cwiseAbs().maxCoeff(), 1e-2 * numeric.cwiseAbs().maxCoeff());
  using Matrix24 = Eigen::Matrix<double, 24, 24>;
  const double lowest = Eigen::SelfAdjointEigenSolver<Matrix24>(projected).eigenvalues().minCoeff();
  EXPECT_GT(lowest, -1e-9 * projected.cwiseAbs().maxCoeff());
}

/// clay_tear's bar (12 x 4 x 4 cells, 5 mm) pulled apart by two styluses, implicit Euler: the
/// x forces of both styluses, and whether each sample converged.
struct TearRun {
  std::vector<double> force;
  std::vector<bool> converged;
  int splits = 0;
  long refreshes = 0;
  int most_take_up_corrections = 0;
};

TearRun tear_run(FactorRefreshPolicy policy, int samples) {
  const TetMesh mesh = test::clay_tear_mesh();
  SpringNetworkSetup s = test::clay_tear_setup(SpringIntegrator::implicit_euler);
  s.refresh = policy;
  SpringNetworkModel model(mesh, s);
  TearRun run;
  std::array<ToolState, 2> tools;
  std::array<ForceSample, 2> forces;
  for (int k = 0; k < samples; ++k) {
    tools[0].position = {0.015 - 5e-6 * k, 0.0, 0.022};
    tools[1].position = {0.045 + 5e-6 * k, 0.0, 0.022};
    model.step(tools, 1e-3, forces);
    run.force.push_back(forces[0].force.x());
    run.force.push_back(forces[1].force.x());
    run.converged.push_back(!forces[0].over_budget);
  }
  run.splits = model.tears();
  run.refreshes = model.refreshes();
  run.most_take_up_corrections = model.most_take_up_corrections();
  return run;
}

/// Where both runs converged, both styluses' forces within 100 x the Newton tolerance (10⁻⁵ k₁ h
/// on clay_tear's 5 mm cells); returns the samples compared.
int expect_forces_agree_where_both_converged(const TearRun& a, const TearRun& b) {
  const double k1h = identify_cell_stiffness(0.5e6, 0.45, 5e-3, true).stiffness.edge * 5e-3;
  int compared = 0;
  for (std::size_t k = 0; k < a.converged.size() && k < b.converged.size(); ++k) {
    if (!a.converged[k] || !b.converged[k]) continue;
    ++compared;
    for (std::size_t t = 0; t < 2; ++t) EXPECT_NEAR(a.force[2 * k + t], b.force[2 * k + t], 100 * 1e-5 * k1h) << "sample " << k;
  }
  return compared;
}

TEST(FactorRefresh, RefreshedRunIsReproducibleAndFollowsTheSynchronousOne) {
  // 330 samples: the first splits come near sample 205 (each stylus 1 mm out).
  const int samples = 330;
  const TearRun a = tear_run({}, samples), b = tear_run({}, samples);
  EXPECT_GT(a.splits, 0);
  EXPECT_GT(a.refreshes, 0);
  // Deterministic adoption: the same run, bit for bit, whatever the worker's timing.
  EXPECT_EQ(a.force, b.force);
  EXPECT_EQ(a.converged, b.converged);
  // Against delay 0 (each refresh adopted in the call that asked for it, the worker waited for:
  // the factor is as fresh as the old synchronous stepper's): where both converged, the forces
  // agree to the Newton tolerance's scale (residual ≤ 10⁻⁵ k₁ h on each free node; the force on
  // a stylus sums its grasped nodes' residual-free internal forces, so ~10 nodes x that).
  const TearRun synchronous = tear_run({0, 4}, samples);
  EXPECT_GT(expect_forces_agree_where_both_converged(a, synchronous), samples * 9 / 10);
}

TEST(FactorRefresh, TakingUpAFactorOverCallsFollowsTakingItUpAtOnce) {
  // 760 samples: through the crack's bursts (near sample 720 a factor is collected with ten
  // splits made since its snapshot). Corrected for two of them per call (the default), the
  // collected factor is taken up over several calls while the kept one serves; against taking
  // it up at once (corrections_per_call 0, each collected factor corrected for all its splits
  // in the collecting call), where both converged the forces agree to the Newton tolerance's
  // scale (the yardstick of the test above), and the bursts did come.
  const int samples = 760;
  FactorRefreshPolicy at_once;
  at_once.corrections_per_call = 0;
  const TearRun spread = tear_run({}, samples), whole = tear_run(at_once, samples);
  EXPECT_EQ(spread.splits, whole.splits);
  EXPECT_GT(whole.most_take_up_corrections, 2);
  EXPECT_LE(spread.most_take_up_corrections, 2);
  EXPECT_GT(expect_forces_agree_where_both_converged(spread, whole), samples * 9 / 10);
}

} // namespace
} // namespace kerf
