#pragma once
// Running one model on one scene: the scene's trajectories sampled, the model stepped through
// them with each step timed into a force profile (experiments/records/run_record.hpp writes it).

#include "formats/profile/force_profile.hpp"
#include "experiments/models/model_catalogue.hpp"
#include "formats/scene/scene.hpp"
#include "formats/trajectory/trajectory.hpp"

#include <filesystem>
#include <vector>

namespace kerf {

/// Steps `model` through the sampled trajectories (one per tool, same rate; a shorter one holds
/// its last state) and returns the profile, one row per tool per sample. Each row's cost_s is
/// the wall time of the model step that produced it (steady_clock); the profile counts the steps
/// the model reported over budget (ForceProfile::steps_over_budget). Throws
/// std::invalid_argument if the tool count or rates do not match.
ForceProfile run_model(ToolModel& model, const std::vector<std::string>& tool_names,
                       const std::vector<SampledTrajectory>& trajectories);

/// Cost statistics of the steps of a profile [s] (each step counted once).
struct CostStatistics {
  std::size_t steps = 0;
  double total = 0.0, median = 0.0, p99 = 0.0, max = 0.0;
  /// The servo rate the p99 cost allows [Hz] (1 / p99).
  [[nodiscard]] double rate_allowed() const { return p99 > 0.0 ? 1.0 / p99 : 0.0; }
};
CostStatistics cost_statistics(const ForceProfile& profile);
/// The cost of each step of a profile [s], in step order (each step counted once).
std::vector<double> step_costs(const ForceProfile& profile);
/// Cost statistics of step costs [s] (the nearest-rank median and 99th percentile); `costs` is
/// reordered.
CostStatistics cost_statistics(std::vector<double> costs);

/// Samples every tool's trajectory of the scene, in scene order.
std::vector<SampledTrajectory> sample_scene_trajectories(const Scene& scene);

} // namespace kerf
