#include "experiments/study/study_plots.hpp"

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

void plot_profiles(const std::filesystem::path& stem,
                   const std::vector<std::pair<std::string, std::filesystem::path>>& runs, const std::string& axis) {
  std::vector<std::string> args{"profiles", stem.string(), "--axis=" + axis};
  for (const auto& [label, csv] : runs) args.push_back(label + "=" + csv.string());
  run_plot_script(args);
}

void plot_pareto(const std::filesystem::path& stem, const std::filesystem::path& table_csv, const std::string& error_column,
                 const std::string& cost_column, const std::string& label_column) {
  run_plot_script({"pareto", stem.string(), table_csv.string(), "--error", error_column, "--cost", cost_column,
                   "--label", label_column});
}

void plot_stability(const std::filesystem::path& stem,
                    const std::vector<std::pair<std::string, std::filesystem::path>>& runs) {
  std::vector<std::string> args{"stability", stem.string()};
  for (const auto& [model, csv] : runs) args.push_back(model + "=" + csv.string());
  run_plot_script(args);
}

} // namespace kerf
