// Hayward & Armstrong pre-sliding friction against its closed-form limits: pure stick is an
// elastic spring, steady sliding is Coulomb friction mu N, unloading is elastic.

#include "realtime/fracture/presliding_friction.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace kerf;

TEST(PreslidingFriction, StickIsElastic) {
  // Within |z| <= z_stick the adhesion map alpha is 0, so dz = dx and f = -k x.
  PreslidingFriction f(1000.0, 0.5);
  const double mu = 0.5, normal = 2.0;          // z_max = mu N / k = 1 mm, z_stick = 0.5 mm
  double force = 0.0;
  for (int i = 0; i < 40; ++i) force = f.update(1e-5, normal, mu); // 0.4 mm
  EXPECT_NEAR(force, -1000.0 * 4e-4, 1e-12);
}

TEST(PreslidingFriction, SteadySlidingIsCoulomb) {
  // Past breakaway (alpha = 1) dz/dx = 1 - z/z_max, so z approaches z_max like
  // exp(-x / z_max): after 40 z_max of sliding the force is mu N (Coulomb) to e^-40.
  PreslidingFriction f(1000.0, 0.5);
  const double mu = 0.3, normal = 5.0; // z_max = 1.5 mm
  double force = 0.0;
  for (int i = 0; i < 60000; ++i) force = f.update(1e-6, normal, mu);
  EXPECT_NEAR(force, -mu * normal, 1e-9);
  for (int i = 0; i < 120000; ++i) force = f.update(-1e-6, normal, mu);
  EXPECT_NEAR(force, mu * normal, 1e-9);
}

TEST(PreslidingFriction, SlidingApproachesCoulombExponentially) {
  // In the sliding regime the closed form of dz/dx = 1 - z/z_max is
  // z(x) = z_max - (z_max - z0) exp(-(x - x0)/z_max); the discrete update follows it to
  // O(dx / z_max).
  PreslidingFriction f(1000.0, 0.0); // no stick zone
  const double mu = 0.5, normal = 2.0, z_max = 1e-3, dx = 1e-8;
  // Load to z_max first, reverse by half (elastic), then slide forward and compare.
  for (int i = 0; i < 1000000; ++i) f.update(dx, normal, mu);
  const double loaded = f.presliding_displacement();
  for (int i = 0; i < 50000; ++i) f.update(-dx, normal, mu); // elastic unloading by 0.5 z_max
  const double z0 = f.presliding_displacement();
  EXPECT_NEAR(z0, loaded - 0.5 * z_max, 1e-12);
  double x = 0.0;
  for (int i = 0; i < 200000; ++i, x += dx) f.update(dx, normal, mu);
  // With stick ratio 0, alpha follows Hayward & Armstrong's sine ramp from 0 to 1 over
  // (0, z_max); alpha <= 1 makes dz/dx = 1 - alpha z/z_max >= 1 - z/z_max, so by comparison z
  // stays between the alpha = 1 exponential and z_max:
  const double exponential = z_max - (z_max - z0) * std::exp(-x / z_max);
  EXPECT_GE(f.presliding_displacement(), exponential - 1e-9);
  EXPECT_LE(f.presliding_displacement(), z_max);
}

TEST(PreslidingFriction, ReversalUnloadsElastically) {
  // After sliding, a reversal of dx unloads with the adhesion stiffness k: df = k dx.
  PreslidingFriction f(2000.0, 0.2);
  for (int i = 0; i < 10000; ++i) f.update(1e-6, 1.0, 1.0);
  const double before = f.update(0.0, 1.0, 1.0);
  const double after = f.update(-1e-4, 1.0, 1.0);
  EXPECT_NEAR(after - before, 2000.0 * 1e-4, 1e-9);
}

TEST(PreslidingFriction, NoNormalLoadNoFrictionAndAlwaysFinite) {
  PreslidingFriction f(1000.0, 0.5);
  EXPECT_EQ(f.update(1e-3, 0.0, 0.5), 0.0);
  EXPECT_EQ(f.update(1e-3, -3.0, 0.5), 0.0);
  EXPECT_TRUE(std::isfinite(f.update(std::nan(""), 1.0, 0.5)));
  EXPECT_TRUE(std::isfinite(f.update(1e300, 1e300, 0.5)));
  EXPECT_THROW(PreslidingFriction(0.0, 0.5), std::invalid_argument);
  EXPECT_THROW(PreslidingFriction(1.0, 1.0), std::invalid_argument);
}
