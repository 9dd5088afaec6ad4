#pragma once
// Tool trajectories: scripted piecewise-linear motion (approach, cut to depth, dwell, retreat,
// paper 002's proportional-depth and constant-depth cuts, straight pulls) or a recorded session,
// sampled at the servo rate into the tool states every model is stepped with.

#include "realtime/tool_state.hpp"

#include <Eigen/Core>

#include <filesystem>
#include <string>
#include <vector>

namespace kerf {

/// One scripted segment. `move`: straight line from the previous end point to `target` at
/// constant `speed` [m/s]. `dwell`: stay put for `duration` [s].
struct TrajectorySegment {
  enum class Kind { move, dwell };
  Kind kind = Kind::move;
  std::string label;                               ///< e.g. "approach", "cut", "retreat"
  Eigen::Vector3d target = Eigen::Vector3d::Zero(); ///< [m], move only
  double speed = 0.0;                              ///< [m/s] > 0, move only
  double duration = 0.0;                           ///< [s] > 0, dwell only
};

/// A tool's motion as the scene declares it: either scripted segments from `start`, or a recorded
/// CSV file (`recorded_file` non-empty; columns t,px,py,pz in seconds and metres, header line).
struct TrajectorySpec {
  double rate = 1000.0;                            ///< sampling rate [Hz]
  Eigen::Vector3d start = Eigen::Vector3d::Zero(); ///< [m]
  std::vector<TrajectorySegment> segments;
  std::filesystem::path recorded_file;             ///< absolute once read from a scene
};

/// Samples of one tool's motion at a fixed rate. Velocities are those of the segment the sample
/// lies in (scripted), or central differences (recorded).
struct SampledTrajectory {
  double rate = 0.0;                ///< [Hz]
  std::vector<ToolState> samples;   ///< time-ordered, samples[k].time = k / rate
  std::vector<std::string> labels;  ///< the segment label of each sample ("" if none)
  [[nodiscard]] double duration() const { return samples.empty() ? 0.0 : samples.back().time; }
};

/// Samples a scripted trajectory: t_k = k / rate for k = 0 .. floor(T rate) (T = total duration),
/// the position interpolated linearly within each segment. Throws std::invalid_argument on a
/// non-positive rate, speed or duration.
SampledTrajectory sample_trajectory(const TrajectorySpec& spec);

/// Reads a recorded trajectory CSV (header `t,px,py,pz`, SI units, strictly increasing t) and
/// resamples it at `rate` by linear interpolation. Throws std::runtime_error naming file:line
/// on malformed rows.
SampledTrajectory read_recorded_trajectory(const std::filesystem::path& csv, double rate);

/// Samples the spec, from its segments or its recorded file.
SampledTrajectory sample(const TrajectorySpec& spec);

} // namespace kerf
