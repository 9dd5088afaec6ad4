#include "experiments/models/run_model.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace kerf {

ForceProfile run_model(ToolModel& model, const std::vector<std::string>& tool_names,
                       const std::vector<SampledTrajectory>& trajectories) {
  const std::size_t tools = trajectories.size();
  if (static_cast<int>(tools) != model.tool_count() || tool_names.size() != tools)
    throw std::invalid_argument("run: model " + std::string(model.name()) + " takes " +
                                std::to_string(model.tool_count()) + " tool(s), the scene has " + std::to_string(tools));
  std::size_t samples = 0;
  for (const SampledTrajectory& t : trajectories) {
    if (t.samples.empty()) throw std::invalid_argument("run: a tool trajectory has no samples");
    if (std::abs(t.rate - trajectories.front().rate) > 1e-9 * t.rate)
      throw std::invalid_argument("run: all tools must be sampled at the same rate");
    samples = std::max(samples, t.samples.size());
  }
  const double dt = 1.0 / trajectories.front().rate;

  ForceProfile profile;
  profile.rows.reserve(samples * tools);
  std::vector<ToolState> states(tools);
  std::vector<ForceSample> forces(tools);
  model.reset();
  for (std::size_t k = 0; k < samples; ++k) {
    for (std::size_t i = 0; i < tools; ++i) {
      const auto& s = trajectories[i].samples;
      states[i] = s[std::min(k, s.size() - 1)];
      states[i].time = static_cast<double>(k) * dt;
      if (k >= s.size()) states[i].velocity.setZero();
    }
    const auto begin = std::chrono::steady_clock::now();
    model.step(states, dt, forces);
    const auto end = std::chrono::steady_clock::now();
    const double cost = std::chrono::duration<double>(end - begin).count();
    if (std::any_of(forces.begin(), forces.end(), [](const ForceSample& f) { return f.over_budget; })) ++profile.steps_over_budget;
    for (std::size_t i = 0; i < tools; ++i) {
      ProfileRow r;
      r.t = states[i].time;
      r.tool = tool_names[i];
      r.position = states[i].position;
      r.force = forces[i].force;
      r.mode = forces[i].mode;
      r.crack_extent = forces[i].crack_extent;
      r.cost_s = cost;
      profile.rows.push_back(std::move(r));
    }
  }
  return profile;
}

std::vector<double> step_costs(const ForceProfile& profile) {
  // Rows of one step share their time and cost: count each step once.
  std::vector<double> costs;
  double last_t = -1.0;
  for (const ProfileRow& r : profile.rows) {
    if (!costs.empty() && r.t == last_t) continue;
    costs.push_back(r.cost_s);
    last_t = r.t;
  }
  return costs;
}

CostStatistics cost_statistics(std::vector<double> costs) {
  CostStatistics s;
  s.steps = costs.size();
  if (costs.empty()) return s;
  for (double c : costs) s.total += c;
  std::sort(costs.begin(), costs.end());
  auto quantile = [&](double q) { return costs[std::min(costs.size() - 1, static_cast<std::size_t>(q * static_cast<double>(costs.size() - 1) + 0.5))]; };
  s.median = quantile(0.5);
  s.p99 = quantile(0.99);
  s.max = costs.back();
  return s;
}

CostStatistics cost_statistics(const ForceProfile& profile) { return cost_statistics(step_costs(profile)); }

std::vector<SampledTrajectory> sample_scene_trajectories(const Scene& scene) {
  std::vector<SampledTrajectory> out;
  for (const Tool& t : scene.tools) out.push_back(sample(t.trajectory));
  return out;
}

} // namespace kerf
