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
  // Far beyond breakaway the force saturates at mu N (Coulomb), opposing the motion.
  PreslidingFriction f(1000.0, 0.5);
  const double mu = 0.3, normal = 5.0;
  double force = 0.0;
  for (int i = 0; i < 10000; ++i) force = f.update(1e-6, normal, mu);
  EXPECT_NEAR(force, -mu * normal, 1e-9);
  for (int i = 0; i < 20000; ++i) force = f.update(-1e-6, normal, mu);
  EXPECT_NEAR(force, mu * normal, 1e-9);
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
