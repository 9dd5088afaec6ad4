#include "viewer/offline_stepping.hpp"

#include <stdexcept>
#include <string>

namespace kerf {

void step_through(ViewedModel& model, const std::vector<SampledTrajectory>& trajectories, std::span<const double> times,
                  const std::function<void(const ViewFrame&)>& visit, const std::function<void(double)>& on_force) {
  if (static_cast<int>(trajectories.size()) != model.tool_count())
    throw std::invalid_argument("viewer: model " + std::string(model.name()) + " takes " +
                                std::to_string(model.tool_count()) + " tool(s), got " +
                                std::to_string(trajectories.size()) + " trajectories");
  std::size_t samples = 0;
  for (const SampledTrajectory& t : trajectories) {
    if (t.samples.empty()) throw std::invalid_argument("viewer: an empty trajectory");
    if (t.rate != trajectories.front().rate)
      throw std::invalid_argument("viewer: trajectories at different rates (" + std::to_string(t.rate) + " and " +
                                  std::to_string(trajectories.front().rate) + " Hz)");
    samples = std::max(samples, t.samples.size());
  }
  for (std::size_t k = 1; k < times.size(); ++k)
    if (times[k] < times[k - 1]) throw std::invalid_argument("viewer: snapshot times must be ascending");
  const double dt = 1.0 / trajectories.front().rate;
  model.reset();
  std::vector<ToolState> tools(trajectories.size());
  std::vector<ForceSample> forces(trajectories.size());
  std::size_t next = 0;
  for (std::size_t k = 0; k < samples && next < times.size(); ++k) {
    for (std::size_t i = 0; i < trajectories.size(); ++i)
      tools[i] = trajectories[i].samples[std::min(k, trajectories[i].samples.size() - 1)];
    model.step(tools, dt, forces);
    if (on_force) {
      double largest = 0.0;
      for (const ForceSample& f : forces) largest = std::max(largest, f.force.norm());
      on_force(largest);
    }
    const bool last = k + 1 == samples;
    const double t_next = static_cast<double>(k + 1) * dt;
    // Snapshot once this is the last sample at or before times[next].
    while (next < times.size() && (last || t_next > times[next] + 1e-12)) {
      model.publish_frame();
      model.update();
      visit(model.frame());
      ++next;
    }
  }
}

} // namespace kerf
