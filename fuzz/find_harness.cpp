#include "fuzz/fuzz_targets.hpp"

namespace kerf::fuzz {

FuzzHarness find_harness(std::string_view name) {
  if (name == "device_protocol") return &fuzz_device_protocol;
  if (name == "quantity") return &fuzz_quantity;
  if (name == "scene") return &fuzz_scene;
  if (name == "trajectory_csv") return &fuzz_trajectory_csv;
  if (name == "session_csv") return &fuzz_session_csv;
  if (name == "profile_csv") return &fuzz_profile_csv;
  if (name == "study") return &fuzz_study;
  if (name == "parameter_file") return &fuzz_parameter_file;
  if (name == "study_table") return &fuzz_study_table;
  if (name == "reference_checkpoint") return &fuzz_reference_checkpoint;
  if (name == "replay") return &fuzz_replay;
  return nullptr;
}

} // namespace kerf::fuzz
