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

#include "reference/finite_strain_solver.hpp"
#include "reference/load_path.hpp"
#include "tests/reference/reference_test_meshes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

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

// A cut-back restores the dynamic state: a load path whose first attempt at t = 2h fails (a NaN
// injected in its residual, SolverSettings::residual_fault) cuts back to t = h and goes on to 2h; the
// failed attempt must leave u, v and a as they were, so the result equals, bit for bit, the path
// that solves t = h and t = 2h directly (the independent run).
TEST(DynamicBar, CutBackRestoresVelocityAndAcceleration) {
  const double L = 0.1, b = 0.01, E = 1e6, rho = 1000.0, sigma = 100.0, h = 1e-4;
  auto problem = [&] {
    FiniteStrainProblem p;
    p.mesh = test::named_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(L, b, b), 10, 1, 1);
    p.materials.push_back({"body", LawKind::neo_hookean, E, 0.0, rho});
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
  EXPECT_EQ(cut.state(), direct.state()); // displacement, velocity, acceleration, time: bit for bit
  EXPECT_EQ(cut.kinetic_energy(), direct.kinetic_energy());
  EXPECT_GT(direct.kinetic_energy(), 0.0);
}

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
