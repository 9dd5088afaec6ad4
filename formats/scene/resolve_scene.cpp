#include "formats/scene/resolve_scene.hpp"

#include "formats/scene/scene_reader.hpp"

namespace kerf {

std::filesystem::path resolve_scene(const std::string& argument) {
  std::filesystem::path p(argument);
  if (std::filesystem::exists(p)) return p;
  if (p.extension().empty()) {
    const std::filesystem::path named = std::filesystem::path(KERF_SCENES_DIR) / (argument + ".toml");
    if (std::filesystem::exists(named)) return named;
  }
  throw SceneError(argument + ": no such scene file, and no scene of that name in " + std::string(KERF_SCENES_DIR));
}

} // namespace kerf
