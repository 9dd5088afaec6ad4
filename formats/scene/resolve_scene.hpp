#pragma once
// A scene named on a command line: a path to a .toml file, or the name of one of kerf's scenes
// (experiments/scenes/NAME.toml).

#include <filesystem>
#include <string>

namespace kerf {

/// `argument` if it is an existing file, else experiments/scenes/ARGUMENT.toml when the argument
/// has no extension and that scene exists. Throws SceneError (scene_reader.hpp) if it is neither.
std::filesystem::path resolve_scene(const std::string& argument);

} // namespace kerf
