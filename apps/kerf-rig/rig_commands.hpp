#pragma once
// The rig's command line (kerf-rig): one file per subcommand, each adding itself to the
// application; a callback does the work and throws on failure (apps/command_line.hpp maps what it
// throws to exit statuses).

#include <CLI/CLI.hpp>

namespace kerf::cli {

void add_haptic_command(CLI::App& app);     ///< kerf-rig haptic SCENE --model M --device ADDRESS... (the live rig)
void add_device_sim_command(CLI::App& app); ///< kerf-rig device-sim SCENE [--port P]... (emulated devices)
void add_replay_command(CLI::App& app);     ///< kerf-rig replay SESSION [--scene S] [--model M] (a recorded hand again)

} // namespace kerf::cli
