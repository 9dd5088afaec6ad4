// The scene-level reference run (experiments/reference_run/reference_run.hpp) on clay_pull's scene with a
// coarse gmsh-free box of the same size (40 × 40 × 20 mm): the stylus is tied (paper 000 §2.1),
// the tool force balances the support reaction (global equilibrium: no other load acts on the
// body), and a run resumed from its checkpoint gives the uninterrupted profile exactly.

#include "experiments/reference_run/reference_run.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"
#include "experiments/study/study_runner.hpp"
#include "formats/trajectory/trajectory.hpp"
#include "meshes/box_tet_mesh.hpp"
#include "tests/experiments/run/grasp_on_box.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <algorithm>
#include <fstream>

namespace kerf {
namespace {

namespace fs = std::filesystem;

struct ClayPull {
  Scene scene = read_scene(fs::path(KERF_SCENES_DIR) / "clay_pull.toml");
  // clay_pull.toml: 40 × 40 × 20 mm block, x in [0, 40], y centred, base z = 0.
  TetMesh mesh = [this] {
    TetMesh m = box_tet_mesh(Eigen::Vector3d(0, -0.02, 0), Eigen::Vector3d(0.04, 0.02, 0.02), 4, 4, 2);
    test::add_grasp_groups_to_box(scene, m);
    return m;
  }();
  std::size_t samples = sample(scene.tools.front().trajectory).samples.size();
};

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("kerf_reference_run_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  return dir;
}

nlohmann::json read_json(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

TEST(ReferenceRun, ClayPullStylusIsTiedAndItsForceBalancesTheSupport) {
  const ClayPull c;
  const ReferenceProblem rp = reference_problem(c.scene, c.mesh);
  ASSERT_EQ(rp.tools.front().coupling.kind, ReferenceToolCoupling::Kind::tied);
  EXPECT_FALSE(rp.problem.tool.has_value());
  EXPECT_NEAR(rp.tools.front().coupling.contact_point.z(), 0.02, 1e-12); // the top face under the stylus

  ReferenceRunSettings s;
  s.sample_indices = reference_sample_indices(c.samples, 4);
  s.write_fields = true;
  const fs::path dir = scratch("tied");
  const ForceProfile profile = run_reference(c.scene, c.mesh, s, dir).profile;
  // The 4 requested samples and the end of the pull at t = 1.6 s (6 mm at 3.75 mm/s), a vertex of
  // the motion the load path passes through (reference/load_path.hpp).
  ASSERT_EQ(profile.rows.size(), 5u);
  EXPECT_DOUBLE_EQ(profile.rows[2].t, 1.6);
  EXPECT_EQ(profile.rows.front().mode, InteractionMode::no_contact); // not yet pulled: zero force
  const nlohmann::json m = read_json(dir / "manifest.json");
  EXPECT_TRUE(m.at("stopped").is_null());
  EXPECT_EQ(m.at("solver").at("tool_coupling"), "tied");
  for (std::size_t k = 1; k < profile.rows.size(); ++k) {
    const ProfileRow& r = profile.rows[k];
    EXPECT_EQ(r.mode, InteractionMode::deformation_1);
    EXPECT_LT(r.force.z(), 0.0); // the body holds the stylus back as it pulls up
    const auto& rec = m.at("samples").at(k);
    const Eigen::Vector3d support(rec.at("support_reaction_N")[0].get<double>(), rec.at("support_reaction_N")[1].get<double>(),
                                  rec.at("support_reaction_N")[2].get<double>());
    // Newton's third law over the whole body: tool force = −support reaction.
    EXPECT_LT((r.force + support).norm(), 1e-6 * r.force.norm()) << "sample " << k;
  }
  EXPECT_TRUE(fs::exists(dir / "fields.pvd"));
  EXPECT_TRUE(fs::exists(dir / "fields" / "step_0004.vtu"));
  EXPECT_EQ(read_profile_csv(dir / "profile.csv").rows.size(), 5u);
}

// A compliant grasp (Tool::grasp_stiffness k): the stylus holds the disc through an elastic layer,
// and its force is the layer's, −∫ k(r) (d − u) dA. It is the tie's in the limit k → ∞ (a penalty
// converges to its constraint at order 1/k: at k = 10⁴ E/h the layer's stretch is ~10⁻⁴ of the
// body's, so the forces agree to well within 1 %); a softer layer gives a smaller force; and the
// support alone balances the stylus (Newton's third law over the body: the layer is not a support).
// The mesh is the scene's reference mesh at h = 10 mm, whose grasp1 conforms to the disc: the
// layer, which ends at the disc's rim, and the tie then hold the same region.
TEST(ReferenceRun, ClayPullCompliantGraspTendsToTheTieAndBalancesTheSupport) {
  ClayPull tied, stiff, soft;
  const double E = tied.scene.material.youngs_modulus, h = 0.01;
  for (ClayPull* c : {&tied, &stiff, &soft}) {
    c->scene.geometry.element_size = h;
    c->mesh = scene_mesh(c->scene, MeshPurpose::reference);
  }
  tied.scene.tools.front().grasp_stiffness.reset(); // the scene's own grasp is compliant: tied rigidly without it
  stiff.scene.tools.front().grasp_stiffness = 1e4 * E / h;
  soft.scene.tools.front().grasp_stiffness = 1.9e9; // docs/scenes.md "Grasp": a 1 mm layer of the clay
  const ReferenceProblem rp = reference_problem(stiff.scene, stiff.mesh);
  EXPECT_EQ(rp.tools.front().coupling.kind, ReferenceToolCoupling::Kind::tied);
  EXPECT_EQ(rp.tools.front().coupling.foundation, 0);
  EXPECT_EQ(rp.problem.foundations.size(), 1u);
  ReferenceRunSettings s;
  s.sample_indices = reference_sample_indices(tied.samples, 3);
  s.write_fields = false;
  const ForceProfile f_tied = run_reference(tied.scene, tied.mesh, s, scratch("tie_rigid")).profile;
  const fs::path dir = scratch("tie_stiff");
  const ForceProfile f_stiff = run_reference(stiff.scene, stiff.mesh, s, dir).profile;
  const ForceProfile f_soft = run_reference(soft.scene, soft.mesh, s, scratch("tie_soft")).profile;
  ASSERT_EQ(f_stiff.rows.size(), 4u); // the 3 requested samples and the pull's end at t = 1.6 s
  const nlohmann::json m = read_json(dir / "manifest.json");
  EXPECT_EQ(m.at("solver").at("tools")[0].at("grasp_stiffness_N_per_m3").get<double>(), 1e4 * E / h);
  for (std::size_t k = 1; k < f_stiff.rows.size(); ++k) {
    SCOPED_TRACE(k);
    const Eigen::Vector3d& F = f_stiff.rows[k].force;
    EXPECT_LT(F.z(), 0.0); // the body holds the stylus back as it pulls up
    EXPECT_LT((F - f_tied.rows[k].force).norm(), 1e-2 * f_tied.rows[k].force.norm());
    EXPECT_LT(f_soft.rows[k].force.norm(), F.norm());
    const auto& support_json = m.at("samples").at(k).at("support_reaction_N");
    const Eigen::Vector3d support(support_json[0].get<double>(), support_json[1].get<double>(), support_json[2].get<double>());
    EXPECT_LT((F + support).norm(), 1e-6 * F.norm());
  }
}

// clay_tear (paper 000 §2.2): two styluses grasp the top at x = 15 and 45 mm and pull it apart,
// 10 mm each along ∓x; the block slides on its table. Both styluses are tied, each with its own
// tie, and the reference reports both forces. Checks: global equilibrium (the two stylus forces
// and the table's reaction sum to zero, Newton's third law over the body), each stylus held back
// towards the middle, and the mirror symmetry of the problem about x = 30 mm (the 6-tetrahedron
// box split is not mirror symmetric, so the two forces agree to the discretisation, not to
// round-off: 5% on this coarse box).
TEST(ReferenceRun, ClayTearTwoTiedStylusesPullTheBlockApart) {
  const Scene scene = read_scene(fs::path(KERF_SCENES_DIR) / "clay_tear.toml");
  // clay_tear.toml: 60 × 20 × 20 mm block, x in [0, 60], y centred, base z = 0; 5 mm cells put a
  // node under each stylus.
  TetMesh mesh = box_tet_mesh(Eigen::Vector3d(0, -0.01, 0), Eigen::Vector3d(0.06, 0.01, 0.02), 12, 4, 2);
  test::add_grasp_groups_to_box(scene, mesh);
  const ReferenceProblem rp = reference_problem(scene, mesh);
  ASSERT_EQ(rp.tools.size(), 2u);
  for (const ReferenceTool& t : rp.tools) EXPECT_EQ(t.coupling.kind, ReferenceToolCoupling::Kind::tied) << t.name;
  EXPECT_FALSE(rp.problem.tool.has_value());

  ReferenceRunSettings s;
  s.sample_indices = reference_sample_indices(sample(scene.tools.front().trajectory).samples.size(), 4);
  s.write_fields = false;
  const fs::path dir = scratch("tear");
  const ForceProfile profile = run_reference(scene, mesh, s, dir).profile;
  ASSERT_EQ(profile.rows.size(), 8u); // two tools per sample
  const nlohmann::json m = read_json(dir / "manifest.json");
  EXPECT_TRUE(m.at("stopped").is_null());
  ASSERT_EQ(m.at("solver").at("tools").size(), 2u);
  for (std::size_t k = 1; k < 4; ++k) {
    const ProfileRow& left = profile.rows[2 * k];
    const ProfileRow& right = profile.rows[2 * k + 1];
    ASSERT_EQ(left.tool, "left");
    ASSERT_EQ(right.tool, "right");
    EXPECT_EQ(left.t, right.t);
    EXPECT_GT(left.force.x(), 0.0);  // pulled to −x, held back towards +x
    EXPECT_LT(right.force.x(), 0.0);
    EXPECT_NEAR(left.force.x(), -right.force.x(), 0.05 * left.force.x()) << "sample " << k;
    const auto& rec = m.at("samples").at(k);
    const Eigen::Vector3d support(rec.at("support_reaction_N")[0].get<double>(), rec.at("support_reaction_N")[1].get<double>(),
                                  rec.at("support_reaction_N")[2].get<double>());
    EXPECT_LT((left.force + right.force + support).norm(), 1e-6 * left.force.norm()) << "sample " << k;
  }
}

TEST(ReferenceRun, ResumeFromACheckpointGivesTheUninterruptedProfile) {
  const ClayPull c;
  ReferenceRunSettings s;
  s.sample_indices = reference_sample_indices(c.samples, 5);
  s.write_fields = false;
  s.checkpoint_every = 4;
  const ForceProfile whole = run_reference(c.scene, c.mesh, s, scratch("whole")).profile;

  // The interrupted run: its last checkpoint is after sample 4 of 6 (the 5 requested and the pull's
  // end at t = 1.6 s); its final files are removed as if it had been killed before writing them.
  const fs::path dir = scratch("interrupted");
  (void)run_reference(c.scene, c.mesh, s, dir);
  fs::remove(dir / "profile.csv");
  fs::remove(dir / "manifest.json");
  s.resume = true;
  const ForceProfile resumed = run_reference(c.scene, c.mesh, s, dir).profile;
  EXPECT_EQ(read_json(dir / "manifest.json").at("resumed_after_sample"), 4);

  ASSERT_EQ(resumed.rows.size(), whole.rows.size());
  for (std::size_t k = 0; k < whole.rows.size(); ++k) {
    EXPECT_EQ(resumed.rows[k].t, whole.rows[k].t);
    EXPECT_EQ(resumed.rows[k].position, whole.rows[k].position);
    EXPECT_EQ(resumed.rows[k].force, whole.rows[k].force) << "row " << k; // bit for bit
    EXPECT_EQ(resumed.rows[k].mode, whole.rows[k].mode);
  }

  // A checkpoint of other settings is refused.
  s.degree = 2;
  EXPECT_THROW(run_reference(c.scene, c.mesh, s, dir), std::runtime_error);
}

// The dynamic step's checkpoint carries the velocity and acceleration: a run resumed from it gives
// the uninterrupted run's forces and kinetic energy bit for bit (without them the first resumed
// step would start from rest and differ), and a quasi-static run's checkpoint is refused by a
// dynamic run, naming the time integration; likewise a damped run's by an undamped one.
// Adaptive sampling (ReferenceRunSettings::adaptive_force_change): on clay_pull's box, 4 requested
// samples. Checks: every requested sample is solved; samples are inserted where the curve bends
// (the stylus starts pulling at t = 0, so the first sample after the start lies within the minimum
// travel of it); and a second method: the quasi-static hyperelastic problem is path-independent, so
// a plain run on the adaptive run's final sample list gives the same forces to the solver's
// tolerance. A resume from the adaptive run's checkpoint (which holds the inserted samples)
// reproduces it bit for bit.
TEST(ReferenceRun, AdaptiveSamplingInsertsSamplesWhereTheCurveBendsAndMatchesAPlainRun) {
  const ClayPull c;
  ReferenceRunSettings s;
  s.sample_indices = reference_sample_indices(c.samples, 4);
  s.write_fields = false;
  s.checkpoint_every = 4;
  s.adaptive_force_change = 0.02;
  s.adaptive_min_travel = 0.05e-3;
  const fs::path dir = scratch("adaptive");
  const ForceProfile adaptive = run_reference(c.scene, c.mesh, s, dir).profile;
  const nlohmann::json m = read_json(dir / "manifest.json");
  ASSERT_TRUE(m.at("stopped").is_null());
  std::vector<std::size_t> solved;
  for (const auto& rec : m.at("samples")) solved.push_back(rec.at("index").get<std::size_t>());
  ASSERT_EQ(solved.size(), adaptive.rows.size());
  EXPECT_GT(solved.size(), s.sample_indices.size());
  EXPECT_TRUE(std::includes(solved.begin(), solved.end(), s.sample_indices.begin(), s.sample_indices.end()));
  EXPECT_TRUE(std::is_sorted(solved.begin(), solved.end()));
  // The pull starts at t = 0: the first sample after it is within the minimum travel (0.05 mm).
  EXPECT_LE((adaptive.rows[1].position - adaptive.rows[0].position).norm(), s.adaptive_min_travel + 1e-12);
  EXPECT_GT(adaptive.rows[1].force.norm(), 0.0);
  // The end of the pull (t = 1.6 s, clay_pull.toml: 6 mm at 3.75 mm/s) is a kink of the force: it is
  // a vertex of the motion, solved itself, where the 4 requested samples are 0.87 s apart.
  EXPECT_TRUE(std::any_of(adaptive.rows.begin(), adaptive.rows.end(), [](const ProfileRow& r) { return r.t == 1.6; }));

  ReferenceRunSettings plain = s;
  plain.adaptive_force_change = 0.0;
  plain.sample_indices = solved;
  const ForceProfile reference = run_reference(c.scene, c.mesh, plain, scratch("plain")).profile;
  ASSERT_EQ(reference.rows.size(), adaptive.rows.size());
  double peak = 0.0;
  for (const ProfileRow& r : reference.rows) peak = std::max(peak, r.force.norm());
  for (std::size_t k = 0; k < reference.rows.size(); ++k)
    EXPECT_LE((adaptive.rows[k].force - reference.rows[k].force).norm(), 1e-7 * peak) << "sample " << k;

  // Resumed from its checkpoint (written after every 4 solved samples), the adaptive run continues
  // with the samples it had inserted and ends with the same profile.
  fs::remove(dir / "profile.csv");
  fs::remove(dir / "manifest.json");
  s.resume = true;
  const ForceProfile resumed = run_reference(c.scene, c.mesh, s, dir).profile;
  ASSERT_EQ(resumed.rows.size(), adaptive.rows.size());
  for (std::size_t k = 0; k < resumed.rows.size(); ++k) EXPECT_EQ(resumed.rows[k].force, adaptive.rows[k].force) << k;
}

TEST(ReferenceRun, DynamicResumeCarriesVelocityAndAcceleration) {
  const ClayPull c;
  ReferenceRunSettings s;
  s.sample_indices = reference_sample_indices(c.samples, 5);
  s.write_fields = false;
  s.checkpoint_every = 4; // after sample 4 of 6 (the 5 requested and the pull's end)
  s.dynamic = true;
  const fs::path whole_dir = scratch("dynamic_whole");
  const ForceProfile whole = run_reference(c.scene, c.mesh, s, whole_dir).profile;
  const nlohmann::json whole_manifest = read_json(whole_dir / "manifest.json");
  EXPECT_GT(whole_manifest.at("energy").at("kinetic_energy_J").get<double>(), 0.0);

  const fs::path dir = scratch("dynamic_interrupted");
  (void)run_reference(c.scene, c.mesh, s, dir);
  fs::remove(dir / "profile.csv");
  fs::remove(dir / "manifest.json");
  s.resume = true;
  const ForceProfile resumed = run_reference(c.scene, c.mesh, s, dir).profile;
  const nlohmann::json m = read_json(dir / "manifest.json");
  EXPECT_EQ(m.at("resumed_after_sample"), 4);
  ASSERT_EQ(resumed.rows.size(), whole.rows.size());
  for (std::size_t k = 0; k < whole.rows.size(); ++k)
    EXPECT_EQ(resumed.rows[k].force, whole.rows[k].force) << "row " << k; // bit for bit
  EXPECT_EQ(m.at("energy").at("kinetic_energy_J"), whole_manifest.at("energy").at("kinetic_energy_J"));

  // A quasi-static run's checkpoint, resumed by a dynamic run.
  ReferenceRunSettings quasi_static = s;
  quasi_static.dynamic = false;
  quasi_static.resume = false;
  const fs::path other = scratch("dynamic_refused");
  (void)run_reference(c.scene, c.mesh, quasi_static, other);
  std::string message;
  try {
    (void)run_reference(c.scene, c.mesh, s, other);
  } catch (const std::runtime_error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("quasi-static run and this run is dynamic"), std::string::npos) << message;

  // clay_pull has damping (10 Pa s): the dynamic run above is damped, its checkpoint carries the
  // damping dissipation (in the resumed manifest bit for bit), and an undamped run refuses it.
  EXPECT_TRUE(whole_manifest.at("model").at("parameters").at("kelvin_voigt_damping").get<bool>());
  EXPECT_GT(whole_manifest.at("energy").at("damping_dissipation_J").get<double>(), 0.0);
  EXPECT_EQ(m.at("energy").at("damping_dissipation_J"), whole_manifest.at("energy").at("damping_dissipation_J"));
  ReferenceRunSettings undamped = s;
  undamped.damping = false;
  message.clear();
  try {
    (void)run_reference(c.scene, c.mesh, undamped, dir);
  } catch (const std::runtime_error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("with the scene's Kelvin-Voigt damping and this run is undamped"), std::string::npos) << message;
}

// Fault injection (docs/reliability.md): a NaN in the assembled residual of a Newton
// iteration (reference::SolverSettings::residual_fault), as an overflowing material or contact term
// would make it.
//  - Once, in the first attempt at sample 2: the solve must fail rather than "converge" on a NaN
//    norm, the load path cuts the increment back and the run goes on to the clean run's equilibria
//    (hyperelastic equilibrium at a given load does not depend on the increments that reached it,
//    so the forces agree to the Newton tolerance, 1e-9 of the force scale).
//  - In every iteration past sample 2: the path stops after its cut-backs; the manifest names the
//    sample and the non-finite residual; the profile holds the converged samples 0-2; the last
//    converged state is in checkpoint.bin, and --resume without the fault reproduces the clean
//    profile bit for bit (the same state and load as the clean run had after sample 2).
TEST(ReferenceRun, NaNInTheResidualCutsBackOrStopsWithTheLastStateSaved) {
  const ClayPull c;
  ReferenceRunSettings s;
  s.sample_indices = reference_sample_indices(c.samples, 5);
  s.write_fields = false;
  s.checkpoint_every = 10; // no regular checkpoint within 5 samples: only the stop writes one
  const ForceProfile clean = run_reference(c.scene, c.mesh, s, scratch("nan_clean")).profile;
  ASSERT_EQ(clean.rows.size(), 6u); // the 5 requested samples and the pull's end at t = 1.6 s
  const double t1 = clean.rows[1].t, t2 = clean.rows[2].t;

  bool poisoned = false;
  s.residual_fault = [&](const reference::LoadState& load, int) {
    if (load.time <= t1 || poisoned) return false;
    poisoned = true;
    return true;
  };
  const fs::path once_dir = scratch("nan_once");
  const ForceProfile once = run_reference(c.scene, c.mesh, s, once_dir).profile;
  EXPECT_TRUE(poisoned);
  const nlohmann::json m_once = read_json(once_dir / "manifest.json");
  EXPECT_TRUE(m_once.at("stopped").is_null());
  EXPECT_GE(m_once.at("samples").at(2).at("cutbacks").get<int>(), 1);
  ASSERT_EQ(once.rows.size(), clean.rows.size());
  for (std::size_t k = 0; k < clean.rows.size(); ++k) {
    ASSERT_TRUE(once.rows[k].force.allFinite()) << "row " << k;
    EXPECT_LE((once.rows[k].force - clean.rows[k].force).norm(), 1e-6 * clean.rows[k].force.norm() + 1e-12)
        << "row " << k;
  }

  s.residual_fault = [&](const reference::LoadState& load, int) { return load.time > t2; };
  const fs::path dir = scratch("nan_always");
  const ReferenceResult stopped_run = run_reference(c.scene, c.mesh, s, dir);
  const ForceProfile& stopped = stopped_run.profile;
  ASSERT_EQ(stopped.rows.size(), 3u);
  EXPECT_FALSE(stopped_run.complete()); // the caller is told (kerf reference exits with status 4)
  const nlohmann::json m = read_json(dir / "manifest.json");
  ASSERT_TRUE(m.at("stopped").is_string());
  EXPECT_TRUE(m.at("partial").get<bool>());
  EXPECT_EQ(m.at("stopped").get<std::string>(), stopped_run.stopped);
  const std::string why = m.at("stopped").get<std::string>();
  EXPECT_NE(why.find("non-finite residual"), std::string::npos) << why;
  EXPECT_NE(why.find("last converged state"), std::string::npos) << why;
  EXPECT_EQ(read_profile_csv(dir / "profile.csv").rows.size(), 3u);
  ASSERT_TRUE(fs::exists(dir / "checkpoint.bin"));

  s.residual_fault = nullptr;
  s.resume = true;
  const ForceProfile resumed = run_reference(c.scene, c.mesh, s, dir).profile;
  EXPECT_EQ(read_json(dir / "manifest.json").at("resumed_after_sample"), 3);
  ASSERT_EQ(resumed.rows.size(), clean.rows.size());
  for (std::size_t k = 0; k < clean.rows.size(); ++k)
    EXPECT_EQ(resumed.rows[k].force, clean.rows[k].force) << "row " << k; // bit for bit
}

} // namespace
} // namespace kerf
