#pragma once
// Reading scene files (toml++). Units are converted here, once.

#include "formats/scene/scene.hpp"

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace kerf {

/// A scene file that cannot be used. what() reads
/// "FILE:LINE:COLUMN: KEY: what was expected (what was found)".
class SceneError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

/// Reads and validates a scene file. Unknown keys, missing fields, wrong units, non-finite or
/// out-of-range values, a missing geometry or trajectory file, and inconsistent tools are
/// SceneErrors naming file:line:column and the key. `parameter_files` are included after the
/// scene's own `include = ...` (docs/scenes.md, "Including parameter files"): each holds
/// [models.*] tables whose keys replace the scene's (calibrated model parameters).
Scene read_scene(const std::filesystem::path& file, const std::vector<std::filesystem::path>& parameter_files = {});

/// Directories searched for a scene's `geo = "NAME.geo"` after the scene file's own folder:
/// the kerf source tree's meshes/geo (compiled in) and $KERF_GEO_PATH if set.
std::vector<std::filesystem::path> geometry_search_path();

} // namespace kerf
