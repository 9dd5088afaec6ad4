#include "realtime/haptics/device_specs.hpp"

#include <stdexcept>

namespace kerf {

std::string device_model_names() {
  std::string names;
  for (const DeviceSpecs& d : device_table) names += (names.empty() ? "" : ", ") + std::string(d.name);
  return names;
}

const DeviceSpecs& device_specs(std::string_view name) {
  for (const DeviceSpecs& d : device_table)
    if (d.name == name) return d;
  throw std::invalid_argument("unknown device model '" + std::string(name) + "' (known: " + device_model_names() + ")");
}

} // namespace kerf
