#include "experiments/study/study_plots.hpp"

#include <cstdio>
#include <stdexcept>

#include <spawn.h>
#include <sys/wait.h>

extern char** environ;

namespace kerf {

namespace {

/// Runs /usr/bin/python3 with the plot script and `args` (no shell: arguments pass verbatim).
void run_plot_script(const std::vector<std::string>& args) {
  std::vector<std::string> argv_strings{"/usr/bin/python3", KERF_PLOT_SCRIPT};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_strings) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0)
    throw std::runtime_error("plots: cannot start /usr/bin/python3 (install python3-matplotlib)");
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::string command;
    for (const std::string& a : argv_strings) command += (command.empty() ? "" : " ") + a;
    throw std::runtime_error("plots: `" + command + "` failed");
  }
}

} // namespace

void plot_profiles(const std::filesystem::path& stem, const std::vector<std::pair<std::string, std::filesystem::path>>& runs,
                   const Eigen::Vector3d& direction, const std::optional<ProfilePlotReference>& reference, bool time_panel,
                   const std::string& title) {
  char d[96];
  std::snprintf(d, sizeof d, "--direction=%.17g,%.17g,%.17g", direction.x(), direction.y(), direction.z());
  std::vector<std::string> args{"profiles", stem.string(), d, "--title=" + title};
  for (const auto& [label, csv] : runs) args.insert(args.end(), {"--run", label, csv.string()}); // a label may hold "="
  if (reference) {
    args.insert(args.end(), {"--reference", reference->label, reference->csv.string()});
    args.push_back("--band-source=" + reference->band_source);
  }
  if (time_panel) args.push_back("--time-panel");
  run_plot_script(args);
}

void plot_pareto(const std::filesystem::path& stem, const std::filesystem::path& table_csv, const std::string& error_column,
                 const std::string& cost_column, const std::string& label_column, const std::string& scene,
                 std::optional<double> floor, const std::string& title) {
  std::vector<std::string> args{"pareto", stem.string(), table_csv.string(), "--error", error_column, "--cost", cost_column,
                                "--label", label_column, "--title=" + title};
  if (!scene.empty()) args.push_back("--scene=" + scene);
  if (floor) {
    char text[64];
    std::snprintf(text, sizeof text, "--floor=%.17g", *floor);
    args.push_back(text);
  }
  run_plot_script(args);
}

Eigen::Vector3d advance_direction(const Scene& scene) {
  const Tool& tool = scene.tools.front();
  if (tool.kind == Tool::Kind::blade) return tool.blade.cutting_direction.normalized();
  Eigen::Vector3d from = tool.trajectory.start;
  for (const TrajectorySegment& s : tool.trajectory.segments)
    if (s.kind == TrajectorySegment::Kind::move) {
      if ((s.target - from).norm() > 0.0) return (s.target - from).normalized();
      from = s.target;
    }
  return Eigen::Vector3d::UnitZ();
}

bool holds_or_retreats(const Scene& scene) {
  const Tool& tool = scene.tools.front();
  const Eigen::Vector3d d = advance_direction(scene);
  Eigen::Vector3d from = tool.trajectory.start;
  for (const TrajectorySegment& s : tool.trajectory.segments) {
    if (s.kind != TrajectorySegment::Kind::move) return true;
    if ((s.target - from).dot(d) < 0.0) return true;
    from = s.target;
  }
  return !tool.trajectory.recorded_file.empty(); // a recorded hand: assume it does
}

void plot_stability(const std::filesystem::path& stem,
                    const std::vector<std::pair<std::string, std::filesystem::path>>& runs) {
  std::vector<std::string> args{"stability", stem.string()};
  for (const auto& [model, csv] : runs) args.push_back(model + "=" + csv.string());
  run_plot_script(args);
}

} // namespace kerf
