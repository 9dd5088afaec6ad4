// clay_tear with fracture on (Reference II): two tied styluses pull the clay block apart at 5 mm/s
// each; the cohesive mid-plane (20 × 20 mm, J_c = 50 J/m², σ_c = 50 kPa) tears from the top down.
// The tear is unstable under the hands' displacement control (the block stores ~100 mJ when it
// starts and needs J_c A = 20 mJ), so the law carries its viscous regularisation (Gao & Bower 2004,
// Eq. 5, weighted by the strength left: reference/cohesive/cohesive_law.hpp), τ = 0.1 s.
// Expected values, independent of the solver:
//   separation     the failed area reaches the whole plane A = 20 mm × 20 mm and the cohesive
//                  dissipation is J_c A = 20 mJ (the area under the bilinear law, per area);
//   free halves    afterwards the hands feel nothing: each half rests on a frictionless base;
//   equilibrium    the hands' pulls are equal and opposite (the base takes no force along x);
//   energy         work = strain + interface energy + cohesive + viscous dissipation (within 1%)
//                  while the tear is under way (docs/cohesive-fracture.md: after the last ligament
//                  parts, the freed halves' recoil leaves the quasi-static ledger).

#include "experiments/reference_run/reference_run.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace kerf {
namespace {

TEST(ClayTear, ViscousRegularisedTearReachesSeparation) {
  namespace fs = std::filesystem;
  const Scene scene = read_scene(fs::path(KERF_SOURCE_DIR) / "experiments" / "scenes" / "clay_tear.toml");
  ASSERT_EQ(scene.tools.size(), 2u);
  const TetMesh mesh = scene_mesh(scene);

  // One sample per 14 ms (the trajectory's 1 kHz samples) to t = 1 s, the pull; then the tear at
  // t ≈ 1.2–1.36 s, and the separated halves.
  ReferenceRunSettings settings;
  settings.fracture = ReferenceFracture::on;
  settings.cohesive_viscous_time = 0.1;
  settings.write_fields = false;
  settings.checkpoint_every = 1000;
  // From t = 1 s, one per 7 ms: the tear runs through in ~0.2 s, and the ledger's trapezoid rule of
  // the hands' work against the backward-Euler viscous term errs by about the sample spacing
  // (docs/cohesive-fracture.md: "finer samples shrink it").
  for (std::size_t k = 0; k < 1008; k += 14) settings.sample_indices.push_back(k);
  for (std::size_t k = 1008; k <= 1694; k += 7) settings.sample_indices.push_back(k);
  const fs::path dir = fs::temp_directory_path() / "kerf_test_clay_tear";
  fs::remove_all(dir);
  (void)run_reference(scene, mesh, settings, dir);

  nlohmann::json manifest;
  std::ifstream(dir / "manifest.json") >> manifest;
  ASSERT_TRUE(manifest.at("stopped").is_null()) << manifest.at("stopped");
  const auto& samples = manifest.at("samples");
  ASSERT_EQ(samples.size(), settings.sample_indices.size());

  const double plane = scene.geometry.parameters.at("width") * scene.geometry.parameters.at("depth"); // 400 mm²
  const double Jc = scene.material.fracture_toughness;
  double peak = 0.0, peak_time = 0.0, separation_time = -1.0, worst_balance_first_half = 0.0;
  for (const auto& s : samples) {
    const double t = s.at("t_s").get<double>();
    const double left = s.at("tool_forces_N").at("left")[0].get<double>();
    const double right = s.at("tool_forces_N").at("right")[0].get<double>();
    EXPECT_NEAR(left, -right, 1e-6) << "t = " << t;
    if (std::abs(left) > peak) {
      peak = std::abs(left);
      peak_time = t;
    }
    const auto& e = s.at("energy");
    const double failed = e.at("failed_area_m2").get<double>();
    if (failed < 0.5 * plane)
      worst_balance_first_half = std::max(worst_balance_first_half, std::abs(e.at("balance_error").get<double>()));
    if (separation_time < 0.0 && failed >= plane * (1.0 - 1e-9)) separation_time = t;
    if (separation_time >= 0.0 && t > separation_time + 0.02) {
      EXPECT_LT(std::abs(left), 1e-6) << "t = " << t;
    }
  }
  const auto& last = samples.back().at("energy");
  const double cohesive = last.at("cohesive_dissipation_J").get<double>();
  const double viscous = last.at("viscous_dissipation_J").get<double>();
  std::printf("clay_tear: peak %.3f N at t = %.3f s, separated at t = %.3f s, cohesive %.3f mJ, viscous %.3f mJ "
              "(share %.1f%%), worst balance before half the plane failed %.3f%%\n",
              peak, peak_time, separation_time, cohesive * 1e3, viscous * 1e3, 100.0 * viscous / (viscous + cohesive),
              100.0 * worst_balance_first_half);
  ASSERT_GE(separation_time, 0.0) << "the plane never failed completely";
  EXPECT_NEAR(last.at("failed_area_m2").get<double>(), plane, 1e-9 * plane);
  EXPECT_NEAR(cohesive, Jc * plane, 0.02 * Jc * plane);
  EXPECT_LT(worst_balance_first_half, 0.01);
  EXPECT_GT(viscous, 0.0);
  fs::remove_all(dir);
}

} // namespace
} // namespace kerf
