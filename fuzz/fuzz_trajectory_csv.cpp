#include "fuzz/fuzz_targets.hpp"

#include "formats/trajectory/trajectory.hpp"
#include "fuzz/fuzz_input_file.hpp"

#include <cmath>

namespace kerf::fuzz {

void fuzz_trajectory_csv(std::span<const std::byte> data) {
  const std::filesystem::path file = write_input_file(data, "trajectory.csv");
  constexpr double rate = 1000.0; // the servo rate every scene uses
  try {
    const SampledTrajectory t = read_recorded_trajectory(file, rate);
    if (t.samples.size() != t.labels.size()) throw FuzzFinding("one label per sample");
    for (std::size_t k = 0; k < t.samples.size(); ++k) {
      const ToolState& s = t.samples[k];
      if (!s.position.allFinite() || !s.velocity.allFinite() || !std::isfinite(s.time))
        throw FuzzFinding("a recorded trajectory sample is not finite");
      // samples[k].time = k / rate (trajectory.hpp), to rounding.
      if (std::abs(s.time - static_cast<double>(k) / rate) > 1e-9 * (1.0 + s.time))
        throw FuzzFinding("a recorded trajectory sample is off its 1 kHz grid");
    }
  } catch (const std::runtime_error&) {
    // The documented rejection, naming file:line.
  }
}

} // namespace kerf::fuzz
