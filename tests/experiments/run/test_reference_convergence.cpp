// Mesh convergence of the reference (experiments/reference_run/reference_convergence.hpp): clay_pull's
// stylus pull and the deformation phase of potato_rect_cut (the blade pressed 1.5 mm in, the
// scene's rupture deflection estimate, before any cutting) on coarse gmsh-free boxes of the
// scenes' sizes, refined 0, 1, 2 times (nested meshes: one boundary-value problem, h halved per
// level). A converging discretisation has curve differences that shrink,
// D_1 = max_t |F_2 − F_1| < D_0 = max_t |F_1 − F_0| (Roache 1998, §5.4); the observed order
// log2(D_0 / D_1) is positive. The blade's force also grows with depth at every level.

#include "experiments/reference_run/reference_convergence.hpp"
#include "formats/scene/scene_reader.hpp"
#include "experiments/study/study_runner.hpp"
#include "formats/trajectory/trajectory.hpp"
#include "meshes/box_tet_mesh.hpp"
#include "tests/experiments/run/grasp_on_box.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>

namespace kerf {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("kerf_reference_convergence_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  return dir;
}

void print(const ConvergenceStudy& s, const char* name) {
  for (std::size_t k = 0; k < s.levels.size(); ++k)
    std::printf("%s: refine %d, %zu DOFs, peak |F| %.6g N%s\n", name, s.levels[k].refinements, s.levels[k].dofs,
                s.peak_force[k], k < s.max_difference.size() ? (", D = " + std::to_string(s.max_difference[k])).c_str() : "");
  std::printf("%s: observed order %.3f\n", name, s.observed_order.front());
}

TEST(ReferenceConvergence, ClayPullDifferencesShrink) {
  const Scene scene = read_scene(fs::path(KERF_SCENES_DIR) / "clay_pull.toml");
  // clay_pull.toml: 40 × 40 × 20 mm block, x in [0, 40], y centred, base z = 0.
  TetMesh mesh = box_tet_mesh(Eigen::Vector3d(0, -0.02, 0), Eigen::Vector3d(0.04, 0.02, 0.02), 4, 4, 2);
  test::add_grasp_groups_to_box(scene, mesh); // the grasp disc as the box's top triangles under it (grasp_on_box.hpp)
  ReferenceRunSettings s;
  s.sample_indices = reference_sample_indices(sample(scene.tools.front().trajectory).samples.size(), 3);
  s.write_fields = false;
  const ConvergenceStudy study = run_reference_convergence(scene, mesh, s, 3, scratch("clay_pull"));
  print(study, "clay_pull");
  ASSERT_EQ(study.max_difference.size(), 2u);
  EXPECT_GT(study.peak_force[0], 0.0);
  EXPECT_LT(study.max_difference[1], study.max_difference[0]);
  EXPECT_GT(study.observed_order[0], 0.0);
  EXPECT_TRUE(fs::exists(scratch("x").parent_path() / "clay_pull" / "convergence.md"));
}

TEST(ReferenceConvergence, PotatoBladeDeformationPhaseConverges) {
  const Scene scene = read_scene(fs::path(KERF_SCENES_DIR) / "potato_rect_cut.toml");
  // potato_rect_cut.toml: 40 × 20 × 15 mm prism, x in [0, 40], y centred, base z = 0; the blade's
  // edge runs along y at x = 20 mm, a grid plane of the box at every level.
  const TetMesh mesh = box_tet_mesh(Eigen::Vector3d(0, -0.01, 0), Eigen::Vector3d(0.04, 0.01, 0.015), 4, 2, 2);
  // Trajectory: 1 mm approach at 1 mm/s, then down at 1 mm/s; t = 2.5 s is 1.5 mm deep.
  const std::size_t until = 2500; // sample index of t = 2.5 s at the scene's 1 kHz
  ReferenceRunSettings s;
  s.sample_indices = reference_sample_indices(until + 1, 6); // t = 0, 0.5, … 2.5 s
  s.write_fields = false;
  const ConvergenceStudy study = run_reference_convergence(scene, mesh, s, 3, scratch("potato"));
  print(study, "potato_rect_cut");
  for (const ConvergenceLevel& l : study.levels) {
    ASSERT_EQ(l.profile.rows.size(), 6u);
    EXPECT_NEAR(l.profile.rows.back().position.z(), 0.0135, 1e-9);
    // Above the top face (t <= 1 s) no force; below it the body pushes the blade up, more with depth.
    for (std::size_t i = 0; i < 6; ++i) {
      if (i <= 1) {
        EXPECT_EQ(l.profile.rows[i].force.norm(), 0.0) << "refine " << l.refinements << " sample " << i;
      }
      if (i >= 3) {
        EXPECT_GT(l.profile.rows[i].force.z(), l.profile.rows[i - 1].force.z()) << "refine " << l.refinements;
        EXPECT_EQ(l.profile.rows[i].mode, InteractionMode::deformation_1);
      }
    }
  }
  EXPECT_LT(study.max_difference[1], study.max_difference[0]);
  EXPECT_GT(study.observed_order[0], 0.0);
}

} // namespace
} // namespace kerf
