// Solution verification (Celik et al. 2008, J. Fluids Eng. 130(7) 078001): the observed order, the
// Richardson-extrapolated value and the GCI, against a closed form (a power law f(h) = f0 + C h^p,
// which the procedure must recover exactly) and against the paper's worked example (Table 1).

#include "experiments/study/solution_verification.hpp"
#include "experiments/study/reference_verification.hpp"

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

TEST(SolutionVerification, DifferenceNormsGiveTheProfilesOrderAndUncertainty) {
  // A profile whose error is C h^p times a fixed shape g: ‖f_h − f‖ = C h^p ‖g‖. With p = 1.5 on
  // h = 0.4, 0.6, 1.2 (r21 = 1.5, r32 = 2): e21 = C‖g‖ (h2^p − h1^p), e32 = C‖g‖ (h3^p − h2^p), and
  // the uncertainty Fs e21 / (r21^p − 1) = Fs C‖g‖ h1^p, Fs times the true error of the finest.
  const double p = 1.5, scale = 0.37, h1 = 0.4, h2 = 0.6, h3 = 1.2;
  const double e21 = scale * (std::pow(h2, p) - std::pow(h1, p)), e32 = scale * (std::pow(h3, p) - std::pow(h2, p));
  const DifferenceConvergence c = difference_convergence(h1, h2, h3, e21, e32, 2.0);
  ASSERT_TRUE(c.usable()) << c.unusable;
  EXPECT_NEAR(*c.observed_order, p, 1e-10);
  EXPECT_NEAR(*c.order_used, p, 1e-10);
  EXPECT_NEAR(*c.uncertainty, gci_safety_factor * scale * std::pow(h1, p), 1e-10);
}

TEST(SolutionVerification, AnOrderAboveTheFormalOneIsNotTrusted) {
  // e32 / e21 = 8 on r = 2: p = 3 observed; with the formal order 2 the uncertainty takes 2:
  // Fs e21 / (2^2 − 1), not Fs e21 / (2^3 − 1) (Roache 1998).
  const DifferenceConvergence c = difference_convergence(1.0, 2.0, 4.0, 0.1, 0.8, 2.0);
  ASSERT_TRUE(c.usable()) << c.unusable;
  EXPECT_NEAR(*c.observed_order, 3.0, 1e-10);
  EXPECT_DOUBLE_EQ(*c.order_used, 2.0);
  EXPECT_NEAR(*c.uncertainty, gci_safety_factor * 0.1 / 3.0, 1e-14);
}

TEST(SolutionVerification, DifferencesThatDoNotShrinkGiveNoUncertainty) {
  const DifferenceConvergence growing = difference_convergence(1.0, 2.0, 4.0, 0.5, 0.4, 2.0);
  EXPECT_FALSE(growing.usable());
  EXPECT_NE(growing.unusable.find("do not shrink"), std::string::npos) << growing.unusable;
  const DifferenceConvergence same = difference_convergence(1.0, 2.0, 4.0, 0.0, 0.4, 2.0);
  EXPECT_FALSE(same.usable());
  EXPECT_THROW(difference_convergence(1.0, 1.0, 4.0, 0.1, 0.2, 2.0), std::invalid_argument);
  EXPECT_THROW(difference_convergence(1.0, 2.0, 4.0, -0.1, 0.2, 2.0), std::invalid_argument);
  EXPECT_THROW(difference_convergence(1.0, 2.0, 4.0, 0.1, 0.2, 0.0), std::invalid_argument);
}

TEST(SolutionVerification, LevelsWhoseRmsAgreeByCoincidenceStillShowTheirProfilesDiffer) {
  // Two samples per level, h = 1, 2, 4 mm: the finest [3, 4] N and the next [4, 3.0001] N have
  // the same RMS |F| to 1e-5, so the GCI of RMS |F| is tiny; the profiles differ by 1 N at both
  // samples. The profile's uncertainty comes from e21 = RMS of the differences = 1 N and
  // e32 = RMS([2, 2.3]) N: p = log2(e32 / e21), U = Fs e21 / (2^p − 1) — of the order of the
  // 1 N the levels differ by, not of the RMS values' coincidence.
  const auto level = [](int k, double h, double f0, double f1) {
    ForceProfile p;
    for (const auto& [t, f] : {std::pair{0.0, f0}, std::pair{1.0, f1}}) {
      ProfileRow r;
      r.t = t;
      r.tool = "blade";
      r.force = Eigen::Vector3d(0.0, 0.0, f);
      p.rows.push_back(r);
    }
    return ReferenceLevel{k, h, p};
  };
  const std::vector<ReferenceLevel> levels{level(0, 1e-3, 3.0, 4.0), level(-1, 2e-3, 4.0, 3.0001), level(-2, 4e-3, 6.0, 0.7001)};
  const auto v = verify_reference(levels, "blade", 2.0);
  ASSERT_TRUE(v.has_value());
  ASSERT_TRUE(v->rms.usable()) << v->rms.unusable;
  EXPECT_LT(*v->rms.gci_fine, 1e-3); // what the RMS's GCI alone would claim
  ASSERT_TRUE(v->profile.usable()) << v->profile.unusable;
  EXPECT_NEAR(v->profile.e21, std::sqrt((1.0 + 0.9999 * 0.9999) / 2.0), 1e-12);
  const double e32 = std::sqrt((4.0 + 2.3 * 2.3) / 2.0);
  EXPECT_NEAR(v->profile.e32, e32, 1e-12);
  const double p = std::log2(e32 / v->profile.e21);
  EXPECT_NEAR(*v->profile.observed_order, p, 1e-9);
  EXPECT_NEAR(*v->profile_uncertainty(), gci_safety_factor * v->profile.e21 / (std::pow(2.0, p) - 1.0), 1e-9);
  EXPECT_GT(*v->profile_uncertainty(), 0.5);
  EXPECT_NE(v->summary().find("on the force profile"), std::string::npos) << v->summary();
}
