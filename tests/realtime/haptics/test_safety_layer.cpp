// The safety layer (realtime/haptics/safety_layer.hpp) with exact numbers: limits chosen as powers
// of two so every expected value below is exactly representable and follows by hand from the
// documented rules (clamp scales the vector, the rate limit steps by rate x dt, the ramp is linear).

#include "realtime/haptics/safety_layer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

using namespace kerf;

namespace {

SafetyLimits limits(double max_force = 4.0, double rate = 1e6, double ramp = 0.5, double watchdog = 0.0625) {
  return {max_force, rate, ramp, watchdog};
}

} // namespace

TEST(SafetyLayer, RefusesLimitsThatWouldDisableIt) {
  EXPECT_THROW(SafetyLayer({0.0, 1.0, 1.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(SafetyLayer({1.0, -1.0, 1.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(SafetyLayer({1.0, 1.0, std::nan(""), 1.0}), std::invalid_argument);
  EXPECT_THROW(SafetyLayer({1.0, 1.0, 1.0, std::numeric_limits<double>::infinity()}), std::invalid_argument);
}

TEST(SafetyLayer, ClampScalesTheVectorToTheSmallerOfConfiguredAndDeclaredMaximum) {
  SafetyLayer s(limits(4.0));
  s.start(0.0);
  std::uint32_t status = 0;
  // |(30, 40, 0)| = 50 N; F_max = min(4, 10) = 4 -> (30, 40) x 4/50 = (2.4, 3.2).
  Eigen::Vector3d f = s.filter({30.0, 40.0, 0.0}, 1.0, 0.0, 1.0, 10.0, status);
  EXPECT_NEAR(f.x(), 2.4, 1e-15);
  EXPECT_NEAR(f.y(), 3.2, 1e-15);
  EXPECT_EQ(f.z(), 0.0);
  EXPECT_TRUE(status & safety_clamped);
  // The device declares 2 N: (30, 40) x 2/50 = (1.2, 1.6).
  f = s.filter({30.0, 40.0, 0.0}, 1.0, 0.0, 1.0, 2.0, status);
  EXPECT_NEAR(f.norm(), 2.0, 1e-15);
  EXPECT_NEAR(f.x(), 1.2, 1e-15);
  // A device that declared nothing (0 N) gets nothing.
  f = s.filter({0.5, 0.0, 0.0}, 1.0, 0.0, 1.0, 0.0, status);
  EXPECT_EQ(f, Eigen::Vector3d::Zero());
  // Under the limit nothing changes and no flag is set.
  f = s.filter({0.5, -0.25, 1.0}, 1.0, 0.0, 1.0, 10.0, status);
  EXPECT_EQ(f, Eigen::Vector3d(0.5, -0.25, 1.0));
  EXPECT_EQ(status, 0u);
  EXPECT_EQ(s.counters().clamped, 3u); // the 50 N twice and the undeclared device
}

TEST(SafetyLayer, RateLimitStepsByRateTimesDt) {
  // 128 N/s at dt = 1/128 s: at most 1 N per tick. 3.5 N is reached as 1, 2, 3, 3.5.
  SafetyLayer s(limits(4.0, 128.0));
  s.start(-10.0); // ramp long finished
  std::uint32_t status = 0;
  const double dt = 1.0 / 128.0;
  const double expected[] = {1.0, 2.0, 3.0, 3.5, 3.5};
  for (double e : expected) EXPECT_EQ(s.filter({0.0, 0.0, 3.5}, 0.0, 0.0, dt, 8.5, status).z(), e);
  EXPECT_EQ(s.counters().rate_limited, 3u);
  // Reversal to -3.5 N: 2.5, 1.5, 0.5, -0.5, -1.5, -2.5, -3.5.
  double last = 0.0;
  for (int k = 0; k < 7; ++k) last = s.filter({0.0, 0.0, -3.5}, 0.0, 0.0, dt, 8.5, status).z();
  EXPECT_EQ(last, -3.5);
  EXPECT_EQ(s.counters().rate_limited, 9u);
}

TEST(SafetyLayer, RampsLinearlyInAndOut) {
  SafetyLayer s(limits(4.0, 1e6, 0.5));
  std::uint32_t status = 0;
  const Eigen::Vector3d two(2.0, 0.0, 0.0);
  EXPECT_EQ(s.filter(two, 0.0, 0.0, 1e-3, 8.5, status).x(), 0.0); // not started: g = 0
  s.start(0.0);
  EXPECT_EQ(s.filter(two, 0.125, 0.0, 1e-3, 8.5, status).x(), 0.5); // g = 0.125 / 0.5 = 0.25
  EXPECT_TRUE(status & safety_ramping);
  EXPECT_EQ(s.filter(two, 0.25, 0.0, 1e-3, 8.5, status).x(), 1.0);  // g = 0.5
  EXPECT_EQ(s.filter(two, 0.5, 0.0, 1e-3, 8.5, status).x(), 2.0);   // g = 1
  EXPECT_FALSE(status & safety_ramping);
  s.stop(1.0);
  EXPECT_EQ(s.filter(two, 1.125, 0.0, 1e-3, 8.5, status).x(), 1.5); // g = 1 - 0.125 / 0.5 = 0.75
  EXPECT_FALSE(s.stopped(1.125));
  EXPECT_EQ(s.filter(two, 1.5, 0.0, 1e-3, 8.5, status).x(), 0.0);
  EXPECT_TRUE(s.stopped(1.5));
  EXPECT_TRUE(status & safety_stopped);
  // A stop during the ramp in ramps out from the gain reached: g_stop = 0.5 at t = 0.25.
  SafetyLayer t(limits(4.0, 1e6, 0.5));
  t.start(0.0);
  t.stop(0.25);
  EXPECT_EQ(t.gain(0.25), 0.5);
  EXPECT_EQ(t.gain(0.375), 0.375); // 0.5 (1 - 0.125 / 0.5): down to 0 over the ramp time
  EXPECT_EQ(t.gain(0.75), 0.0);
}

TEST(SafetyLayer, NonFiniteModelForceBecomesZeroThroughTheRateLimit) {
  SafetyLayer s(limits(4.0, 128.0));
  s.start(-10.0);
  std::uint32_t status = 0;
  const double dt = 1.0 / 128.0;
  s.filter({1.0, 0.0, 0.0}, 0.0, 0.0, dt, 8.5, status);
  Eigen::Vector3d f = s.filter({std::nan(""), 0.0, 0.0}, 0.0, 0.0, dt, 8.5, status);
  EXPECT_EQ(f, Eigen::Vector3d::Zero()); // 1 N -> 0 within one 1 N step
  EXPECT_TRUE(status & safety_non_finite);
  f = s.filter({0.0, std::numeric_limits<double>::infinity(), 0.0}, 0.0, 0.0, dt, 8.5, status);
  EXPECT_EQ(f, Eigen::Vector3d::Zero());
  f = s.filter({0.0, 0.0, 1.0}, 0.0, 0.0, dt, std::numeric_limits<double>::quiet_NaN(), status);
  EXPECT_EQ(f, Eigen::Vector3d::Zero()); // a NaN declared maximum passes nothing
  EXPECT_EQ(s.counters().non_finite, 2u);
}

TEST(SafetyLayer, WatchdogAndEmergencyStopZeroAtOnce) {
  SafetyLayer s(limits(4.0, 128.0, 0.5, 0.0625));
  s.start(-10.0);
  std::uint32_t status = 0;
  const double dt = 1.0 / 128.0;
  // A state one microsecond younger than the timeout: alive.
  for (int k = 0; k < 4; ++k) s.filter({3.5, 0.0, 0.0}, 0.0, 0.0625 - 1e-6, dt, 8.5, status);
  EXPECT_EQ(s.last_output().x(), 3.5);
  // A state as old as the timeout is silence: zero in one tick, although the rate limit allows 1 N.
  EXPECT_EQ(s.filter({3.5, 0.0, 0.0}, 0.0, 0.0625, dt, 8.5, status), Eigen::Vector3d::Zero());
  EXPECT_TRUE(status & safety_watchdog);
  EXPECT_EQ(s.filter({3.5, 0.0, 0.0}, 0.0, std::nan(""), dt, 8.5, status), Eigen::Vector3d::Zero());
  // The link is back: force returns through the rate limit (1 N per tick), not as a jump.
  EXPECT_EQ(s.filter({3.5, 0.0, 0.0}, 0.0, 0.0, dt, 8.5, status).x(), 1.0);
  EXPECT_EQ(s.counters().watchdog, 2u);
  s.emergency_stop();
  EXPECT_EQ(s.filter({3.5, 0.0, 0.0}, 0.0, 0.0, dt, 8.5, status), Eigen::Vector3d::Zero());
  EXPECT_TRUE(status & safety_emergency_stop);
  s.start(0.0); // latched: a new start does not clear it
  EXPECT_EQ(s.filter({3.5, 0.0, 0.0}, 1.0, 0.0, dt, 8.5, status), Eigen::Vector3d::Zero());
  EXPECT_EQ(s.counters().emergency, 2u);
}

TEST(SafetyLayer, HoldsWhateverTheModelDoes) {
  // Property over 200000 random ticks with NaN, Inf, huge and tiny forces, random declared
  // maxima and link ages: the output is always finite, within min(configured, declared), and
  // changes by at most rate x dt unless the watchdog zeroed it.
  const double rate = 100.0, dt = 1e-3, f_max = 5.0;
  SafetyLayer s(limits(f_max, rate, 0.2, 0.05));
  s.start(0.0);
  std::mt19937_64 random(8);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double specials[] = {std::nan(""), std::numeric_limits<double>::infinity(), -1e300, 1e-300, 0.0};
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (int k = 0; k < 200000; ++k) {
    Eigen::Vector3d desired(unit(random), unit(random), unit(random));
    desired *= std::pow(10.0, 4.0 * unit(random));
    if (random() % 50 == 0) desired[random() % 3] = specials[random() % 5];
    const double declared = random() % 20 == 0 ? 1.0 : 8.5;
    const double age = random() % 100 == 0 ? 0.1 : 0.001;
    std::uint32_t status = 0;
    const Eigen::Vector3d f = s.filter(desired, 1e-3 * k, age, dt, declared, status);
    ASSERT_TRUE(f.allFinite());
    ASSERT_LE(f.norm(), std::min(f_max, declared) * (1.0 + 1e-12));
    if (!(status & safety_watchdog) && declared == 8.5) {
      ASSERT_LE((f - previous).norm(), rate * dt * (1.0 + 1e-9));
    }
    previous = f;
  }
}
