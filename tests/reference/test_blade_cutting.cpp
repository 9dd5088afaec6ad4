// Blade cutting through the cohesive interface of the reference (Reference II) on the scene as a
// user runs it: potato_rect_cut (gmsh mesh of rect_prism.geo, h = 2 mm, P1), the blade driven down
// through the top face to the scene's 10 mm depth, fracture on, frictionless. Expected values from
// paper 001 §3:
//
//   work balance   f_t Δx = ΔU + J_c a(Δs)                      (Eq. 6: deformation + fracture work)
//   steady state   a(Δs) = l Δx  ⇒  f = J_c l                    (Eqs. 9–10, l the contact length)
//
// with l = 20 mm the prism's width (the 30 mm edge spans it), J_c l = 4 N.
//
// The route (docs/cohesive-fracture.md, "Steady cutting"): the bilinear law separates the faces only
// past δ_f = 2 J_c/σ_c, and a blade of thickness t pushes the two halves apart by t behind its
// edge, which stores elastic energy that grows as t² (the deformation term ΔU of Eq. 6). So the
// potato scenes take σ_c = 1 MPa, the top of their cited range for potato tensile strength
// (0.3–1 MPa), which gives δ_f = 0.4 mm, and a thin blade just thicker than that, t = 0.5 mm
// (a 0.1 mm razor never separates the faces of this law). Its wedge (15°) is 1.9 mm
// long; the force is read from 4 mm depth, with the bevel fully inside, to the end of the cut.

#include "experiments/reference_run/reference_run.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>

namespace kerf {
namespace {

/// The scene `name` as its file gives it, with the thin blade of this file's route: σ_c = 1 MPa
/// (δ_f = 2 J_c/σ_c = 0.4 mm) and a blade 0.5 mm thick (> δ_f). Throws if the file gives other values.
Scene thin_blade_scene(const std::string& name) {
  Scene scene = read_scene(std::filesystem::path(KERF_SOURCE_DIR) / "experiments" / "scenes" / (name + ".toml"));
  if (std::abs(scene.material.cohesive_strength - 1e6) > 1e-6 || scene.tools.empty() ||
      std::abs(scene.tools.front().blade.thickness - 0.5e-3) > 1e-12)
    throw std::runtime_error(name + ": the test's route needs the scene's σ_c = 1 MPa and a 0.5 mm blade");
  return scene;
}

/// A fracture-on reference run solving every 250th trajectory sample (0.25 mm of blade travel at
/// 1 mm/s and 1 kHz) up to sample `last`; its profile and the manifest's per-sample ledger.
struct BladeRun {
  ForceProfile profile;
  nlohmann::json manifest;
  std::size_t samples_asked = 0;
  std::filesystem::path dir; ///< the run's output folder (removed by the test at its end)
};

BladeRun run_blade(const Scene& scene, const TetMesh& mesh, std::size_t last, const std::string& dir_name) {
  ReferenceRunSettings settings;
  settings.fracture = ReferenceFracture::on;
  settings.write_fields = false;
  settings.checkpoint_every = 1000;
  for (std::size_t k = 0; k <= last; k += 250) settings.sample_indices.push_back(k);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / dir_name;
  std::filesystem::remove_all(dir);
  BladeRun run;
  run.dir = dir;
  run.profile = run_reference(scene, mesh, settings, dir).profile;
  run.samples_asked = settings.sample_indices.size();
  std::ifstream(dir / "manifest.json") >> run.manifest;
  return run;
}

TEST(BladeCutting, SteadyCuttingForceIsToughnessTimesContactLength) {
  const Scene scene = thin_blade_scene("potato_rect_cut");
  ASSERT_EQ(scene.tools.size(), 1u);
  const TetMesh mesh = scene_mesh(scene);

  // Samples every 0.25 mm of blade travel: the approach (1 mm) and the whole 10 mm cut (t = 11 s).
  const BladeRun run = run_blade(scene, mesh, 11000, "kerf_test_blade_cutting");
  const ForceProfile& profile = run.profile;
  ASSERT_EQ(profile.rows.size(), run.samples_asked) << "the load path stopped";
  const nlohmann::json& manifest = run.manifest;
  const auto& samples = manifest.at("samples");
  auto at_time = [&](double t) -> const nlohmann::json& {
    for (const auto& s : samples)
      if (std::abs(s.at("t_s").get<double>() - t) < 1e-9) return s;
    throw std::runtime_error("no sample at t = " + std::to_string(t));
  };
  const nlohmann::json& a = at_time(5.0);  // 4 mm deep
  const nlohmann::json& b = at_time(11.0); // 10 mm deep
  const double dx = 6e-3;
  auto rate = [&](const char* key) { return (b.at("energy").at(key).get<double>() - a.at("energy").at(key).get<double>()) / dx; };
  const double l = 20e-3, Jc_l = scene.material.fracture_toughness * l; // 4 N
  // The mean cutting force over the steady part: the work per advance (trapezoid rule, which the
  // run's energy bookkeeping sums), and the plain mean of the sampled vertical force.
  const double work_rate = rate("external_work_J");
  std::vector<double> forces;
  for (const auto& s : samples) {
    const double t = s.at("t_s").get<double>();
    if (t >= 5.0 - 1e-9 && t <= 11.0 + 1e-9) forces.push_back(s.at("tool_force_N")[2].get<double>());
  }
  const double mean_force = std::accumulate(forces.begin(), forces.end(), 0.0) / static_cast<double>(forces.size());
  const double dissipation_rate = rate("cohesive_dissipation_J");
  const double stored_rate = rate("stored_elastic_energy_J") + rate("interface_energy_J") + rate("contact_energy_J");
  std::printf("steady cutting 4-10 mm: mean force %.4f N, dW/dx %.4f N, dD/dx %.4f N, dU/dx %.4f N, J_c l %.4f N, "
              "failed area per advance %.2f mm\n",
              mean_force, work_rate, dissipation_rate, stored_rate, Jc_l, rate("failed_area_m2") * 1e3);
  // Eq. 10: the steady cutting force is J_c l (required within 10%).
  EXPECT_NEAR(work_rate, Jc_l, 0.10 * Jc_l);
  EXPECT_NEAR(mean_force, Jc_l, 0.10 * Jc_l);
  // Eq. 9: the crack advances with the blade over the whole contact length, and dissipates J_c per area.
  EXPECT_NEAR(rate("failed_area_m2"), l, 0.05 * l);
  EXPECT_NEAR(dissipation_rate, Jc_l, 0.05 * Jc_l);
  // Eq. 6: what is left is the wedge's deformation work, small for a thin blade (t² scaling).
  EXPECT_NEAR(work_rate - stored_rate, dissipation_rate, 0.02 * Jc_l);
  EXPECT_LT(stored_rate, 0.10 * Jc_l);
  // The mechanics names the phase: the crack grows with the blade. Its failed front trails the
  // edge by the part of the bevel whose opening 2 s tan(θ/2) is still below δ_f (the faces lie on
  // the flanks): s = δ_f/(2 tan(θ/2)) = 1.52 mm for θ = 15°, so it reaches 10 − 1.52 mm (within
  // half a 2 mm element).
  EXPECT_EQ(profile.rows.back().mode, InteractionMode::cutting);
  const double half_angle = 0.5 * scene.tools.front().blade.wedge_angle;
  const double trailing = 0.4e-3 / (2.0 * std::tan(half_angle));
  EXPECT_NEAR(profile.rows.back().crack_extent, 10e-3 - trailing, 1e-3);
  // Energy balance of the whole run (required within 1%).
  EXPECT_LT(std::abs(manifest.at("energy").at("balance_error").get<double>()), 0.01);
  std::filesystem::remove_all(run.dir);
}

// potato_wedge_cut (tri_prism.geo: base b = 18 mm, apex d_a = 17 mm above it, h = 2 mm, P1): the
// blade enters the apex line, so the contact length grows with the depth d below the apex,
// l(d) = b d/d_a (paper 001 §5.1, Fig. 8), and Eq. 10 says the force grows with it, f = J_c l(d).
// Same route as above (σ_c = 1 MPa, 0.5 mm blade). Expected values:
//   work     W(d_0 → d_1) = J_c ∫ l dd = J_c b (d_1² − d_0²)/(2 d_a)       (Eq. 10 integrated)
//   fracture the dissipation density behind the edge is φ_d(κ) = J_c κ/δ_f on the softening branch
//            (reference/cohesive/cohesive_law.hpp, δ_0 ≪ δ_f), and the flanks open the faces to
//            κ = 2 s tan(θ/2) at a distance s behind the edge, which fails at s_f = δ_f/(2 tan(θ/2));
//            so the dissipated area trails the edge by s_f/2 on average:
//            D(d_0 → d_1) = J_c b ((d_1 − s_f/2)² − (d_0 − s_f/2)²)/(2 d_a).
// With 2 mm elements the sampled force saw-tooths as the crack front crosses elements, so the force
// is compared through the work over 3 mm windows.
TEST(BladeCutting, WedgeForceGrowsWithTheContactLength) {
  const Scene scene = thin_blade_scene("potato_wedge_cut");
  ASSERT_EQ(scene.tools.size(), 1u);
  const TetMesh mesh = scene_mesh(scene);
  const double b = scene.geometry.parameters.at("base_width"), apex = scene.geometry.parameters.at("depth");
  const double Jc = scene.material.fracture_toughness;
  const double delta_f = 2.0 * Jc / scene.material.cohesive_strength;
  const double s_f = delta_f / (2.0 * std::tan(0.5 * scene.tools.front().blade.wedge_angle));

  // Every 0.25 mm of blade travel: the 1 mm approach and 12 mm below the apex (t = 13 s).
  const BladeRun run = run_blade(scene, mesh, 13000, "kerf_test_wedge_cutting");
  const ForceProfile& profile = run.profile;
  ASSERT_EQ(profile.rows.size(), run.samples_asked) << "the load path stopped";
  const nlohmann::json& manifest = run.manifest;
  const auto& samples = manifest.at("samples");
  // The sample with the blade edge d below the apex: the edge touches it at t = 1 s, then moves at
  // 1 mm/s (the scene's trajectory).
  auto at_depth = [&](double d) -> const nlohmann::json& {
    const double t = 1.0 + d / 1e-3;
    for (const auto& s : samples)
      if (std::abs(s.at("t_s").get<double>() - t) < 1e-9) return s;
    throw std::runtime_error("no sample at depth " + std::to_string(d));
  };
  auto energy = [&](double d, const char* key) { return at_depth(d).at("energy").at(key).get<double>(); };
  auto work_ratio = [&](double d0, double d1) {
    return (energy(d1, "external_work_J") - energy(d0, "external_work_J")) / (Jc * b * (d1 * d1 - d0 * d0) / (2.0 * apex));
  };
  auto mean_work_rate = [&](double d0, double d1) {
    return (energy(d1, "external_work_J") - energy(d0, "external_work_J")) / (d1 - d0);
  };
  const double w1 = work_ratio(3e-3, 6e-3), w2 = work_ratio(6e-3, 9e-3), w3 = work_ratio(9e-3, 12e-3);
  const double w_all = work_ratio(3e-3, 12e-3);
  const double trailing = 0.5 * s_f;
  const double dissipation_ratio = (energy(12e-3, "cohesive_dissipation_J") - energy(3e-3, "cohesive_dissipation_J")) /
                                   (Jc * b * ((12e-3 - trailing) * (12e-3 - trailing) - (3e-3 - trailing) * (3e-3 - trailing)) /
                                    (2.0 * apex));
  const double rate_ratio = mean_work_rate(9e-3, 12e-3) / mean_work_rate(3e-3, 6e-3);
  const double length_ratio = (9e-3 + 12e-3) / (3e-3 + 6e-3); // mean l over 9–12 mm against 3–6 mm
  std::printf("wedge: W/(J_c ∫l) 3-6 mm %.3f, 6-9 mm %.3f, 9-12 mm %.3f, 3-12 mm %.3f; D against the trailing "
              "estimate %.3f; mean force 9-12 / 3-6 mm %.3f (l ratio %.3f)\n",
              w1, w2, w3, w_all, dissipation_ratio, rate_ratio, length_ratio);
  // Eq. 10 with l(d): the mean force over the cut is J_c l(d) (10%), and so is each 3 mm stretch
  // (20%, one and a half elements each), while l grows from 3 to 13 mm.
  EXPECT_NEAR(w_all, 1.0, 0.10);
  for (const double w : {w1, w2, w3}) EXPECT_NEAR(w, 1.0, 0.20);
  EXPECT_NEAR(rate_ratio / length_ratio, 1.0, 0.20);
  // The fracture work follows the faces the flanks open (5%).
  EXPECT_NEAR(dissipation_ratio, 1.0, 0.05);
  EXPECT_EQ(profile.rows.back().mode, InteractionMode::cutting);
  EXPECT_LT(std::abs(manifest.at("energy").at("balance_error").get<double>()), 0.02);
  std::filesystem::remove_all(run.dir);
}

} // namespace
} // namespace kerf
