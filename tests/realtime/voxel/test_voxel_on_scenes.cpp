// The voxel model (paper 002) built by the catalogue on the sponge scenes as a user runs them
// (gmsh meshes, the scenes' trajectories and [models.voxel] = Table 1), the DCS/CFF switches of
// the scene file, the knife scenes' stick at the knife's point, and the refusal of other scenes. Kept beside the model's own tests (this
// program links kerf_experiments).

#include "experiments/models/model_catalogue.hpp"
#include "experiments/models/run_model.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/resolve_scene.hpp"
#include "formats/scene/scene_reader.hpp"
#include "realtime/voxel/voxel_surface_cutting_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

using namespace kerf;

namespace {

struct SceneRun {
  Scene scene;
  BuiltModel built;
  ForceProfile profile;
};

SceneRun run(const Scene& scene) {
  SceneRun r{scene, {}, {}};
  const TetMesh mesh = scene_mesh(r.scene);
  r.built = make_model("voxel", r.scene, mesh);
  r.profile = run_model(*r.built.model, {r.scene.tools.front().name}, sample_scene_trajectories(r.scene));
  return r;
}

/// Mean force against the cut (-f_x) over the rows of the cut phase (x between 0.15 and
/// 0.85 mm, tip deeper than 0.02 mm): first and last fifth.
std::pair<double, double> cut_force_fifths(const ForceProfile& p) {
  std::vector<double> fx;
  for (const ProfileRow& row : p.rows)
    if (row.mode == InteractionMode::cutting && row.position.x() > 0.15e-3 && row.position.x() < 0.85e-3)
      fx.push_back(-row.force.x());
  const std::size_t n = fx.size() / 5;
  double first = 0.0, last = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    first += fx[k] / static_cast<double>(n);
    last += fx[fx.size() - n + k] / static_cast<double>(n);
  }
  return {first, last};
}

} // namespace

TEST(VoxelOnScenes, TableOneIsReadInThePapersMillimetreUnit) {
  const Scene scene = read_scene(resolve_scene("sponge_cut_constant"));
  const SceneRun r = run(scene);
  // docs/models.md (voxel): "20.0 N/m^2" -> E = 20 N/mm^2 = 2e7 Pa, k_e = E x 1 mm = 2e4 N/m;
  // "0.5 N s/m^2" -> λ = 0.5 N s/mm^2 = 5e5 N s/m^2, per unit penetration (F = λ δ dδ/dt).
  EXPECT_DOUBLE_EQ(r.built.parameters["contact_stiffness_N_per_m"].get<double>(), 2e4);
  EXPECT_DOUBLE_EQ(r.built.parameters["clip_modulus_Pa"].get<double>(), 2e7);
  EXPECT_DOUBLE_EQ(r.built.parameters["damping_N_s_per_m2"].get<double>(), 5e5);
  EXPECT_TRUE(r.built.parameters["depth_cutting_stiffness"].get<bool>());
  EXPECT_TRUE(r.built.parameters["clip_friction"].get<bool>());
}

TEST(VoxelOnScenes, SpongeCutsGiveFlatAndGrowingCuttingForces) {
  // Paper 002 Fig. 5: constant depth (0.5 mm) -> flat; proportional depth (0 -> 0.5 mm) ->
  // growing, as the DCS 0.066 E d follows the depth d (0.66 N at 0.5 mm).
  const SceneRun constant = run(read_scene(resolve_scene("sponge_cut_constant")));
  const SceneRun proportional = run(read_scene(resolve_scene("sponge_cut_proportional")));
  for (const SceneRun* r : {&constant, &proportional}) {
    for (const ProfileRow& row : r->profile.rows) ASSERT_TRUE(row.force.allFinite());
    // The cut runs from x = 0.1 mm to 0.9 mm: Cl at the end ~0.8 mm.
    EXPECT_NEAR(r->profile.rows.back().crack_extent, 0.8e-3, 0.05e-3) << r->scene.name;
    EXPECT_EQ(r->profile.rows.front().mode, InteractionMode::no_contact);
    EXPECT_EQ(r->profile.rows.back().mode, InteractionMode::no_contact);
  }
  const auto [c_first, c_last] = cut_force_fifths(constant.profile);
  const auto [p_first, p_last] = cut_force_fifths(proportional.profile);
  EXPECT_NEAR(c_first, c_last, 0.1 * c_last);
  EXPECT_GT(p_last - p_first, 0.3);
}

TEST(VoxelOnScenes, DcsAndClipFrictionSwitchFromTheSceneFile) {
  // The paper's case a) (neither), read from a copy of the scene with both keys false.
  std::ifstream in(resolve_scene("sponge_cut_constant"));
  std::stringstream text;
  text << in.rdbuf();
  std::string toml = text.str();
  const std::string anchor = "grid = [10, 20, 20]";
  ASSERT_NE(toml.find(anchor), std::string::npos);
  toml.replace(toml.find(anchor), anchor.size(), anchor + "\ndepth_cutting_stiffness = false\nclip_friction = false");
  const std::filesystem::path copy = std::filesystem::temp_directory_path() / "kerf_voxel_case_a.toml";
  std::ofstream(copy) << toml;
  Scene scene = read_scene(copy);
  EXPECT_FALSE(scene.voxel->depth_cutting_stiffness);
  EXPECT_FALSE(scene.voxel->clip_friction);
  const SceneRun case_a = run(scene);
  const SceneRun case_d = run(read_scene(resolve_scene("sponge_cut_constant")));
  const auto [a_first, a_last] = cut_force_fifths(case_a.profile);
  const auto [d_first, d_last] = cut_force_fifths(case_d.profile);
  // Case a) feels only the point cut (wall force up to 0.1 N, friction of the bottom); case d)
  // adds the DCS 0.66 N at 0.5 mm depth (paper 002 Fig. 7: a) below the measured force).
  EXPECT_LT(a_last, 0.2);
  EXPECT_NEAR(d_last - a_last, 0.66, 0.05);
  // A switch that is not a boolean is an error naming the key.
  toml.replace(toml.find("clip_friction = false"), 21, "clip_friction = 1");
  std::ofstream(copy) << toml;
  try {
    read_scene(copy);
    ADD_FAILURE() << "a non-boolean clip_friction was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("clip_friction"), std::string::npos) << e.what();
  }
  std::filesystem::remove(copy);
}

TEST(VoxelOnScenes, AKnifeIsRenderedByTheStickAtItsPoint) {
  // sponge_knife_cut_*: a 0.1 mm knife, edge e = (3, 0, 4)/5 of 1 mm, cutting direction
  // d = (4, 0, -3)/5. The stick (docs/models.md, voxel, "A knife"): radius Cw = t/2 = 0.05 mm,
  // centre = the edge's lower end (midpoint - 0.5 mm e) - Cw d.
  const Scene scene = read_scene(resolve_scene("sponge_knife_cut_constant"));
  const TetMesh mesh = scene_mesh(scene);
  BuiltModel built = make_model("voxel", scene, mesh);
  EXPECT_DOUBLE_EQ(built.parameters["tool_radius_m"].get<double>(), 0.05e-3);
  const Eigen::Vector3d e(0.6, 0.0, 0.8), d(0.8, 0.0, -0.6);
  const Eigen::Vector3d expected = -0.5e-3 * e - 0.05e-3 * d;
  const auto offset = built.parameters["stick_centre_offset_m"].get<std::vector<double>>();
  ASSERT_EQ(offset.size(), 3u);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(offset[static_cast<std::size_t>(k)], expected[k], 1e-15);

  // Stepped along the scene's trajectory, the depth d of DCS and CFF (the stick's lowest point
  // below the top face z = 1 mm) follows the knife's point: drawn at constant depth, the midpoint
  // at z = 0.9 mm puts the centre at 0.9 - 0.4 + 0.05 x 0.6 = 0.53 mm and the stick's lowest point
  // at 0.48 mm, so d = 0.52 mm (the point itself is 0.5 mm deep).
  auto& model = dynamic_cast<VoxelSurfaceCuttingModel&>(*built.model);
  const std::vector<SampledTrajectory> trajectories = sample_scene_trajectories(scene);
  ForceSample force;
  int drawn = 0;
  for (const ToolState& st : trajectories.front().samples) {
    model.step(std::span<const ToolState>(&st, 1), 1e-3, std::span<ForceSample>(&force, 1));
    ASSERT_TRUE(force.force.allFinite());
    if (st.position.z() < 0.9e-3 + 1e-9 && st.position.x() > 0.5e-3 && st.position.x() < 0.8e-3) {
      EXPECT_NEAR(model.last_depth(), 0.52e-3, 1e-9) << "t = " << st.time;
      EXPECT_EQ(force.mode, InteractionMode::cutting) << "t = " << st.time;
      ++drawn;
    }
  }
  EXPECT_GT(drawn, 250); // 0.3 mm of the draw at 1 mm/s and 1 kHz
  // The cut length Cl: the draw of 0.4 mm, from where the front first advanced (at the end of
  // the plunge, within a few advance lengths) plus one advance length.
  EXPECT_NEAR(model.cut_length(), 0.4e-3, 0.06e-3);
}

TEST(VoxelOnScenes, RefusesScenesWithoutTableOneOrWithMoreThanOneTool) {
  for (const char* name : {"potato_rect_cut", "potato_wedge_cut", "liver_prism_cut"}) {
    const Scene s = read_scene(resolve_scene(name));
    try {
      require_model_for_scene("voxel", s);
      ADD_FAILURE() << name << " was accepted";
    } catch (const ModelMismatch& e) {
      EXPECT_NE(std::string(e.what()).find("[models.voxel]"), std::string::npos) << e.what();
    }
  }
  // clay_cut_apart: a blade and a stylus.
  try {
    require_model_for_scene("voxel", read_scene(resolve_scene("clay_cut_apart")));
    ADD_FAILURE() << "clay_cut_apart was accepted";
  } catch (const ModelMismatch& e) {
    EXPECT_NE(std::string(e.what()).find("one cutting stick"), std::string::npos) << e.what();
  }
  // clay_pull: one sphere, but no [models.voxel] (and no cutting).
  EXPECT_THROW(require_model_for_scene("voxel", read_scene(resolve_scene("clay_pull"))), ModelMismatch);
}

TEST(VoxelOnScenes, KnifeCutForceStepsAreTheOnesThePapersEquationsAllow) {
  // sponge_knife_cut_proportional, the cut segment (the knife drawn down and along at 1 mm/s,
  // the stick in contact): between two samples the force may change by
  //  - smoothly, one sample's motion (|v| = 1 mm/s, Δt = 1 ms, so 1 µm of travel): the
  //    elastic depth force by k_e |v| Δt = 0.02 N, the wall force by as much, the DCS 0.066 k_e d
  //    by 0.066 k_e |v| Δt = 0.0013 N, the damping λ δ dδ/dt by λ δ_max |v|² Δt... (δ_max below,
  //    < 10⁻⁵ N), CFF (Eq. 1, decreasing in Cl, growing with dz) by less than the DCS;
  //  - at a depth advance (§2.3 step 3: the surface point moves one advance length h when
  //    k_e δ_d exceeds F_crit,d): the normal force falls by at most what it was, k_e δ_max +
  //    λ δ_max |v| with k_e δ_max ≤ F_crit,d + k_e |v| Δt (the first sample past the critical
  //    force), and the Coulomb friction μ F_n with it, at right angles: sqrt(1 + μ²) ΔF_n;
  //  - at a cutting advance: the wall force k_e δ_c, at most F_crit,c + k_e |v| Δt, drops to 0.
  // A sample may hold both advances. The bound is their sum plus the smooth changes (the modes
  // stay "cutting" through the segment, so DCS and CFF are not switched). With Table 1: k_e =
  // 2e4 N/m, F_crit,d = 0.3 N, F_crit,c = 0.1 N, μ = 0.8, λ = 5e5 N s/m².
  const SceneRun r = run(read_scene(resolve_scene("sponge_knife_cut_proportional")));
  const double ke = 2e4, lambda = 5e5, mu = 0.8, v = 1e-3, dt = 1e-3;
  const double smooth = ke * v * dt;
  const double delta_max = (0.3 + smooth) / ke;
  const double normal_drop = ke * delta_max + lambda * delta_max * v;
  const double bound = std::sqrt(1.0 + mu * mu) * normal_drop + (0.1 + smooth) + 4.0 * smooth;
  // The cut segment: from the approach's end (the point on the top face, t = 0.1 s) to the
  // cut's end (t = 0.1 + 0.64 s), rows in contact on both sides.
  double largest = 0.0;
  int steps = 0;
  const auto& rows = r.profile.rows;
  for (std::size_t k = 1; k < rows.size(); ++k) {
    if (rows[k].t <= 0.1 || rows[k].t > 0.74 || rows[k - 1].mode == InteractionMode::no_contact ||
        rows[k].mode == InteractionMode::no_contact)
      continue;
    largest = std::max(largest, (rows[k].force - rows[k - 1].force).norm());
    ++steps;
  }
  EXPECT_GT(steps, 500);
  EXPECT_LE(largest, bound);
  // and the advances do happen: the bound is not met by a force that never moves.
  EXPECT_GT(largest, 0.5 * 0.3);
}
