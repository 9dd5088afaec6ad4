// clay_tear with fracture on and the dynamic step (Reference II; SolverSettings::dynamic): two tied
// styluses pull the clay block apart at 5 mm/s each; the cohesive mid-plane (20 × 20 mm,
// J_c = 50 J/m², σ_c = 50 kPa) tears with no viscous regularisation (τ = 0): the energy the block
// releases when the tear runs away goes into the kinetic energy of the halves instead of a
// viscous term, and the ledger keeps it. The scene's Kelvin–Voigt damping (10 Pa s) is on, and the
// load path's interface energy control (ReferenceRunSettings::interface_error_relative, 0.5% of each
// step's cohesive dissipation + 10⁻⁵ J_c A) re-solves the steps in which points cross the law's
// kinks in halves.
// Time steps: the samples every 28 ms through the slow pull (quasi-static in all but name: the
// kinetic energy is below 10⁻⁵ of the work), every 1 ms (the trajectory's rate) from t = 0.91 s
// (on the scene's mesh the quasi-static path stops at 0.93 s as the tear starts: `kerf reference
// clay_tear --mesh scene --fracture on --samples 101 --until 1.5 --adaptive 0 --no-fields`) to
// 0.965 s, past separation.
// Expected values, independent of the solver:
//   separation     the failed area reaches the whole plane A = 20 mm × 20 mm and the cohesive
//                  dissipation is J_c A = 20 mJ (the area under the bilinear law, per area);
//   energy         W = U + K + interface energy + cohesive dissipation + damping dissipation at
//                  every sample, to 1%, without booking the time integration's error at
//                  the law's kinks: the trapezoidal rule's energy identity (Hughes, The Finite
//                  Element Method, §9.1) for the hands' work from their reactions;
//   kinks          the time integration's error at the law's kinks (measured point by point and
//                  reported) below 1% of J_c A: the interface energy control bounds its sum by
//                  0.5% of the dissipation J_c A plus 10⁻⁵ J_c A per accepted step (reference/
//                  load_path.hpp), 0.5% + 0.14% for the ~140 steps of this run;
//   kinetic        once separated the halves carry the energy they released as kinetic energy
//                  (in the quasi-static run, 38% of the work leaves the ledger there): on average over
//                  the samples after separation more than 20% of W;
//   peak           the hands' peak pull lies within 3% of the last quasi-static equilibrium
//                  before the tear ran away, 12.41 N (the unregularised quasi-static path's last
//                  converged sample, t = 0.915 s, before it stopped at t = 0.93 s: the command
//                  above, a second method): inertia barely changes the slow pull;
//   equilibrium    until the tear the hands' pulls are equal and opposite (the base takes no x).

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

/// What one dynamic tear run gave.
struct TearRun {
  nlohmann::json manifest;
  double plane = 0.0, toughness = 0.0;
  double peak = 0.0, peak_time = 0.0, separation_time = -1.0, worst_balance = 0.0, worst_time = 0.0;
};

/// clay_tear, fracture on, dynamic, τ = 0: samples every 28 ms until `from` [s], then every
/// `window_step` seconds from `from` to `until`; `rate` [Hz] resamples both trajectories (the
/// scene's is 1 kHz).
TearRun run_tear(double rate, double from, double window_step, double until, bool print_rows,
               double interface_error_relative = ReferenceRunSettings{}.interface_error_relative, bool damping = true) {
  namespace fs = std::filesystem;
  Scene scene = read_scene(fs::path(KERF_SOURCE_DIR) / "experiments" / "scenes" / "clay_tear.toml");
  for (Tool& tool : scene.tools) tool.trajectory.rate = rate;
  const TetMesh mesh = scene_mesh(scene);
  ReferenceRunSettings settings;
  settings.fracture = ReferenceFracture::on;
  settings.dynamic = true;
  settings.write_fields = false;
  settings.checkpoint_every = 100000;
  settings.interface_error_relative = interface_error_relative;
  if (interface_error_relative == 0.0) settings.interface_error_floor = 0.0; // the control off
  settings.damping = damping;
  const auto at = [&](double t) { return static_cast<std::size_t>(std::llround(t * rate)); };
  // The hands start from rest at 5 mm/s: the first steps short (2, 2, 4, 8 ms; a first step of
  // 28 ms from rest needs three cut-backs), then every 28 ms.
  for (const double t : {0.0, 0.002, 0.004, 0.008, 0.016}) settings.sample_indices.push_back(at(t));
  for (std::size_t k = at(0.028); k < at(from); k += at(0.028)) settings.sample_indices.push_back(k);
  for (std::size_t k = at(from); k <= at(until); k += at(window_step)) settings.sample_indices.push_back(k);
  const fs::path dir = fs::temp_directory_path() / "kerf_test_clay_tear_dynamic";
  fs::remove_all(dir);
  (void)run_reference(scene, mesh, settings, dir);

  TearRun out;
  std::ifstream(dir / "manifest.json") >> out.manifest;
  fs::remove_all(dir);
  out.plane = scene.geometry.parameters.at("width") * scene.geometry.parameters.at("depth"); // 400 mm²
  out.toughness = scene.material.fracture_toughness;
  for (const auto& s : out.manifest.at("samples")) {
    const double t = s.at("t_s").get<double>();
    const double left = s.at("tool_forces_N").at("left")[0].get<double>();
    const double right = s.at("tool_forces_N").at("right")[0].get<double>();
    const auto& e = s.at("energy");
    const double failed = e.at("failed_area_m2").get<double>();
    // Equal and opposite pulls until the tear, once the start from rest has rung out (the two
    // halves' meshes differ, so their start-up vibrations do: 10% at t = 2 ms).
    if (failed == 0.0 && t >= 0.1) {
      EXPECT_NEAR(left, -right, 1e-2 * std::abs(left)) << "t = " << t;
    }
    if (std::abs(left) > out.peak && out.separation_time < 0.0) {
      out.peak = std::abs(left);
      out.peak_time = t;
    }
    const double balance = std::abs(e.at("balance_error").get<double>());
    if (balance > out.worst_balance) {
      out.worst_balance = balance;
      out.worst_time = t;
    }
    if (out.separation_time < 0.0 && failed >= out.plane * (1.0 - 1e-9)) out.separation_time = t;
    if (print_rows)
      std::printf("t %.4f s  left %8.3f N  right %8.3f N  failed %6.1f mm2  W %7.3f  U %7.3f  K %7.3f  cohesive %6.3f  "
                  "kinks %6.3f mJ  damping %6.3f mJ  balance %+.3f%%  Newton %d  cut-backs %d (rejected %d)\n",
                  t, left, right, failed * 1e6, e.at("external_work_J").get<double>() * 1e3,
                  e.at("stored_elastic_energy_J").get<double>() * 1e3, e.at("kinetic_energy_J").get<double>() * 1e3,
                  e.at("cohesive_dissipation_J").get<double>() * 1e3, e.at("cohesive_time_integration_J").get<double>() * 1e3,
                  e.at("damping_dissipation_J").get<double>() * 1e3, 100.0 * e.at("balance_error").get<double>(),
                  s.at("newton_iterations").get<int>(), s.at("cutbacks").get<int>(), s.at("interface_rejections").get<int>());
  }
  const auto& last = out.manifest.at("samples").back().at("energy");
  int rejections = 0;
  for (const auto& s : out.manifest.at("samples")) rejections += s.at("interface_rejections").get<int>();
  std::printf("clay_tear dynamic (control %.4g, damping %s): %d steps rejected by the interface energy control, "
              "damping dissipation %.3f mJ\n",
              interface_error_relative, damping ? "on" : "off", rejections, last.at("damping_dissipation_J").get<double>() * 1e3);
  std::printf("clay_tear dynamic (window step %.2f ms from t = %.3f s): peak %.3f N at t = %.4f s, separated at t = %.4f s, worst balance "
              "%.3f%% at t = %.4f s, time-integration error at the kinks %.3f mJ (%.1f%% of J_c A), Newton %d, solve %.1f s, "
              "kinetic at the end %.2f mJ of W = %.2f mJ\n",
              window_step * 1e3, from, out.peak, out.peak_time, out.separation_time, 100.0 * out.worst_balance, out.worst_time,
              last.at("cohesive_time_integration_J").get<double>() * 1e3,
              100.0 * last.at("cohesive_time_integration_J").get<double>() / (out.toughness * out.plane),
              out.manifest.at("newton_iterations_total").get<int>(),
              out.manifest.at("timings").at("solve_total_s").get<double>(), last.at("kinetic_energy_J").get<double>() * 1e3,
              last.at("external_work_J").get<double>() * 1e3);
  return out;
}

TEST(ClayTearDynamic, TearToSeparationKeepsTheEnergyBalance) {
  const TearRun r = run_tear(1000.0, 0.91, 0.001, 0.965, true);
  ASSERT_TRUE(r.manifest.at("stopped").is_null()) << r.manifest.at("stopped");
  const auto& last = r.manifest.at("samples").back().at("energy");
  ASSERT_GE(r.separation_time, 0.0) << "the plane never failed completely";
  EXPECT_NEAR(last.at("cohesive_dissipation_J").get<double>(), r.toughness * r.plane, 0.02 * r.toughness * r.plane);
  EXPECT_EQ(last.at("viscous_dissipation_J").get<double>(), 0.0);
  EXPECT_GT(last.at("damping_dissipation_J").get<double>(), 0.0);
  EXPECT_LT(r.worst_balance, 0.01); // the kinks' error is not booked (EnergyBookkeeping::balance_error)
  // The halves' kinetic energy after separation, averaged over the samples (K and U exchange
  // while they vibrate: K swings between 3 and 46 mJ of W = 69 mJ, docs/cohesive-fracture.md).
  double kinetic = 0.0;
  int after = 0;
  for (const auto& s : r.manifest.at("samples"))
    if (s.at("t_s").get<double>() > r.separation_time) {
      kinetic += s.at("energy").at("kinetic_energy_J").get<double>();
      ++after;
    }
  ASSERT_GT(after, 20);
  EXPECT_GT(kinetic / after, 0.2 * last.at("external_work_J").get<double>());
  // The time integration's error at the law's kinks: below 1% of J_c A under the interface energy
  // control (the bound in the file comment; without the control it is 14.3% of J_c A on these
  // samples, docs/cohesive-fracture.md).
  const double kinks = last.at("cohesive_time_integration_J").get<double>();
  EXPECT_LT(std::abs(kinks), 0.01 * r.toughness * r.plane);
  EXPECT_NEAR(r.peak, 12.41, 0.03 * 12.41);
}

// The control's cost (docs/cohesive-fracture.md; run by hand: --gtest_also_run_disabled_tests
// --gtest_filter='*ControlCost*'): the ctest's samples with the interface energy control off, and
// on without the damping.
TEST(ClayTearDynamic, DISABLED_ControlCost) {
  (void)run_tear(1000.0, 0.91, 0.001, 0.965, false, 0.0, true);
  (void)run_tear(1000.0, 0.91, 0.001, 0.965, false, ReferenceRunSettings{}.interface_error_relative, false);
}

// The damped halves (docs/cohesive-fracture.md; run by hand: --gtest_filter='*DampedHold*' with
// --gtest_also_run_disabled_tests): the tear and 245 ms after it, 1 ms steps.
TEST(ClayTearDynamic, DISABLED_DampedHold) { (void)run_tear(1000.0, 0.91, 0.001, 1.2, true); }

} // namespace
} // namespace kerf
