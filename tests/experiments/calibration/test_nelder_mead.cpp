// The simplex minimiser on functions whose minimum is known in closed form.

#include "experiments/calibration/nelder_mead.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace kerf;

TEST(NelderMead, FindsTheRosenbrockMinimum) {
  // Rosenbrock (1960): f = (1 - x)^2 + 100 (y - x^2)^2, minimum 0 at (1, 1) — a curved valley.
  const auto f = [](const Eigen::VectorXd& v) {
    return (1 - v[0]) * (1 - v[0]) + 100 * (v[1] - v[0] * v[0]) * (v[1] - v[0] * v[0]);
  };
  NelderMeadSettings s;
  s.max_evaluations = 2000;
  s.step_tolerance = 1e-8;
  s.value_tolerance = 1e-16;
  const NelderMeadResult r = nelder_mead(f, Eigen::Vector2d(-1.2, 1.0), s);
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(r.x[0], 1.0, 1e-5);
  EXPECT_NEAR(r.x[1], 1.0, 1e-5);
  EXPECT_LT(r.value, 1e-10);
}

TEST(NelderMead, ShiftedQuadraticInThreeDimensions) {
  // f = sum_k (k + 1) (x_k - c_k)^2: minimum at c exactly.
  const Eigen::Vector3d c(0.3, -2.0, 5.0);
  const auto f = [&](const Eigen::VectorXd& v) {
    double sum = 0.0;
    for (int k = 0; k < 3; ++k) sum += (k + 1) * (v[k] - c[k]) * (v[k] - c[k]);
    return sum;
  };
  NelderMeadSettings s;
  s.max_evaluations = 3000;
  s.step_tolerance = 1e-9;
  s.value_tolerance = 1e-18;
  const NelderMeadResult r = nelder_mead(f, Eigen::Vector3d::Zero(), s);
  EXPECT_LT((r.x - c).norm(), 1e-6);
}

TEST(NelderMead, MovesAwayFromNonFiniteValuesAndStopsAtTheLimit) {
  // NaN left of x = 0.5: the simplex must treat it as +inf and still find (x - 1)^2's minimum.
  const auto f = [](const Eigen::VectorXd& v) {
    return v[0] < 0.5 ? std::numeric_limits<double>::quiet_NaN() : (v[0] - 1) * (v[0] - 1);
  };
  const NelderMeadResult r = nelder_mead(f, Eigen::VectorXd::Constant(1, 0.8), {500, 1e-9, 1e-18, 0.25});
  EXPECT_NEAR(r.x[0], 1.0, 1e-6);
  const NelderMeadResult limited = nelder_mead(f, Eigen::VectorXd::Constant(1, 0.8), {5, 1e-12, 1e-18, 0.25});
  EXPECT_FALSE(limited.converged);
  EXPECT_LE(limited.evaluations, 7); // the limit is checked once per iteration (at most 2 more)
  EXPECT_THROW(nelder_mead(f, Eigen::VectorXd(), {}), std::invalid_argument);
}
