// The device table and the rig's safety defaults (realtime/haptics/device_specs.hpp,
// safety_layer.hpp). Expected values are the makers' specifications as CHAI3D 3.2.0 carries them
// (src/devices/CPhantomDevices.cpp, src/devices/CDeltaDevices.cpp), typed here a second time, so
// an edit of the table that changes a device's limits fails here.

#include "realtime/haptics/safety_layer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <stdexcept>
#include <string>

using namespace kerf;

TEST(DeviceSpecs, NamedDevicesHaveTheirMakersMaximumForce) {
  EXPECT_EQ(device_specs("touch").max_force, 3.3);
  EXPECT_EQ(device_specs("phantom-omni").max_force, 3.3);
  EXPECT_EQ(device_specs("phantom-desktop").max_force, 7.9);
  EXPECT_EQ(device_specs("phantom-premium-1.5").max_force, 8.5);
  EXPECT_EQ(device_specs("phantom-premium-3.0").max_force, 22.0);
  EXPECT_EQ(device_specs("falcon").max_force, 8.0);
  EXPECT_EQ(device_specs("delta.3").max_force, 20.0);
  EXPECT_EQ(device_specs("omega.3").max_force, 12.0);
  EXPECT_EQ(device_specs("omega.6").max_force, 12.0);
  EXPECT_EQ(device_specs("omega.7").max_force, 12.0);
  EXPECT_EQ(device_specs("sigma.7").max_force, 12.0);
  EXPECT_EQ(device_specs("touch").max_stiffness, 400.0);
  EXPECT_EQ(device_specs("falcon").max_stiffness, 3000.0);
  EXPECT_EQ(device_specs("omega.3").max_stiffness, 5000.0);
}

TEST(DeviceSpecs, TableRowsArePhysicalUniqueAndSourced) {
  std::set<std::string> names;
  for (const DeviceSpecs& d : device_table) {
    EXPECT_TRUE(names.insert(std::string(d.name)).second) << "duplicate name " << d.name;
    EXPECT_GT(d.max_force, 0.0) << d.name;
    EXPECT_TRUE(std::isfinite(d.max_force)) << d.name;
    EXPECT_GT(d.max_stiffness, 0.0) << d.name;
    EXPECT_FALSE(d.model.empty()) << d.name;
    EXPECT_FALSE(d.source.empty()) << d.name;
    EXPECT_EQ(&device_specs(d.name), &d);
  }
}

TEST(DeviceSpecs, UnknownNameIsAnErrorListingTheKnownOnes) {
  try {
    (void)device_specs("phantom");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'phantom'"), std::string::npos) << what;
    EXPECT_NE(what.find("touch"), std::string::npos) << what;
    EXPECT_NE(what.find("omega.3"), std::string::npos) << what;
  }
}

TEST(RigSafetyDefaults, AreTheDefaultDevicesLimitsAndATenMillisecondWatchdog) {
  // 8.5 N: the PHANToM Premium 1.5 (the default device); 1000 N/s; 0.2 s ramps; 10 ms watchdog.
  EXPECT_EQ(default_safety_limits.max_force, 8.5);
  EXPECT_EQ(default_safety_limits.max_force, device_specs(default_device_model).max_force);
  EXPECT_EQ(default_safety_limits.max_force_rate, 1000.0);
  EXPECT_EQ(default_safety_limits.ramp_time, 0.2);
  EXPECT_EQ(default_safety_limits.watchdog_timeout, 0.010);
  EXPECT_NO_THROW(SafetyLayer{default_safety_limits});
  // A named device changes the force clamp only.
  const SafetyLimits touch = default_safety_limits_for(device_specs("touch"));
  EXPECT_EQ(touch.max_force, 3.3);
  EXPECT_EQ(touch.max_force_rate, default_safety_limits.max_force_rate);
  EXPECT_EQ(touch.ramp_time, default_safety_limits.ramp_time);
  EXPECT_EQ(touch.watchdog_timeout, default_safety_limits.watchdog_timeout);
  // The watchdog: 10 ms at 1 kHz (10 ticks), never below two periods (100 Hz: 20 ms).
  EXPECT_EQ(default_watchdog_timeout(1000.0), 0.010);
  EXPECT_EQ(default_watchdog_timeout(10000.0), 0.010);
  EXPECT_EQ(default_watchdog_timeout(100.0), 0.02);
}

TEST(RigSafetyDefaults, TheClampOfANamedDeviceHoldsInTheSafetyLayer) {
  // A Touch's 3.3 N: a 10 N model force is scaled to 3.3 N even when the device declares 8.5 N.
  SafetyLayer s(default_safety_limits_for(device_specs("touch")));
  s.start(-1.0); // ramp finished
  std::uint32_t status = 0;
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  for (int k = 0; k < 20; ++k) f = s.filter({10.0, 0.0, 0.0}, 0.0, 0.0, 1e-3, 8.5, status); // 1 N per tick
  EXPECT_DOUBLE_EQ(f.x(), 3.3);
  EXPECT_TRUE(status & safety_clamped);
}
