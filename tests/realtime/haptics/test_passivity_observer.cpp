// The passivity observer and the replay device, against a closed form. A replay device moves a
// stylus linearly from the rest point of a spring (k = 1000 N/m) out by A = 10 mm in 1 s and back
// in 1 s; the servo ticks at T = 1 ms (N = 1000 ticks each way) with ticks driven by hand at
// now = k T. With the zero-order hold the observer sums E = sum F_{k-1} . (x_k - x_{k-1}):
//   out:  -k (A/N)^2 sum_{j=0}^{N-1} j = -k A^2 (N - 1) / (2 N)   (the hand loads the spring)
//   back: +k (A/N)^2 sum_{m=1}^{N}   m = +k A^2 (N + 1) / (2 N)
//   cycle: k A^2 / N = 1e-4 J > 0 -- the sampled-data spring's energy leak (Colgate & Schenkel
//   1997) that the observer exists to expose.

#include "realtime/haptics/replay_device.hpp"
#include "realtime/haptics/servo_loop.hpp"
#include "tests/realtime/haptics/rest_point_spring.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace kerf;

TEST(PassivityObserver, ZeroOrderHoldSpringCycleMatchesClosedForm) {
  const double k = 1000.0, A = 0.010;
  const int N = 1000;
  const auto file = std::filesystem::temp_directory_path() / ("kerf_replay_" + std::to_string(getpid()) + ".csv");
  std::ofstream(file) << "# out and back along x\nt,px,py,pz\n0,0,0,0\n1,0.01,0,0\n2,0,0,0\n";
  auto device = open_device("replay:" + file.string());
  ASSERT_NE(dynamic_cast<ReplayDevice*>(device.get()), nullptr);
  test::RestPointSpring model(k, {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}, 1);
  HapticDevice* devices[] = {device.get()};
  ServoSettings settings;
  settings.rate = 1000.0;
  // Transparent safety for this check: a ramp of 1 ns (full gain from the second tick, where
  // the spring force is still 0), no effective clamp or rate limit.
  settings.safety = {1e6, 1e12, 1e-9, 1.0};
  settings.realtime = false;
  ServoLoop loop(model, devices, settings, nullptr);
  double at_top = 0.0;
  for (int tick = 0; tick <= 2 * N; ++tick) {
    ASSERT_TRUE(loop.tick(1e-3 * tick, 0.0));
    if (tick == N) at_top = loop.injected_energy(0);
  }
  std::filesystem::remove(file);
  EXPECT_NEAR(at_top, -k * A * A * (N - 1) / (2.0 * N), 1e-12);
  EXPECT_NEAR(loop.injected_energy(0), k * A * A / N, 1e-12);
  EXPECT_EQ(loop.model_steps(), 2u * N + 1u);
}

TEST(ReplayDevice, RefusesBadFilesAndAddresses) {
  const auto file = std::filesystem::temp_directory_path() / ("kerf_replay_bad_" + std::to_string(getpid()) + ".csv");
  std::ofstream(file) << "t,px,py,pz\n0,0,0,0\n0,1,0,0\n";
  EXPECT_THROW(open_device("replay:" + file.string()), std::runtime_error); // time not increasing
  std::ofstream(file) << "t,px,py\n0,0,0\n";
  EXPECT_THROW(open_device("replay:" + file.string()), std::runtime_error);
  std::filesystem::remove(file);
  EXPECT_THROW(open_device("replay:/nonexistent/file.csv"), std::runtime_error);
  EXPECT_THROW(open_device("tcp://127.0.0.1:5"), std::invalid_argument);
  EXPECT_THROW(open_device("udp://127.0.0.1"), std::invalid_argument);
  EXPECT_THROW(open_device("udp://127.0.0.1:99999"), std::invalid_argument);
}

TEST(VirtualCoupling, RendersTheSeriesSpringOfModelAndCoupling) {
  // A still device at x_d = 0, a model spring k_m = 4000 N/m to r = 5 mm along z, a coupling
  // k_c = 1000 N/m, b_c = 20 N s/m, m_v = 0.05 kg. At rest the virtual tool sits where the two
  // springs balance, x_v = k_m r / (k_m + k_c) = 4 mm, and the device feels the series spring:
  // F = k_m k_c / (k_m + k_c) r = 800 N/m x 5 mm = 4 N (plain rendering: k_m r = 20 N).
  const auto file = std::filesystem::temp_directory_path() / ("kerf_still_" + std::to_string(getpid()) + ".csv");
  std::ofstream(file) << "t,px,py,pz\n0,0,0,0\n100,0,0,0\n";
  const Eigen::Vector3d r(0.0, 0.0, 0.005);
  for (const bool coupled : {true, false}) {
    auto device = open_device("replay:" + file.string());
    test::RestPointSpring model(4000.0, {r, r}, 1);
    HapticDevice* devices[] = {device.get()};
    ServoSettings settings;
    settings.safety = {1e6, 1e12, 1e-9, 1.0};
    settings.realtime = false;
    if (coupled) settings.coupling = {1000.0, 20.0, 0.05};
    ServoLoop loop(model, devices, settings, nullptr);
    for (int tick = 0; tick <= 3000; ++tick) ASSERT_TRUE(loop.tick(1e-3 * tick, 0.0));
    const auto* replay = dynamic_cast<const ReplayDevice*>(device.get());
    ASSERT_NE(replay, nullptr);
    // The virtual tool's transient (omega = 316 rad/s, zeta = 0.63) has died out after 3 s.
    EXPECT_NEAR(replay->last_force().z(), coupled ? 4.0 : 20.0, 1e-9);
    EXPECT_NEAR(replay->last_force().head<2>().norm(), 0.0, 1e-12);
  }
  std::filesystem::remove(file);
}
