// The dynamic step (SolverSettings::dynamic: Newmark average acceleration, consistent mass)
// against the closed form of a suddenly loaded elastic bar.
//
// A prismatic bar (length L, section A, E, ν = 0, ρ) bonded at x = 0 and loaded at x = L by an end
// traction σ applied at t = 0 and held. One-dimensional wave theory (e.g. Graff, Wave Motion in
// Elastic Solids, 1975, §2.1; Timoshenko & Goodier §143): a step of stress runs to the bonded end
// and back with the bar velocity c = sqrt(E/ρ); the loaded end moves at σ/(ρ c) until t = 2L/c,
// where it reaches u = 2 σ L/E = twice the static displacement u_s, then returns to rest at 4L/c:
// the response is periodic with period 4L/c and its time average over a period is u_s.
// With ν = 0 the three-dimensional solution is exactly this uniaxial one (no lateral contraction;
// with the Bonet–Wood neo-Hookean law and λ = 0, S₂₂ = μ(1 − 1/λ₂²) = 0 gives λ₂ = 1 at any
// stretch), and on the x-layered box mesh the discrete one is too (the end face stays plane).
// Independent checks:
//   peak           max u(L, t) = 2 u_s (the discrete system's modes all start at rest: each adds
//                  c_i (1 − cos ω_i t) with c_i >= 0, so the peak is below 2 u_s and near it)
//   half period    the peak at t = 2L/c
//   mean           the time average over [0, 4L/c] is u_s
//   energy         the trapezoid-rule work of the end force equals strain + kinetic energy at every
//                  step: the trapezoidal rule's energy identity (Hughes, The Finite Element Method,
//                  §9.1; exact for a linear system; the strain here is 10⁻⁴, so nearly linear)
// The damped bar (MaterialRegion::damping, reference/material/kelvin_voigt.hpp): the same bar
// released from a static stretch vibrates freely; with ν = 0 the Kelvin–Voigt stress is the 1-D
// σ = E ε + τ E ε̇ (τ = η/E), stiffness-proportional damping, so mode k decays with the damping
// ratio ζ_k = ω_k τ/2 (Chopra, Dynamics of Structures, §11.4) and the logarithmic decrement of
// the first mode's free vibration is δ = 2πζ₁/√(1 − ζ₁²) (Chopra §2.2), with ω₁ = (π/2) c/L
// (the fixed–free bar's first mode; Graff §2.1). Higher modes (ω₃ = 3ω₁, ζ₃ = 3ζ₁) decay nine
// times faster, so from the second period on the end motion is the first mode alone.

#include "reference/finite_strain_solver.hpp"
#include "reference/load_path.hpp"
#include "tests/reference/reference_test_meshes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <cstdio>
#include <vector>

namespace kerf::reference {
namespace {

TEST(DynamicBar, SuddenlyLoadedBarReachesTwiceTheStaticDisplacement) {
  const double L = 0.1, b = 0.01, E = 1e6, rho = 1000.0, sigma = 100.0; // strain σ/E = 1e-4
  const double c = std::sqrt(E / rho), period = 4.0 * L / c, u_static = sigma * L / E;
  FiniteStrainProblem p;
  p.mesh = test::named_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(L, b, b), 20, 1, 1);
  p.materials.push_back({"body", LawKind::neo_hookean, E, 0.0, rho});
  p.displacement_boundaries.push_back({"xmin", DisplacementBoundary::Kind::bonded, {}, {}});
  p.tractions.push_back({"xmax", Eigen::Vector3d(sigma * b * b, 0.0, 0.0)});
  SolverSettings settings;
  settings.dynamic = true;
  FiniteStrainSolver solver(p, settings);

  const int steps_per_period = 400;
  const double h = period / steps_per_period, F = sigma * b * b;
  const Eigen::Vector3d tip(L, 0.5 * b, 0.5 * b);
  double u_prev = 0.0, F_prev = 0.0, work = 0.0, peak = 0.0, peak_time = 0.0, mean = 0.0, worst_energy = 0.0;
  for (int k = 1; k <= steps_per_period; ++k) {
    const double t = k * h;
    // The load factor 1 from the first step on: the traction is applied within [0, h].
    const EquilibriumReport r = solver.solve({1.0, Eigen::Vector3d::Zero(), t});
    ASSERT_TRUE(r.converged) << "t = " << t << ": " << r.failure;
    // The end face's mean displacement ū = (1/A) ∫ u dA, exact for the P1 field on its two
    // triangles: (1/6)(2 u_p + 2 u_q + u_r + u_s) with p–q the diagonal the face is cut along
    // (the one whose corners average to the centre's value). The uniform traction does the work
    // F ū (its nodal forces are ∫ t N_i dA).
    const double u00 = solver.displacement_at({L, 0.0, 0.0}).x(), ubb = solver.displacement_at({L, b, b}).x();
    const double ub0 = solver.displacement_at({L, b, 0.0}).x(), u0b = solver.displacement_at({L, 0.0, b}).x();
    const double centre = solver.displacement_at(tip).x();
    const bool diagonal_00_bb = std::abs(centre - 0.5 * (u00 + ubb)) <= std::abs(centre - 0.5 * (ub0 + u0b));
    const double u = diagonal_00_bb ? (2.0 * (u00 + ubb) + ub0 + u0b) / 6.0 : (2.0 * (ub0 + u0b) + u00 + ubb) / 6.0;
    work += 0.5 * (F_prev + F) * (u - u_prev); // trapezoid rule, F_0 = 0 (unloaded at rest)
    const double energy = solver.strain_energy() + r.kinetic_energy;
    worst_energy = std::max(worst_energy, std::abs(work - energy) / (F * u_static));
    mean += 0.5 * (u + u_prev) * h / period;
    if (u > peak) {
      peak = u;
      peak_time = t;
    }
    u_prev = u;
    F_prev = F;
  }
  std::printf("dynamic bar: peak %.5f u_s at t = %.5f (2L/c = %.5f) s, mean %.5f u_s, worst |W - U - K| %.2e F u_s\n",
              peak / u_static, peak_time, 2.0 * L / c, mean / u_static, worst_energy);
  // 2% of the closed-form peak 2 u_s: the 20 elements along the bar round its corner at 2L/c
  // (measured 1.970 u_s at t = 0.986 × 2L/c; 400 steps per period).
  EXPECT_NEAR(peak, 2.0 * u_static, 0.02 * 2.0 * u_static);
  EXPECT_LT(peak, 2.0 * u_static);
  EXPECT_NEAR(peak_time, 2.0 * L / c, 0.03 * 2.0 * L / c);
  EXPECT_NEAR(mean, u_static, 0.01 * u_static);
  EXPECT_LT(worst_energy, 1e-5); // measured 4e-7 (the law's nonlinearity at strain 1e-4)
}

/// The end face's mean displacement ū = (1/A) ∫ u dA of the box bar (see the first test).
double end_displacement(const FiniteStrainSolver& solver, double L, double b) {
  const double u00 = solver.displacement_at({L, 0.0, 0.0}).x(), ubb = solver.displacement_at({L, b, b}).x();
  const double ub0 = solver.displacement_at({L, b, 0.0}).x(), u0b = solver.displacement_at({L, 0.0, b}).x();
  const double centre = solver.displacement_at({L, 0.5 * b, 0.5 * b}).x();
  const bool diagonal_00_bb = std::abs(centre - 0.5 * (u00 + ubb)) <= std::abs(centre - 0.5 * (ub0 + u0b));
  return diagonal_00_bb ? (2.0 * (u00 + ubb) + ub0 + u0b) / 6.0 : (2.0 * (ub0 + u0b) + u00 + ubb) / 6.0;
}

TEST(DynamicBar, DampedFreeVibrationDecaysWithTheFirstModesDampingRatio) {
  const double L = 0.1, b = 0.01, E = 1e6, rho = 1000.0, sigma = 100.0; // strain σ/E = 1e-4
  const double c = std::sqrt(E / rho), omega_1 = 0.5 * std::numbers::pi * c / L;
  const double zeta_1 = 0.05, tau = 2.0 * zeta_1 / omega_1; // ζ₁ = ω₁τ/2
  FiniteStrainProblem p;
  p.mesh = test::named_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(L, b, b), 20, 1, 1);
  p.materials.push_back({"body", LawKind::neo_hookean, E, 0.0, rho, tau * E}); // η = τ E
  p.displacement_boundaries.push_back({"xmin", DisplacementBoundary::Kind::bonded, {}, {}});
  p.tractions.push_back({"xmax", Eigen::Vector3d(sigma * b * b, 0.0, 0.0)});
  SolverSettings settings;
  settings.dynamic = true;
  FiniteStrainSolver solver(p, settings);
  // At rest under the end stress (h = 0: a quasi-static solve), released at t = 0: load factor 0.
  ASSERT_TRUE(solver.solve({1.0, Eigen::Vector3d::Zero(), 0.0}).converged);
  const double F = sigma * b * b, u_static = end_displacement(solver, L, b), U0 = solver.strain_energy();
  const double period = 2.0 * std::numbers::pi / omega_1;
  const int steps_per_period = 200, steps = 700; // 3.5 periods: three peaks after t = 0
  const double h = period / steps_per_period;
  double u_prev = u_static, work = 0.0, worst_energy = 0.0;
  std::vector<double> u_history{u_static}, peaks, peak_times;
  for (int k = 1; k <= steps; ++k) {
    const EquilibriumReport r = solver.solve({0.0, Eigen::Vector3d::Zero(), k * h});
    ASSERT_TRUE(r.converged) << "t = " << k * h << ": " << r.failure;
    const double u = end_displacement(solver, L, b);
    // The trapezoid-rule work of the end force: F at t = 0, 0 from t = h on.
    work += 0.5 * ((k == 1 ? F : 0.0) + 0.0) * (u - u_prev);
    // W = ΔU + K + D: the Newmark energy identity with the viscous forces' trapezoid work booked as
    // the damping dissipation (EquilibriumReport::damping_dissipation).
    const double ledger = solver.strain_energy() - U0 + r.kinetic_energy + r.damping_dissipation;
    worst_energy = std::max(worst_energy, std::abs(work - ledger) / (F * u_static));
    ASSERT_GE(r.damping_dissipation, 0.0);
    u_history.push_back(u);
    u_prev = u;
  }
  // Positive peaks of the end displacement after t = 0, refined by a parabola through the three
  // samples around each.
  for (std::size_t k = 1; k + 1 < u_history.size(); ++k)
    if (u_history[k] > u_history[k - 1] && u_history[k] >= u_history[k + 1] && u_history[k] > 0.0) {
      const double a = u_history[k - 1], m = u_history[k], z = u_history[k + 1];
      const double shift = 0.5 * (a - z) / (a - 2.0 * m + z);
      peaks.push_back(m - 0.25 * (a - z) * shift);
      peak_times.push_back((static_cast<double>(k) + shift) * h);
    }
  ASSERT_GE(peaks.size(), 3u);
  // From the second peak on (the higher modes have decayed, see the file comment).
  const double decrement = std::log(peaks[1] / peaks[2]);
  const double damped_period = peak_times[2] - peak_times[1];
  const double expected = 2.0 * std::numbers::pi * zeta_1 / std::sqrt(1.0 - zeta_1 * zeta_1);
  const double D = solver.damping_dissipation();
  std::printf("damped bar: log decrement %.5f (closed form %.5f), damped period %.6f s (closed form %.6f s), "
              "worst |W - dU - K - D| %.2e F u_s, D %.4e J of U0 %.4e J after 3.5 periods\n",
              decrement, expected, damped_period, period / std::sqrt(1.0 - zeta_1 * zeta_1), worst_energy, D, U0);
  // 2%: the 20 P1 elements' first mode is a little stiffer than the continuum's (ω₁ enters ζ₁).
  EXPECT_NEAR(decrement, expected, 0.02 * expected);
  EXPECT_NEAR(damped_period, period / std::sqrt(1.0 - zeta_1 * zeta_1), 0.01 * period);
  EXPECT_LT(worst_energy, 1e-5);
  // After 3.5 periods of ζ₁ = 5% the first mode keeps e^{−2·3.5·2πζ₁/√(1−ζ₁²)} = 11% of its
  // energy: most of the released energy is dissipated.
  EXPECT_GT(D, 0.8 * U0);
  EXPECT_LT(D, U0);
}

// A cut-back restores the dynamic state: a load path whose first attempt at t = 2h fails (a NaN
// injected in its residual, SolverSettings::residual_fault) cuts back to t = h and goes on to 2h; the
// failed attempt must leave u, v and a as they were, so the result equals, bit for bit, the path
// that solves t = h and t = 2h directly (the independent run).
// The same with Kelvin–Voigt damping: the restore carries the viscous forces and the dissipation.
class DynamicBarCutBack : public ::testing::TestWithParam<double> {};

TEST_P(DynamicBarCutBack, RestoresVelocityAccelerationAndDamping) {
  const double L = 0.1, b = 0.01, E = 1e6, rho = 1000.0, sigma = 100.0, h = 1e-4, eta = GetParam();
  auto problem = [&] {
    FiniteStrainProblem p;
    p.mesh = test::named_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(L, b, b), 10, 1, 1);
    p.materials.push_back({"body", LawKind::neo_hookean, E, 0.0, rho, eta});
    p.displacement_boundaries.push_back({"xmin", DisplacementBoundary::Kind::bonded, {}, {}});
    p.tractions.push_back({"xmax", Eigen::Vector3d(sigma * b * b, 0.0, 0.0)});
    return p;
  };
  SolverSettings settings;
  settings.dynamic = true;
  // The paths start at load factor 1 (the load applied at t = 0, as above), so that a cut-back
  // interpolates only the time.
  FiniteStrainSolver direct(problem(), settings);
  LoadPath direct_path(direct, LoadState{1.0, Eigen::Vector3d::Zero(), 0.0});
  for (int k = 1; k <= 3; ++k) ASSERT_TRUE(direct_path.advance({{1.0, Eigen::Vector3d::Zero(), k * h}, 0, k * h}).converged);

  int faults = 0;
  settings.residual_fault = [&](const LoadState& load, int iteration) {
    const bool fault = faults == 0 && std::abs(load.time - 2 * h) < 1e-12 && iteration == 1;
    faults += fault ? 1 : 0;
    return fault;
  };
  FiniteStrainSolver cut(problem(), settings);
  LoadPath cut_path(cut, LoadState{1.0, Eigen::Vector3d::Zero(), 0.0});
  // Target 2h from t = 0: the attempt with a step of 2h fails, the cut-back solves h, then 2h; then 3h.
  const LoadStepReport first = cut_path.advance({{1.0, Eigen::Vector3d::Zero(), 2 * h}, 0, 2 * h});
  ASSERT_TRUE(first.converged);
  EXPECT_EQ(first.cutbacks, 1);
  EXPECT_EQ(first.increments, 2);
  ASSERT_TRUE(cut_path.advance({{1.0, Eigen::Vector3d::Zero(), 3 * h}, 0, 3 * h}).converged);
  EXPECT_EQ(faults, 1);
  EXPECT_EQ(cut.state(), direct.state()); // displacement, velocity, acceleration, time (, damping): bit for bit
  EXPECT_EQ(cut.kinetic_energy(), direct.kinetic_energy());
  EXPECT_GT(direct.kinetic_energy(), 0.0);
  EXPECT_EQ(cut.damping_dissipation(), direct.damping_dissipation());
  if (eta > 0.0) {
    EXPECT_GT(direct.damping_dissipation(), 0.0);
  }
}

INSTANTIATE_TEST_SUITE_P(UndampedAndDamped, DynamicBarCutBack, ::testing::Values(0.0, 20.0));

TEST(DynamicBar, RefusesAMaterialWithoutDensity) {
  FiniteStrainProblem p;
  p.mesh = test::named_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.01, 0.01, 0.01), 1, 1, 1);
  p.materials.push_back({"body", LawKind::neo_hookean, 1e6, 0.3, 0.0});
  p.displacement_boundaries.push_back({"xmin", DisplacementBoundary::Kind::bonded, {}, {}});
  SolverSettings settings;
  settings.dynamic = true;
  EXPECT_THROW(FiniteStrainSolver(p, settings), std::invalid_argument);
}

} // namespace
} // namespace kerf::reference
