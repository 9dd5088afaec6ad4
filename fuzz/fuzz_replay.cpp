#include "fuzz/fuzz_targets.hpp"

#include "fuzz/fuzz_input_file.hpp"
#include "realtime/haptics/replay_device.hpp"

#include <cmath>
#include <optional>

namespace kerf::fuzz {

void fuzz_replay(std::span<const std::byte> data) {
  const std::filesystem::path file = write_input_file(data, "replay.csv");
  std::optional<ReplayDevice> device;
  try {
    device.emplace(file, 0, 8.5);
  } catch (const std::runtime_error&) {
    return; // the documented rejection, naming file:line
  }
  // The servo loop's use: poll at the rig clock, from before the start to past the end (held
  // there); every state must be finite (the UDP link accepts only finite states: a replay must
  // not be the way a NaN position reaches a model).
  const double duration = device->duration();
  if (!(duration > 0.0)) throw FuzzFinding("a replay was accepted with no positive duration");
  const double span = std::isfinite(duration) ? duration : 1e300; // rig clock times stay finite
  for (const double f : {0.0, 1e-9, 0.1, 0.25, 0.5, 0.75, 0.999, 1.0, 2.0}) {
    device->poll(f * span);
    if (!device->has_state()) throw FuzzFinding("a replay poll accepted no state");
    if (!device->state().position.allFinite()) throw FuzzFinding("a replay gave a non-finite position");
  }
}

} // namespace kerf::fuzz
