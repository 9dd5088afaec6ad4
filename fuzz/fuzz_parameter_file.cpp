#include "fuzz/fuzz_targets.hpp"

#include "formats/scene/scene_reader.hpp"
#include "experiments/study/study_spec.hpp"
#include "fuzz/fuzz_input_file.hpp"

#include <algorithm>
#include <vector>

namespace kerf::fuzz {

namespace {

/// The repository's scenes (experiments/scenes/*.toml), sorted: the first input byte picks one.
const std::vector<std::filesystem::path>& repository_scenes() {
  static const std::vector<std::filesystem::path> scenes = [] {
    std::vector<std::filesystem::path> out;
    for (const auto& e : std::filesystem::directory_iterator(KERF_SCENES_DIR))
      if (e.path().extension() == ".toml") out.push_back(e.path());
    std::sort(out.begin(), out.end());
    return out;
  }();
  return scenes;
}

} // namespace

void fuzz_parameter_file(std::span<const std::byte> data) {
  if (data.empty()) return;
  const auto& scenes = repository_scenes();
  const std::filesystem::path& scene_file = scenes[std::to_integer<std::size_t>(data[0]) % scenes.size()];
  const std::filesystem::path file = write_input_file(data.subspan(1), "parameters.toml");

  // The study's reader: the names of the [models.*] tables.
  std::vector<std::string> calibrated;
  bool study_accepts = true;
  try {
    calibrated = calibrated_models(file);
  } catch (const StudyError&) {
    study_accepts = false; // the documented rejection, naming file:line:column
  }

  // The scene's reader: the file's keys replace the scene's.
  try {
    const Scene scene = read_scene(scene_file, {file});
    if (!study_accepts) throw FuzzFinding("a parameter file the scene accepts is a syntax error to the study");
    for (const std::string& model : calibrated) {
      const bool has_section = (model == "fracture" && scene.fracture) || (model == "voxel" && scene.voxel) ||
                               (model == "springs" && scene.springs);
      if (!has_section) throw FuzzFinding("a parameter file for model \"" + model + "\" was accepted, but the scene has no such section");
    }
  } catch (const SceneError&) {
    // The documented rejection, naming the parameter file's (or the scene's) line and the key.
  }
}

} // namespace kerf::fuzz
