#pragma once
// Replaying what a hand did at the rig: the tool positions of a recorded haptic session
// (realtime/haptics/session_file.hpp) as trajectories, for `kerf run --trajectory` (a fast model
// offline) and `kerf reference --trajectory` (the ground truth for the same motion).

#include "formats/scene/scene.hpp"
#include "formats/trajectory/trajectory.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace kerf {

/// One trajectory per named tool (matched by name with the session's tools), sampled at the
/// session's servo rate. Throws std::invalid_argument naming the file if a tool is missing or the
/// session has no ticks.
std::vector<SampledTrajectory> session_trajectories(const std::filesystem::path& session,
                                                    const std::vector<std::string>& tools);

/// `scene` with every tool's trajectory replaced by the session's: each tool's positions are
/// written as a recorded trajectory (`DIR/session_TOOL.csv`, columns t,px,py,pz) at the session's
/// rate, so anything that samples a Scene — the reference — replays the hand's motion.
Scene replay_session(const Scene& scene, const std::filesystem::path& session, const std::filesystem::path& dir);

} // namespace kerf
