// The three integrators on small networks: energy conservation and the computed stability limit
// of symplectic Euler (against the measured one), unconditional boundedness of implicit Euler.

#include "realtime/springs/lattice_forces.hpp"
#include "realtime/springs/newton_stepper.hpp"
#include "realtime/springs/symplectic_euler.hpp"
#include "tests/realtime/springs/network_fixtures.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace kerf {
namespace {

double kinetic_energy(const SpringNetwork& net, const Eigen::Matrix3Xd& v) {
  double e = 0.0;
  for (int p = 0; p < net.node_count; ++p) e += 0.5 * net.mass[static_cast<std::size_t>(p)] * v.col(p).squaredNorm();
  return e;
}

/// Total energy (kinetic + elastic) of the state.
double total_energy(const SpringNetwork& net, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v) {
  Eigen::Matrix3Xd f(3, net.node_capacity());
  const Eigen::Matrix3Xd zero = Eigen::Matrix3Xd::Zero(3, net.node_capacity());
  return kinetic_energy(net, v) + network_forces(net, x, zero, f);
}

/// A 3^3 block (clay: E = 0.5 MPa, ν = 0.45, ρ = 1700 kg/m^3, h = 2.5 mm), base fixed when
/// `supported`, with every free node displaced randomly by up to 1% of h.
struct Perturbed {
  SpringNetwork net;
  Eigen::Matrix3Xd x, v, f;
};
Perturbed perturbed_block(bool supported, double stiffness_scale = 1.0) {
  const double h = 2.5e-3;
  CellStiffness k = identify_cell_stiffness(0.5e6 * stiffness_scale, 0.45, h, true).stiffness;
  Perturbed p{test::full_block(3, h, k, 1700.0), {}, {}, {}};
  if (supported)
    for (int n = 0; n < p.net.node_count; ++n)
      if (test::grid_of(p.net, n).z() == 0) p.net.constraint[static_cast<std::size_t>(n)] = fix_all;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.01 * h, 0.01 * h);
  p.x = p.net.rest;
  for (int n = 0; n < p.net.node_count; ++n)
    if (!p.net.constraint[static_cast<std::size_t>(n)])
      for (int i = 0; i < 3; ++i) p.x(i, n) += u(rng);
  p.v.setZero(3, p.net.node_capacity());
  p.f.setZero(3, p.net.node_capacity());
  return p;
}

TEST(SpringNetwork, MergedForcesEqualTheCellSum) {
  // network_forces runs over merged parallel springs; the independent value is cell_forces (each
  // cell's own 28 springs and volume term) summed cell by cell, with dashpots (τ > 0) and after
  // a vertex of the block has been split by hand (merge_springs then un-merges its springs).
  Perturbed p = perturbed_block(true);
  p.net.damping_time = 2e-5;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1e-3, 1e-3);
  for (int n = 0; n < p.net.node_count; ++n)
    for (int i = 0; i < 3; ++i) p.v(i, n) = u(rng);
  EXPECT_LT(p.net.springs.count, 28 * p.net.cell_count()); // shared edges and faces were merged
  for (const bool split : {false, true}) {
    if (split) { // the centre node of the 3^3 block's lower middle layer: cells with grid x = 1 take a copy
      int centre = -1;
      for (int n = 0; n < p.net.node_count; ++n)
        if (test::grid_of(p.net, n) == Eigen::Vector3i(1, 1, 1)) centre = n;
      ASSERT_GE(centre, 0);
      const int copy = p.net.node_count++;
      p.x.col(copy) = p.x.col(centre) + Eigen::Vector3d(1e-5, 0, 0);
      p.v.col(copy) = p.v.col(centre);
      for (int c = 0; c < p.net.cell_count(); ++c)
        if (p.net.cell_index[static_cast<std::size_t>(c)].x() == 1)
          for (int& id : p.net.cell_nodes[static_cast<std::size_t>(c)]) id = id == centre ? copy : id;
      merge_springs(p.net);
    }
    Eigen::Matrix3Xd expected = Eigen::Matrix3Xd::Zero(3, p.net.node_capacity());
    double expected_energy = 0.0;
    Eigen::Matrix<double, 3, 8> xc, vc, fc;
    for (int c = 0; c < p.net.cell_count(); ++c) {
      const auto& nodes = p.net.cell_nodes[static_cast<std::size_t>(c)];
      for (int a = 0; a < 8; ++a) xc.col(a) = p.x.col(nodes[static_cast<std::size_t>(a)]), vc.col(a) = p.v.col(nodes[static_cast<std::size_t>(a)]);
      expected_energy += cell_forces(p.net, c, xc, vc, fc);
      for (int a = 0; a < 8; ++a) expected.col(nodes[static_cast<std::size_t>(a)]) += fc.col(a);
    }
    const double energy = network_forces(p.net, p.x, p.v, p.f);
    const double scale = expected.leftCols(p.net.node_count).cwiseAbs().maxCoeff();
    EXPECT_LT((p.f - expected).leftCols(p.net.node_count).cwiseAbs().maxCoeff(), 1e-12 * scale) << "split " << split;
    EXPECT_NEAR(energy, expected_energy, 1e-12 * expected_energy) << "split " << split;
  }
}

TEST(SymplecticEuler, ConservesEnergyWithoutDamping) {
  for (const bool supported : {false, true}) {
    Perturbed p = perturbed_block(supported);
    const double limit = symplectic_euler_stability_limit(highest_angular_frequency(p.net), 0.0);
    const double h = 0.1 * limit;
    const double e0 = total_energy(p.net, p.x, p.v);
    double max_deviation = 0.0, first_window = 0.0, last_window = 0.0;
    const int steps = 100000, window = 5000;
    for (int s = 0; s < steps; ++s) {
      symplectic_euler_step(p.net, p.x, p.v, h, p.f);
      const double e = total_energy(p.net, p.x, p.v);
      max_deviation = std::max(max_deviation, std::abs(e - e0) / e0);
      if (s < window) first_window += e / window;
      if (s >= steps - window) last_window += e / window;
    }
    // Symplectic Euler conserves a modified energy: the true energy oscillates by O(h ω) and does
    // not drift (Hairer, Lubich & Wanner, Geometric Numerical Integration, 2006, §IX.8).
    EXPECT_LT(max_deviation, 0.2);
    EXPECT_LT(std::abs(last_window - first_window) / e0, 1e-3);
  }
}

TEST(SymplecticEuler, SinglePrecisionForcesConserveEnergyWithoutDamping) {
  // The lattice sub-steps with single-precision force loops (the explicit integrator's default):
  // no drift over 10⁵ steps either (the energy's window means, every 10th step sampled).
  for (const bool supported : {false, true}) {
    Perturbed p = perturbed_block(supported);
    const double limit = symplectic_euler_stability_limit(highest_angular_frequency(p.net), 0.0);
    const double h = 0.1 * limit;
    const double e0 = total_energy(p.net, p.x, p.v);
    LatticeForces lattice(p.net);
    ASSERT_TRUE(lattice.applies(p.net));
    lattice.gather(p.x, p.v);
    double max_deviation = 0.0, first_window = 0.0, last_window = 0.0;
    const int steps = 100000, window = 5000;
    for (int s = 0; s < steps; ++s) {
      lattice.substep(p.net, h, LatticeForces::ForcePrecision::single_precision);
      if (s % 10 != 0) continue;
      lattice.scatter(p.x, p.v);
      const double e = total_energy(p.net, p.x, p.v);
      max_deviation = std::max(max_deviation, std::abs(e - e0) / e0);
      if (s < window) first_window += e / (window / 10);
      if (s >= steps - window) last_window += e / (window / 10);
    }
    EXPECT_LT(max_deviation, 0.2);
    EXPECT_LT(std::abs(last_window - first_window) / e0, 1e-3);
  }
}

/// Runs `steps` steps of size h and returns the largest energy over the initial one.
double energy_growth(double h_over_limit, bool supported, int steps) {
  Perturbed p = perturbed_block(supported);
  const double limit = symplectic_euler_stability_limit(highest_angular_frequency(p.net), 0.0);
  const double e0 = total_energy(p.net, p.x, p.v);
  double worst = 1.0;
  for (int s = 0; s < steps; ++s) {
    symplectic_euler_step(p.net, p.x, p.v, h_over_limit * limit, p.f);
    const double e = total_energy(p.net, p.x, p.v);
    if (!std::isfinite(e)) return INFINITY;
    worst = std::max(worst, e / e0);
    if (worst > 1e6) break;
  }
  return worst;
}

TEST(SymplecticEuler, ComputedLimitMatchesTheMeasuredOne) {
  // The computed limit is within 15% of the measured one: bounded at 0.85 of it, unbounded at
  // 1.15 of it (the explicit integrator sub-steps at 0.9 of the computed limit).
  for (const bool supported : {false, true}) {
    EXPECT_LT(energy_growth(0.85, supported, 20000), 10.0);
    EXPECT_GT(energy_growth(1.15, supported, 20000), 1e6);
  }
}

TEST(SymplecticEuler, DampedLimitFormula) {
  // Undamped: 2/ω; damping shortens it: (2/ω)(√(1+ζ²) − ζ), ζ = τω/2.
  EXPECT_DOUBLE_EQ(symplectic_euler_stability_limit(1000.0, 0.0), 2e-3);
  EXPECT_NEAR(symplectic_euler_stability_limit(1000.0, 2e-3), 2e-3 * (std::sqrt(2.0) - 1.0), 1e-15);
}

TEST(ImplicitEuler, BoundedFarBeyondTheExplicitLimit) {
  for (const double stiffness_scale : {1.0, 1e6}) {
    Perturbed p = perturbed_block(true, stiffness_scale);
    const double limit = symplectic_euler_stability_limit(highest_angular_frequency(p.net), 0.0);
    // 100x the explicit limit, and the scene's 1 ms sample at 10^6 x the scene's stiffness.
    const double dt = stiffness_scale > 1.0 ? 1e-3 : 100.0 * limit;
    if (stiffness_scale > 1.0) {
      EXPECT_GT(dt, 100.0 * limit);
    }
    NewtonStepper stepper(p.net, NewtonStepper::Mode::implicit_euler, 20);
    const double e0 = total_energy(p.net, p.x, p.v);
    for (int s = 0; s < 500; ++s) {
      const NewtonReport r = stepper.advance(p.net, p.x, p.v, dt);
      EXPECT_TRUE(r.converged) << "step " << s;
      // Backward Euler dissipates: the energy never rises above the initial one.
      EXPECT_LE(total_energy(p.net, p.x, p.v), e0 * (1.0 + 1e-9)) << "step " << s;
    }
  }
}

TEST(LinearlyImplicitEuler, BoundedFarBeyondTheExplicitLimit) {
  // The same settings for the linearised step (one solve with the factor kept from the first
  // step, no residual check): bounded, and it comes to rest like backward Euler.
  for (const double stiffness_scale : {1.0, 1e6}) {
    Perturbed p = perturbed_block(true, stiffness_scale);
    const double limit = symplectic_euler_stability_limit(highest_angular_frequency(p.net), 0.0);
    const double dt = stiffness_scale > 1.0 ? 1e-3 : 100.0 * limit;
    NewtonStepper stepper(p.net, NewtonStepper::Mode::linearly_implicit_euler, 1);
    const double e0 = total_energy(p.net, p.x, p.v);
    for (int s = 0; s < 500; ++s) {
      stepper.advance(p.net, p.x, p.v, dt);
      ASSERT_LE(total_energy(p.net, p.x, p.v), e0 * (1.0 + 1e-6)) << "step " << s;
    }
    EXPECT_LT(total_energy(p.net, p.x, p.v), 1e-3 * e0);
  }
}

TEST(QuasiStatic, FreeBlockReturnsToRest) {
  // With the base fixed and nothing else prescribed, the equilibrium is the rest shape.
  Perturbed p = perturbed_block(true);
  NewtonStepper stepper(p.net, NewtonStepper::Mode::quasi_static, 30);
  EXPECT_TRUE(stepper.advance(p.net, p.x, p.v, 1e-3).converged);
  EXPECT_LT((p.x - p.net.rest).leftCols(p.net.node_count).cwiseAbs().maxCoeff(), 1e-9 * 2.5e-3);
}

} // namespace
} // namespace kerf
