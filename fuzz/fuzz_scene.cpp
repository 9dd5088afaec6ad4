#include "fuzz/fuzz_targets.hpp"

#include "formats/scene/scene_reader.hpp"
#include "fuzz/fuzz_input_file.hpp"

namespace kerf::fuzz {

void fuzz_scene(std::span<const std::byte> data) {
  const std::filesystem::path file = write_input_file(data, "scene.toml");
  try {
    const Scene scene = read_scene(file);
    if (scene.tools.empty()) throw FuzzFinding("a scene was accepted without tools");
  } catch (const SceneError&) {
    // The documented rejection, naming file:line:column and the key.
  }
}

} // namespace kerf::fuzz
