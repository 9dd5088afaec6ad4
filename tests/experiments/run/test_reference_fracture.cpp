// The scene-level crack path of Reference II (experiments/run/reference_fracture.hpp): the
// zone-resolution check reads the element size on the crack path, the viscous regularisation's η
// follows from τ, and bad input is refused naming the scene.

#include "experiments/run/reference_fracture.hpp"
#include "experiments/run/reference_run.hpp"
#include "experiments/run/scene_mesh.hpp"
#include "experiments/scene/scene_reader.hpp"
#include "reference/cohesive/cohesive_zone.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>

namespace kerf {
namespace {

TEST(ReferenceFracture, ZoneCheckUsesTheCrackPathElementSizeAndViscosityFollowsTau) {
  namespace fs = std::filesystem;
  Scene scene = read_scene(fs::path(KERF_SOURCE_DIR) / "experiments" / "scenes" / "potato_rect_cut.toml");
  scene.geometry.element_size = 5e-3; // a coarse mesh: the check reads numbers, the mesh only has to split
  const TetMesh mesh = scene_mesh(scene);
  // Rice's zone for the scene's law (reference/cohesive/cohesive_zone.hpp), 0.665 mm for potato
  // (σ_c = 1 MPa; (9π/32) E/(1−ν²) J_c/σ_c² = 0.8836 × 3.76 MPa × 200 J/m² / (1 MPa)²).
  const double l_cz = reference::cohesive_zone_length(scene.material.youngs_modulus, scene.material.poisson_ratio,
                                                      scene.material.fracture_toughness, scene.material.cohesive_strength);
  {
    ReferenceProblem rp = reference_problem(scene, mesh);
    const CrackPathInfo info = add_crack_path(scene, rp.problem, ReferenceFracture::on, 1);
    ASSERT_TRUE(info.active);
    EXPECT_DOUBLE_EQ(info.element_size, 2.5e-3); // one refinement halves the 5 mm elements
    EXPECT_NEAR(info.elements_in_zone, l_cz / 2.5e-3, 1e-12);
    EXPECT_FALSE(info.warning.empty()); // 0.27 elements < 3 (Turon et al. 2007)
    EXPECT_EQ(info.viscosity, 0.0);
    EXPECT_EQ(rp.problem.cohesive->law.viscosity, 0.0);
  }
  {
    // A cut plane graded to 0.2 mm (rect_prism.geo's cut_element_size): 3.3 elements in the zone.
    Scene graded = scene;
    graded.geometry.parameters["cut_element_size"] = 0.2e-3;
    ReferenceProblem rp = reference_problem(graded, mesh);
    const double tau = 0.1;
    const CrackPathInfo info = add_crack_path(graded, rp.problem, ReferenceFracture::on, 0, tau);
    EXPECT_DOUBLE_EQ(info.element_size, 0.2e-3);
    EXPECT_TRUE(info.warning.empty()) << info.warning;
    // η = σ_c τ/δ_f with δ_f = 2 J_c/σ_c (Gao & Bower 2004 in the form of add_crack_path).
    const double delta_f = 2.0 * scene.material.fracture_toughness / scene.material.cohesive_strength;
    EXPECT_NEAR(info.viscosity, scene.material.cohesive_strength * tau / delta_f, 1e-9 * info.viscosity);
    EXPECT_DOUBLE_EQ(rp.problem.cohesive->law.viscosity, info.viscosity);
  }
  {
    ReferenceProblem rp = reference_problem(scene, mesh);
    EXPECT_THROW(add_crack_path(scene, rp.problem, ReferenceFracture::on, 0, -1.0), std::invalid_argument);
  }
}

} // namespace
} // namespace kerf
