// `include = "FILE.toml"` in a scene (docs/scenes.md): a parameter file's [models.*] keys replace
// the scene's, are unit-converted like any value, and errors name the parameter file's line.

#include "formats/scene/scene_reader.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include <unistd.h>

using namespace kerf;
namespace fs = std::filesystem;

namespace {

/// A copy of a catalogue scene in a temporary folder, with `extra` appended at its top (before
/// the first table), and the parameter file `parameters` beside it.
fs::path scene_with(const std::string& name, const std::string& extra, const std::string& parameters) {
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_include_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ifstream in(fs::path(KERF_SCENES_DIR) / (name + ".toml"));
  std::stringstream text;
  text << in.rdbuf();
  std::ofstream(dir / "params.toml") << parameters;
  const fs::path scene = dir / (name + ".toml");
  std::ofstream(scene) << extra << "\n" << text.str();
  return scene;
}

} // namespace

TEST(SceneInclude, ParameterFileReplacesModelKeysWithUnits) {
  const fs::path scene = scene_with("clay_pull", "include = \"params.toml\"",
                                    "[models.springs]\nstiffness_scale = 1.25\n");
  const Scene s = read_scene(scene);
  ASSERT_TRUE(s.springs.has_value());
  EXPECT_EQ(s.springs->stiffness_scale, 1.25);

  const fs::path potato = scene_with("potato_rect_cut", "include = [\"params.toml\"]",
                                     "[models.fracture]\nrupture_deflection = \"2 mm\"\n"
                                     "[models.voxel]\nelastic_coefficient = \"2 N/mm^2\"\n"
                                     "friction_coefficient = 0.1\ndamping_coefficient = 0\ncritical_force_cutting = \"1 N\"\n"
                                     "critical_force_depth = \"2 N\"\nadvance_length = \"0.1 mm\"\n");
  const Scene p = read_scene(potato);
  EXPECT_DOUBLE_EQ(p.fracture->rupture_deflection, 2e-3);           // replaced, converted from mm
  EXPECT_DOUBLE_EQ(p.fracture->rupture_force_per_length, 300.0);    // the scene's own
  ASSERT_TRUE(p.voxel.has_value());                                 // a section the scene lacked
  EXPECT_DOUBLE_EQ(p.voxel->elastic_coefficient, 2e6);              // 2 N/mm^2 = 2 MPa
}

TEST(SceneInclude, ErrorsNameTheParameterFileAndOnlyModelTablesAreAllowed) {
  const std::pair<std::string, std::string> cases[] = {
      // A wrong unit in the parameter file: its own file, line 2, and the key.
      {"[models.fracture]\nrupture_deflection = \"2 kg\"\n", "params.toml:2:22: models.fracture.rupture_deflection"},
      // A material in a parameter file would change the reference: refused.
      {"[material]\nyoungs_modulus = \"1 MPa\"\n", "params.toml:1:2: material: a parameter file holds [models.*] tables only"},
      // An unknown key, reported where it is written.
      {"[models.springs]\nstifness_scale = 2\n", "params.toml:2:18: models.springs.stifness_scale: unknown key"},
      {"[models.springs]\nstiffness_scale = -1\n", "params.toml:2:19: models.springs.stiffness_scale"},
  };
  for (const auto& [parameters, expected] : cases) {
    const fs::path scene = scene_with("potato_rect_cut", "include = \"params.toml\"", parameters);
    try {
      read_scene(scene);
      ADD_FAILURE() << "accepted " << parameters;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
  // A missing parameter file is named with the scene's include line.
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_include_" + std::to_string(::getpid()));
  const fs::path scene = scene_with("potato_rect_cut", "include = \"nowhere.toml\"", "");
  try {
    read_scene(scene);
    ADD_FAILURE() << "accepted a missing include";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find(":1:11: include: file \"nowhere.toml\" not found"), std::string::npos) << e.what();
  }
}
