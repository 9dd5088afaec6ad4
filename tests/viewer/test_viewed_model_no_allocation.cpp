// The view's cost inside the servo thread allocates nothing: ViewedModel::step with a snapshot
// at every step (the worst case), for every model with an adapter, after the model's first
// contact (so every lazily filled structure is in use). The models' own steps are allocation-free
// by their own tests; what is counted here is the step plus the snapshot.

#include "experiments/models/model_catalogue.hpp"
#include "experiments/models/run_model.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"
#include "tests/realtime/counting_allocator.hpp"
#include "tests/realtime/springs/model_fixtures.hpp"
#include "viewer/viewed_model.hpp"

#include <gtest/gtest.h>

using namespace kerf;

namespace {

/// Steps `model` (built on `mesh`) through `t` with a snapshot after every step; returns the
/// allocations counted during the steps after the first `warmup` ones.
long allocations_while_viewed(ToolModel& model, const TetMesh& mesh, const std::vector<SampledTrajectory>& t,
                              std::size_t warmup) {
  std::unique_ptr<ModelAdapter> adapter = make_model_adapter(model, mesh);
  ViewedModel viewed(model, *adapter, 1e-9); // a snapshot at every step
  std::vector<ToolState> tools(t.size());
  std::vector<ForceSample> forces(t.size());
  std::size_t samples = 0;
  for (const auto& s : t) samples = std::max(samples, s.samples.size());
  const double dt = 1.0 / t[0].rate;
  long counted = 0;
  for (std::size_t k = 0; k < samples; ++k) {
    for (std::size_t i = 0; i < t.size(); ++i) tools[i] = t[i].samples[std::min(k, t[i].samples.size() - 1)];
    const long start = kerf::test::allocations.load();
    kerf::test::set_counting(true);
    viewed.step(tools, dt, forces);
    kerf::test::set_counting(false);
    if (k >= warmup) counted += kerf::test::allocations.load() - start;
  }
  EXPECT_GE(viewed.frames_published(), samples);
  return counted;
}

/// The same for model `model_name` built by the catalogue for scene `scene_name`.
long allocations_while_viewed(const std::string& scene_name, const std::string& model_name, std::size_t warmup) {
  const Scene scene = read_scene(std::string(KERF_SCENES_DIR) + "/" + scene_name + ".toml");
  const TetMesh mesh = scene_mesh(scene);
  BuiltModel built = make_model(model_name, scene, mesh);
  return allocations_while_viewed(*built.model, mesh, sample_scene_trajectories(scene), warmup);
}

} // namespace

// The spring network itself (the catalogue may wrap it), with the springs adapter's capture.
TEST(ViewedModelNoAllocation, SpringsOnClayPull) {
  const TetMesh mesh = test::clay_pull_mesh();
  SpringNetworkModel model(mesh, test::clay_pull_setup(SpringIntegrator::symplectic_euler));
  const auto t = sample_scene_trajectories(read_scene(std::string(KERF_SCENES_DIR) + "/clay_pull.toml"));
  EXPECT_EQ(allocations_while_viewed(model, mesh, t, 1), 0);
}
TEST(ViewedModelNoAllocation, FractureOnPotato) { EXPECT_EQ(allocations_while_viewed("potato_rect_cut", "fracture", 1), 0); }
TEST(ViewedModelNoAllocation, EdgeOnPotato) { EXPECT_EQ(allocations_while_viewed("potato_rect_cut", "edge", 1), 0); }
TEST(ViewedModelNoAllocation, VoxelOnSponge) { EXPECT_EQ(allocations_while_viewed("sponge_cut_constant", "voxel", 1), 0); }
// Shape forming (edge with a blade and a stylus): the edge's points, then the stage's network,
// captured while the worker thread cuts (its allocations are its own thread's, not counted).
TEST(ViewedModelNoAllocation, ShapeFormingOnClayCutApart) {
  EXPECT_EQ(allocations_while_viewed("clay_cut_apart", "edge", 1), 0);
}
