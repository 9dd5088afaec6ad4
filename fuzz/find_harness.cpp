#include "fuzz/fuzz_targets.hpp"

namespace kerf::fuzz {

FuzzHarness find_harness(std::string_view name) {
  if (name == "device_protocol") return &fuzz_device_protocol;
  if (name == "quantity") return &fuzz_quantity;
  if (name == "scene") return &fuzz_scene;
  if (name == "trajectory_csv") return &fuzz_trajectory_csv;
  if (name == "session_csv") return &fuzz_session_csv;
  if (name == "profile_csv") return &fuzz_profile_csv;
  return nullptr;
}

} // namespace kerf::fuzz
