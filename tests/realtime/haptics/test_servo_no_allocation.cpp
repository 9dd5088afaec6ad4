// The servo tick allocates nothing (../shared/DESIGN.md, realtime contract): this program
// replaces every global allocation function (all operator new forms incl. nothrow and aligned,
// and glibc's malloc family outside sanitizer builds) with counting versions, then drives
// ServoLoop::tick() by hand -- UDP receive and decode, the fracture model's step, the safety
// layer, the UDP send, the passivity observer and the recorder's ring -- against an emulated
// device in another thread, through contact, rupture and cutting, and requires zero allocations
// on the ticking thread.

#include "meshes/box_tet_mesh.hpp"
#include "realtime/fracture/fracture_cutting_model.hpp"
#include "realtime/haptics/device_emulator.hpp"
#include "realtime/haptics/servo_loop.hpp"
#include "realtime/haptics/udp_device.hpp"

#include "tests/realtime/counting_allocator.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <thread>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <new>

using kerf::test::allocations;
using kerf::test::set_counting;

using namespace kerf;

TEST(RealtimeContract, ServoTickAllocatesNothing) {
  TetMesh mesh = box_tet_mesh({0.0, -0.010, 0.0}, {0.040, 0.010, 0.015}, 8, 4, 5);
  FractureCuttingSetup s;
  s.blade.edge_length = 0.030;
  s.fracture_toughness = {200.0};
  s.response = {300.0, 0.0015, 2, 0.0003, 1, 2000.0, 5000.0, 0.5};
  s.friction = true;
  s.friction_coefficient = 0.3;
  s.crack_capture_width = 1e-3;
  FractureCuttingModel model(mesh, s);

  // The hand pushes the blade from 1 mm above the top face to 8 mm deep within 0.8 s.
  EmulatedDeviceSettings device;
  for (int k = 0; k <= 800; ++k) device.target.emplace_back(0.020, 0.0, 0.016 - 1e-5 * k);
  device.hand.stiffness = 3000.0;
  device.hold = 0.05;
  DeviceEmulator emulator(device);
  std::atomic<bool> stop{false};
  std::thread emulator_thread([&] { emulator.run(stop); });

  UdpDevice link("127.0.0.1", emulator.port());
  HapticDevice* devices[] = {&link};
  ServoSettings settings;
  settings.safety = {8.5, 1000.0, 0.05, 0.05};
  settings.realtime = false;
  const auto file = std::filesystem::temp_directory_path() / ("kerf_no_alloc_" + std::to_string(getpid()) + ".csv");
  SessionRecorder recorder(file, {1000.0, "fracture", "box", {"blade"}}, 1 << 14);
  ServoLoop loop(model, devices, settings, &recorder);

  // Sanity check that the counter works at all.
  set_counting(true);
  ::operator delete(::operator new(16));
  set_counting(false);
  ASSERT_GE(allocations.load(), 1);
  allocations = 0;

  const auto start = std::chrono::steady_clock::now();
  long modes_seen = 0;
  long ticks = 0;
  for (int k = 1; k <= 1100; ++k) {
    std::this_thread::sleep_until(start + std::chrono::milliseconds(k));
    const double now = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    set_counting(true);
    loop.tick(now, 0.0);
    set_counting(false);
    ++ticks;
  }
  const long counted = allocations.load();
  stop = true;
  emulator_thread.join();
  recorder.close();
  const Session session = read_session(file);
  for (const TickRecord& r : session.ticks) modes_seen |= 1L << static_cast<int>(r.tool[0].mode);
  std::filesystem::remove(file);

  EXPECT_EQ(counted, 0) << "allocations during " << ticks << " servo ticks";
  EXPECT_GT(session.ticks.size(), 500u);
  // contact, rupture and cutting were all exercised while counting
  EXPECT_TRUE(modes_seen & (1L << static_cast<int>(InteractionMode::deformation_1)));
  EXPECT_TRUE(modes_seen & (1L << static_cast<int>(InteractionMode::cutting)));
}
