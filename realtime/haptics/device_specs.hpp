#pragma once
// What a haptic device declares about itself, as plain data (CHAI3D's cHapticDeviceInfo, the kerf
// way: SI units in the names' docs), and the table of devices kerf knows by name, so that a user
// who names the device (`kerf-rig haptic --device-model touch`) gets its limits rather than another
// device's. Every number comes from the source named in its row (docs/haptic-rig.md, "Devices").

#include <array>
#include <cstddef>
#include <string>
#include <string_view>

namespace kerf {

/// One device's declared capabilities.
struct DeviceSpecs {
  std::string_view name;       ///< the name `--device-model` takes ("touch", "omega.3")
  std::string_view model;      ///< maker and model ("3D Systems Touch")
  double max_force = 0.0;      ///< [N] largest force the device exerts (its data sheet's peak / maximum force)
  double max_stiffness = 0.0;  ///< [N/m] largest stiffness it renders stably at 1 kHz
  std::string_view source;     ///< where both numbers come from
};

/// The devices kerf knows, by name. CHAI3D 3.2.0's device classes carry each device's maximum
/// force and stiffness as its maker specifies them (src/devices/CPhantomDevices.cpp,
/// cPhantomDevice::cPhantomDevice; src/devices/CDeltaDevices.cpp, cDeltaDevice::open).
inline constexpr std::array<DeviceSpecs, 11> device_table{{
    {"touch", "3D Systems Touch", 3.3, 400.0, "CHAI3D 3.2.0 CPhantomDevices.cpp (\"Touch\")"},
    {"phantom-omni", "SensAble PHANTOM Omni", 3.3, 700.0, "CHAI3D 3.2.0 CPhantomDevices.cpp (\"PHANTOM Omni\")"},
    {"phantom-desktop", "SensAble PHANTOM Desktop", 7.9, 1000.0,
     "CHAI3D 3.2.0 CPhantomDevices.cpp (\"PHANTOM Desktop\")"},
    {"phantom-premium-1.5", "SensAble PHANTOM Premium 1.5", 8.5, 800.0,
     "CHAI3D 3.2.0 CPhantomDevices.cpp (\"PHANTOM Premium 1.5 6DOF\")"},
    {"phantom-premium-3.0", "SensAble PHANTOM Premium 3.0", 22.0, 1000.0,
     "CHAI3D 3.2.0 CPhantomDevices.cpp (\"PHANTOM Premium 3.0 6DOF\")"},
    {"falcon", "Novint Falcon", 8.0, 3000.0, "CHAI3D 3.2.0 CDeltaDevices.cpp (DHD_DEVICE_FALCON)"},
    {"delta.3", "Force Dimension delta.3", 20.0, 5000.0, "CHAI3D 3.2.0 CDeltaDevices.cpp (DHD_DEVICE_DELTA3)"},
    {"omega.3", "Force Dimension omega.3", 12.0, 5000.0, "CHAI3D 3.2.0 CDeltaDevices.cpp (DHD_DEVICE_OMEGA3)"},
    {"omega.6", "Force Dimension omega.6", 12.0, 5000.0, "CHAI3D 3.2.0 CDeltaDevices.cpp (DHD_DEVICE_OMEGA6_*)"},
    {"omega.7", "Force Dimension omega.7", 12.0, 5000.0, "CHAI3D 3.2.0 CDeltaDevices.cpp (DHD_DEVICE_OMEGA7_*)"},
    {"sigma.7", "Force Dimension sigma.7", 12.0, 4000.0, "CHAI3D 3.2.0 CDeltaDevices.cpp (DHD_DEVICE_SIGMA7_*)"},
}};

/// The device the rig's defaults are for when none is named: the PHANToM Premium 1.5 of the
/// papers' rigs (paper 000 used PHANToM devices).
inline constexpr std::string_view default_device_model = "phantom-premium-1.5";

/// The row of `device_table` called `name`, at compile time (an unknown name is a compile error
/// there: the lookup runs off the table's end).
constexpr const DeviceSpecs& device_specs_constexpr(std::string_view name) {
  std::size_t i = 0;
  while (device_table.at(i).name != name) ++i;
  return device_table[i];
}

/// The row of `device_table` called `name` (exactly as in the table). Throws
/// std::invalid_argument naming `name` and listing the known names.
const DeviceSpecs& device_specs(std::string_view name);

/// The known names, comma separated (for help texts and errors).
std::string device_model_names();

} // namespace kerf
