// Solution verification (Celik et al. 2008, J. Fluids Eng. 130(7) 078001): the observed order, the
// Richardson-extrapolated value and the GCI, against a closed form (a power law f(h) = f0 + C h^p,
// which the procedure must recover exactly) and against the paper's worked example (Table 1).

#include "experiments/study/solution_verification.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

using namespace kerf;

namespace {
GridTriplet power_law(double f0, double c, double p, double h1, double h2, double h3) {
  return {h1, h2, h3, f0 + c * std::pow(h1, p), f0 + c * std::pow(h2, p), f0 + c * std::pow(h3, p)};
}
} // namespace

TEST(SolutionVerification, RecoversOrderAndLimitOfAPowerLawWithAConstantRatio) {
  // f(h) = 3.2 + 0.5 h^1.7 on h = 1, 2, 4: p and f0 exactly (to round-off), and the GCI is Fs times
  // the true relative error of the finest value, |φ1 - f0| / |φ1| (Richardson is exact for a power law).
  const GridTriplet g = power_law(3.2, 0.5, 1.7, 1.0, 2.0, 4.0);
  const GridConvergence c = grid_convergence(g);
  ASSERT_TRUE(c.usable()) << c.unusable;
  EXPECT_FALSE(c.oscillatory);
  EXPECT_NEAR(*c.observed_order, 1.7, 1e-12);
  EXPECT_NEAR(*c.extrapolated, 3.2, 1e-12);
  EXPECT_NEAR(*c.gci_fine, gci_safety_factor * std::abs(g.phi1 - 3.2) / std::abs(g.phi1), 1e-12);
  EXPECT_NEAR(*c.extrapolated_relative_error, std::abs(g.phi1 - 3.2) / 3.2, 1e-12);
  EXPECT_LE(c.iterations, 3); // q(p) = 0 for a constant ratio: the first iterate is the answer
}

TEST(SolutionVerification, RecoversOrderAndLimitWithANonConstantRatio) {
  // r21 = 1.5, r32 = 2 and a decreasing sequence (C < 0): the fixed-point iteration for p.
  const GridTriplet g = power_law(-7.5, -2.0, 2.3, 0.4, 0.6, 1.2);
  const GridConvergence c = grid_convergence(g);
  ASSERT_TRUE(c.usable()) << c.unusable;
  EXPECT_NEAR(c.r21, 1.5, 1e-15);
  EXPECT_NEAR(c.r32, 2.0, 1e-15);
  EXPECT_NEAR(*c.observed_order, 2.3, 1e-10);
  EXPECT_NEAR(*c.extrapolated, -7.5, 1e-10);
  EXPECT_NEAR(*c.gci_fine, gci_safety_factor * std::abs(g.phi1 + 7.5) / std::abs(g.phi1), 1e-10);
  EXPECT_GT(c.iterations, 3);
}

TEST(SolutionVerification, CelikTable1) {
  // Celik et al. 2008 Table 1, the three worked columns: 2D grids of N1, N2, N3 cells, h = N^(-1/2).
  // Published: p, φ_ext^21 to four decimals, e_a^21, e_ext^21 and GCI_fine^21 to 0.1 %; checked to
  // half a unit of the last published digit.
  const auto h = [](double n) { return 1.0 / std::sqrt(n); };
  {
    // Dimensionless reattachment length: monotonic, r21 = 1.5, r32 = 1.333, p = 1.53, φ_ext = 6.1685,
    // e_a = 1.5 %, e_ext = 1.7 %, GCI = 2.2 %.
    const GridConvergence c = grid_convergence({h(18000), h(8000), h(4500), 6.063, 5.972, 5.863});
    ASSERT_TRUE(c.usable()) << c.unusable;
    EXPECT_FALSE(c.oscillatory);
    EXPECT_NEAR(c.r21, 1.5, 1e-12);
    EXPECT_NEAR(c.r32, 1.333, 5e-4);
    EXPECT_NEAR(*c.observed_order, 1.53, 5e-3);
    EXPECT_NEAR(*c.extrapolated, 6.1685, 5e-5);
    EXPECT_NEAR(c.approximate_relative_error, 0.015, 5e-4);
    EXPECT_NEAR(*c.extrapolated_relative_error, 0.017, 5e-4);
    EXPECT_NEAR(*c.gci_fine, 0.022, 5e-4);
  }
  {
    // Axial velocity at x/H = 8, y = 0.0526: monotonic with p < 1; φ_ext = 10.8801, e_a = 0.6 %,
    // GCI = 1.1 % (the table's e_ext is not checked here: 0.85 % computed).
    const GridConvergence c = grid_convergence({h(18000), h(4500), h(980), 10.7880, 10.7250, 10.6050});
    ASSERT_TRUE(c.usable()) << c.unusable;
    EXPECT_FALSE(c.oscillatory);
    EXPECT_LT(*c.observed_order, 1.0);
    EXPECT_NEAR(*c.extrapolated, 10.8801, 5e-5);
    EXPECT_NEAR(c.approximate_relative_error, 0.006, 5e-4);
    EXPECT_NEAR(*c.gci_fine, 0.011, 5e-4);
  }
  {
    // Axial velocity at another point: oscillatory convergence (ε32/ε21 < 0), computed with s = -1;
    // φ_ext = 6.0269, e_a = 0.7 %, e_ext = 0.4 %, GCI = 0.5 %.
    const GridConvergence c = grid_convergence({h(18000), h(4500), h(980), 6.0042, 5.9624, 6.0909});
    ASSERT_TRUE(c.usable()) << c.unusable;
    EXPECT_TRUE(c.oscillatory);
    EXPECT_NEAR(*c.extrapolated, 6.0269, 5e-5);
    EXPECT_NEAR(c.approximate_relative_error, 0.007, 5e-4);
    EXPECT_NEAR(*c.extrapolated_relative_error, 0.004, 5e-4);
    EXPECT_NEAR(*c.gci_fine, 0.005, 5e-4);
  }
}

TEST(SolutionVerification, SaysWhyWhereTheProcedureDoesNotApply) {
  // Divergence: the difference grows under refinement (f = 2 - 1/h on h = 1, 2, 4: ε21 = 0.5, ε32 = 0.25).
  const GridConvergence diverging = grid_convergence({1.0, 2.0, 4.0, 1.0, 1.5, 1.75});
  EXPECT_FALSE(diverging.usable());
  EXPECT_NE(diverging.unusable.find("divergence"), std::string::npos) << diverging.unusable;
  // The same value on two meshes: no order (Celik: "the above procedure does not work").
  const GridConvergence flat = grid_convergence({1.0, 2.0, 4.0, 2.0, 2.0, 2.5});
  EXPECT_FALSE(flat.usable());
  EXPECT_FALSE(flat.observed_order.has_value());
  EXPECT_FALSE(flat.unusable.empty());
  EXPECT_THROW(grid_convergence({2.0, 1.0, 4.0, 1.0, 2.0, 3.0}), std::invalid_argument);
  EXPECT_THROW(grid_convergence({1.0, 2.0, 4.0, 1.0, NAN, 3.0}), std::invalid_argument);
}

TEST(SolutionVerification, TheBandIsTheGciSampleBySample) {
  // Two samples of a power law f_k(h) = a_k + b_k h^2 on h = 1, 2: U_k = Fs |f1 - f2| / (2^2 - 1) =
  // Fs |b_k| (4 - 1) / 3 = Fs |b_k| = Fs |f1,k - a_k|: Fs times the true error at each sample.
  const std::vector<double> a{1.0, -2.0}, b{0.1, -0.3};
  std::vector<double> fine, medium;
  for (std::size_t k = 0; k < a.size(); ++k) {
    fine.push_back(a[k] + b[k]);
    medium.push_back(a[k] + 4.0 * b[k]);
  }
  const std::vector<double> u = gci_band_half_width(fine, medium, 2.0, 2.0);
  ASSERT_EQ(u.size(), 2u);
  for (std::size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(u[k], gci_safety_factor * std::abs(fine[k] - a[k]), 1e-14);
  EXPECT_THROW(gci_band_half_width(fine, {1.0}, 2.0, 2.0), std::invalid_argument);
  EXPECT_THROW(gci_band_half_width(fine, medium, 1.0, 2.0), std::invalid_argument);
}
