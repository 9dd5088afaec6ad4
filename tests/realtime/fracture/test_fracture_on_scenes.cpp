// The fracture model as `kerf run` builds it (its cutting axis tabulated, ContactLengthTable)
// against the same model measuring l(x) on the mesh at every step (the second method), on the
// two potato scenes' gmsh meshes along their own trajectories: the same forces, sample by sample.

#include "experiments/models/model_catalogue.hpp"
#include "experiments/models/run_model.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"
#include "realtime/fracture/fracture_cutting_model.hpp"

#include <gtest/gtest.h>

#include <filesystem>

using namespace kerf;

TEST(FractureOnScenes, TabulatedCuttingAxisGivesTheMeasuredForces) {
  for (const char* name : {"potato_rect_cut", "potato_wedge_cut"}) {
    const Scene scene = read_scene(std::filesystem::path(KERF_SOURCE_DIR) / "experiments" / "scenes" / (std::string(name) + ".toml"));
    const TetMesh mesh = scene_mesh(scene);
    BuiltModel built = make_model("fracture", scene, mesh);
    auto& tabulated = dynamic_cast<FractureCuttingModel&>(*built.model);
    ASSERT_TRUE(tabulated.setup().cutting_axis_point.has_value()) << name;
    FractureCuttingSetup direct_setup = tabulated.setup();
    direct_setup.cutting_axis_point.reset();
    FractureCuttingModel measured(mesh, direct_setup);
    const std::vector<ToolState> samples = sample(scene.tools.front().trajectory).samples;
    ForceSample a, b;
    double largest = 0.0, scale = 0.0;
    int in_contact = 0;
    for (const ToolState& s : samples) {
      tabulated.step({&s, 1}, 1e-3, {&a, 1});
      measured.step({&s, 1}, 1e-3, {&b, 1});
      ASSERT_EQ(a.mode, b.mode) << name << " at t = " << s.time;
      ASSERT_EQ(a.crack_extent, b.crack_extent) << name << " at t = " << s.time;
      largest = std::max(largest, (a.force - b.force).norm());
      scale = std::max(scale, b.force.norm());
      in_contact += b.mode != InteractionMode::no_contact ? 1 : 0;
    }
    EXPECT_GT(in_contact, static_cast<int>(samples.size()) / 3) << name; // the approach and the retreat inside the crack are not
    // The table's l(x) is the measured one to round-off (ContactLengthTable's test: 10⁻¹³ of
    // the edge length); the forces are l times the responses, so 10⁻¹² of the largest force.
    EXPECT_LE(largest, 1e-12 * scale) << name;
  }
}
