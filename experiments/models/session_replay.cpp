#include "experiments/models/session_replay.hpp"

#include "meshes/atomic_file.hpp"
#include "realtime/haptics/session_file.hpp"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <stdexcept>

namespace kerf {

std::vector<SampledTrajectory> session_trajectories(const std::filesystem::path& file,
                                                    const std::vector<std::string>& tools) {
  const Session session = read_session(file);
  if (session.ticks.empty()) throw std::invalid_argument(file.string() + ": the session has no ticks");
  const auto states = session_tool_states(session);
  std::vector<SampledTrajectory> out;
  for (const std::string& name : tools) {
    const auto& recorded = session.header.tools;
    const auto at = std::find(recorded.begin(), recorded.end(), name);
    if (at == recorded.end()) throw std::invalid_argument(file.string() + ": the session has no tool named " + name);
    SampledTrajectory t;
    t.rate = session.header.rate;
    t.samples = states[static_cast<std::size_t>(at - recorded.begin())];
    t.labels.assign(t.samples.size(), "session");
    out.push_back(std::move(t));
  }
  return out;
}

Scene replay_session(const Scene& scene, const std::filesystem::path& session, const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const Tool& t : scene.tools) names.push_back(t.name);
  const std::vector<SampledTrajectory> replayed = session_trajectories(session, names);
  Scene out = scene;
  for (std::size_t i = 0; i < out.tools.size(); ++i) {
    const std::filesystem::path csv = dir / ("session_" + names[i] + ".csv");
    write_atomically(csv, [&](const std::filesystem::path& tmp) {
      std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(tmp.c_str(), "w"), &std::fclose);
      if (!f) throw std::runtime_error(csv.string() + ": cannot open for writing");
      std::fprintf(f.get(), "t,px,py,pz\n");
      for (const ToolState& s : replayed[i].samples)
        std::fprintf(f.get(), "%.17g,%.17g,%.17g,%.17g\n", s.time, s.position.x(), s.position.y(), s.position.z());
      if (std::fflush(f.get()) != 0) throw std::runtime_error(csv.string() + ": write failed");
    });
    TrajectorySpec& spec = out.tools[i].trajectory;
    spec.segments.clear();
    spec.rate = replayed[i].rate;
    spec.recorded_file = std::filesystem::absolute(csv);
  }
  return out;
}

} // namespace kerf
