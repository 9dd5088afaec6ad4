// The reference cache key (experiments/study/reference_cache.hpp): every input that changes the
// reference's numbers changes the key, and nothing else does; the solver's version among them.

#include "experiments/study/reference_cache.hpp"

#include "formats/scene/scene_reader.hpp"
#include "experiments/records/content_hash.hpp"
#include "experiments/study/stability_sweep.hpp"
#include "experiments/study/study_runner.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <set>

#include <unistd.h>

using namespace kerf;
namespace fs = std::filesystem;

namespace {

Scene clay_pull() { return read_scene(fs::path(KERF_SCENES_DIR) / "clay_pull.toml"); }

ReferenceRunSettings settings_of(const Scene& scene, const StudyReferenceSpec& spec, int level) {
  std::size_t n = 0;
  for (const auto& t : sample_scene_trajectories(scene)) n = std::max(n, t.samples.size());
  return study_reference_settings(spec, scene, level, reference_sample_indices(n, spec.samples));
}

} // namespace

TEST(ReferenceCache, StudySettingsCarryTheSpecAndNeverDistribute) {
  StudyReferenceSpec spec;
  spec.degree = 2;
  spec.linear_solver = reference::LinearSolverChoice::iterative;
  spec.fracture = ReferenceFracture::automatic;
  const ReferenceRunSettings s = study_reference_settings(spec, clay_pull(), 3, {0, 5, 9});
  EXPECT_EQ(s.degree, 2);
  // A scene's own degree ([reference] scene_degree) replaces the study's for that scene only.
  spec.scene_degree["clay_pull"] = 1;
  EXPECT_EQ(study_reference_settings(spec, clay_pull(), 3, {0}).degree, 1);
  const Scene potato = read_scene(fs::path(KERF_SCENES_DIR) / "potato_rect_cut.toml");
  EXPECT_EQ(study_reference_settings(spec, potato, 3, {0}).degree, 2);
  // Without a study-wide degree each scene keeps its own ([geometry] element_degree): clay_pull's
  // file asks for quadratic tetrahedra, potato_rect_cut's gives none (linear).
  StudyReferenceSpec own;
  EXPECT_EQ(clay_pull().geometry.element_degree, 2);
  EXPECT_EQ(study_reference_settings(own, clay_pull(), 0, {0}).degree, 2);
  EXPECT_EQ(study_reference_settings(own, potato, 0, {0}).degree, 1);
  EXPECT_EQ(s.refinements, 0); // level 3 is the geometry meshed anew (study_reference_scene), not refined
  EXPECT_EQ(s.sample_indices, (std::vector<std::size_t>{0, 5, 9}));
  EXPECT_EQ(s.linear_solver, reference::LinearSolverChoice::iterative);
  EXPECT_EQ(s.fracture, ReferenceFracture::automatic);
  EXPECT_FALSE(s.distribute); // one process per solve: the study spreads whole solves over ranks
  EXPECT_FALSE(s.write_fields);
}

TEST(ReferenceCache, ALevelBelowZeroIsTheSceneMeshedCoarserAndMissesTheFinerLevelsEntry) {
  // Level k: the geometry meshed anew at element size h 2^-k (study_spec.hpp): clay_pull's 2.5 mm
  // (its file) becomes 5 mm at level -1.
  const Scene scene = clay_pull();
  const double h = scene.geometry.element_size;
  EXPECT_DOUBLE_EQ(h, 2.5e-3);
  EXPECT_DOUBLE_EQ(study_reference_scene(scene, -1).geometry.element_size, 5e-3);
  EXPECT_DOUBLE_EQ(study_reference_scene(scene, -3).geometry.element_size, 20e-3);
  EXPECT_DOUBLE_EQ(study_reference_scene(scene, 2).geometry.element_size, h / 4); // meshed anew, graded alike
  EXPECT_DOUBLE_EQ(study_reference_element_size(scene, -1), 5e-3);
  EXPECT_DOUBLE_EQ(study_reference_element_size(scene, 2), 0.625e-3);
  EXPECT_THROW(study_reference_scene(scene, -4), std::invalid_argument);
  StudyReferenceSpec spec;
  spec.samples = 6;
  EXPECT_EQ(settings_of(scene, spec, -1).refinements, 0);
  EXPECT_EQ(settings_of(scene, spec, 2).refinements, 0);
  // A scene whose mesh is a .msh file has no geometry to mesh anew: level k >= 0 refines that mesh
  // k times, and a coarser level is refused.
  Scene from_file = scene;
  from_file.geometry.kind = SceneGeometry::Kind::msh;
  from_file.geometry.source = "/data/body.msh";
  EXPECT_DOUBLE_EQ(study_reference_scene(from_file, 2).geometry.element_size, h);
  EXPECT_EQ(settings_of(from_file, spec, 2).refinements, 2);
  EXPECT_THROW(study_reference_scene(from_file, -1), std::invalid_argument);
  // The coarse level's entry is not the scene's own mesh's: the element size is in the key.
  const Scene coarse = study_reference_scene(scene, -1);
  const ReferenceCacheKey k_coarse = reference_cache_key(coarse, settings_of(coarse, spec, -1));
  const ReferenceCacheKey k_own = reference_cache_key(scene, settings_of(scene, spec, 0));
  EXPECT_NE(k_coarse.directory, k_own.directory);
  EXPECT_NE(k_coarse.text.find("element_size = 0.0050000000000000001"), std::string::npos) << k_coarse.text;
}

TEST(ReferenceCache, UnchangedInputsGiveTheSameKey) {
  const Scene a = clay_pull(), b = clay_pull(); // read twice: nothing but the inputs may enter
  StudyReferenceSpec spec;
  spec.samples = 6;
  const ReferenceCacheKey ka = reference_cache_key(a, settings_of(a, spec, 0));
  const ReferenceCacheKey kb = reference_cache_key(b, settings_of(b, spec, 0));
  EXPECT_EQ(ka.text, kb.text);
  EXPECT_EQ(ka.directory, kb.directory);
  // The readable prefix: scene hash, degree, level, samples; then the hash of the whole key.
  EXPECT_EQ(ka.directory.substr(0, 16), file_sha256(a.file).substr(0, 16));
  EXPECT_NE(ka.directory.find("-p2-L0-n6-"), std::string::npos) << ka.directory; // clay_pull's own degree, 2
  // Write-only settings (field files, checkpoints) do not change the reference's numbers.
  ReferenceRunSettings s = settings_of(a, spec, 0);
  s.write_fields = true;
  s.checkpoint_every = 1;
  EXPECT_EQ(reference_cache_key(a, s).directory, ka.directory);
}

TEST(ReferenceCache, EveryNumberChangingInputMissesTheCache) {
  const Scene nominal = clay_pull();
  StudyReferenceSpec spec;
  spec.samples = 6;
  const std::string base = reference_cache_key(nominal, settings_of(nominal, spec, 0)).directory;
  // Each change below changes what the reference computes; each must give a key of its own.
  const std::pair<std::string, std::function<ReferenceCacheKey()>> changes[] = {
      {"degree", [&] { StudyReferenceSpec s = spec; s.degree = 1; return reference_cache_key(nominal, settings_of(nominal, s, 0)); }},
      {"level", [&] {
         const Scene finer = study_reference_scene(nominal, 1);
         return reference_cache_key(finer, settings_of(finer, spec, 1));
       }},
      {"samples", [&] { StudyReferenceSpec s = spec; s.samples = 7; return reference_cache_key(nominal, settings_of(nominal, s, 0)); }},
      {"linear solver", [&] {
         StudyReferenceSpec s = spec;
         s.linear_solver = reference::LinearSolverChoice::iterative;
         return reference_cache_key(nominal, settings_of(nominal, s, 0));
       }},
      {"direct solver", [&] {
         StudyReferenceSpec s = spec;
         s.linear_solver = reference::LinearSolverChoice::direct;
         return reference_cache_key(nominal, settings_of(nominal, s, 0));
       }},
      {"fracture", [&] {
         StudyReferenceSpec s = spec;
         s.fracture = ReferenceFracture::on;
         return reference_cache_key(nominal, settings_of(nominal, s, 0));
       }},
      {"E in memory", [&] { const Scene s = scaled_scene(nominal, "stiffness", 2.0); return reference_cache_key(s, settings_of(s, spec, 0)); }},
      {"nu in memory", [&] { const Scene s = scaled_scene(nominal, "poisson", 0.49); return reference_cache_key(s, settings_of(s, spec, 0)); }},
      // (x 0.8: x 0.5 is level 1, the same mesh, rightly the same key)
      {"element size", [&] { const Scene s = scaled_scene(nominal, "element_size", 0.8); return reference_cache_key(s, settings_of(s, spec, 0)); }},
      // A faster trajectory: the same file, the same sample count, other times and positions.
      {"trajectory", [&] { const Scene s = scaled_scene(nominal, "speed", 2.0); return reference_cache_key(s, settings_of(s, spec, 0)); }},
  };
  std::set<std::string> keys{base};
  for (const auto& [what, key] : changes) {
    const ReferenceCacheKey k = key();
    EXPECT_NE(k.directory, base) << what << " did not change the key:\n" << k.text;
    keys.insert(k.directory);
  }
  EXPECT_EQ(keys.size(), std::size(changes) + 1); // and no two changes collide
}

TEST(ReferenceCache, TheKeyNamesTheSolverSettings) {
  // key.txt is read by people deciding whether a cache entry is the one they want.
  const Scene scene = clay_pull();
  StudyReferenceSpec spec;
  spec.linear_solver = reference::LinearSolverChoice::direct;
  // Level 1 is clay_pull's geometry meshed anew at half its element size, not its mesh refined.
  const Scene level1 = study_reference_scene(scene, 1);
  EXPECT_DOUBLE_EQ(level1.geometry.element_size, 0.5 * scene.geometry.element_size);
  const std::string text = reference_cache_key(level1, settings_of(level1, spec, 1)).text;
  for (const char* line : {"degree = 2\n", "refinements = 0\n", "linear_solver = direct\n", "fracture = off\n", "processes = 1\n",
                           "newton_relative_tolerance = ", "iterative_tolerance = ", "contact_penalty = automatic\n",
                           "max_cutbacks = ", "max_newton_iterations = ", "trajectory_sha256 = "})
    EXPECT_NE(text.find(line), std::string::npos) << line << " not in\n" << text;
}

TEST(ReferenceCache, TheSolversVersionIsInTheKey) {
  // reference/solver_version.hpp: a profile cached by another version of the reference's numbers
  // has another key.
  const Scene scene = clay_pull();
  StudyReferenceSpec spec;
  spec.samples = 6;
  const ReferenceRunSettings settings = settings_of(scene, spec, 0);
  const ReferenceCacheKey current = reference_cache_key(scene, settings);
  EXPECT_NE(current.text.find("solver_version = " + std::to_string(reference::solver_version) + "\n"), std::string::npos)
      << current.text;
  EXPECT_EQ(reference_cache_key(scene, settings, reference::solver_version).directory, current.directory);
  for (int other : {reference::solver_version - 1, reference::solver_version + 1})
    EXPECT_NE(reference_cache_key(scene, settings, other).directory, current.directory) << "version " << other;
}

TEST(ReferenceCache, AProfileCachedByAnotherSolverVersionIsRecomputedNeverRead) {
  // A study whose cache holds, for its one reference solve, a profile written under the previous
  // solver version (a marker force of 123 N that no solve produces): the study solves anew (the
  // runner is called) and scores against the new profile; a second run reads the new entry.
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_cache_version_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path study_file = dir / "v.toml";
  std::ofstream(study_file) << "[study]\nname = \"v\"\nscenes = [\"clay_pull\"]\nmodels = [\"springs\"]\n"
                               "[reference]\ndegree = 1\nrefinements = [0]\nsamples = 3\ntime_verification = false\n";
  const StudySpec spec = read_study(study_file);
  const fs::path out = dir / "out";
  const Scene scene = clay_pull();
  const ReferenceRunSettings settings = settings_of(scene, spec.reference, 0);

  // The old version's entry, where the study would find it if the key left the version out.
  ForceProfile stale;
  const std::vector<SampledTrajectory> trajectories = sample_scene_trajectories(scene);
  for (std::size_t k : settings.sample_indices)
    for (std::size_t t = 0; t < trajectories.size(); ++t) {
      ProfileRow r;
      r.tool = scene.tools[t].name;
      r.t = trajectories[t].samples[k].time;
      r.position = trajectories[t].samples[k].position;
      r.force = Eigen::Vector3d(0.0, 0.0, 123.0);
      stale.rows.push_back(r);
    }
  const ReferenceCacheKey old_key =
      reference_cache_key(study_reference_scene(scene, 0), settings, reference::solver_version - 1);
  write_profile_csv(stale, out / "cache" / old_key.directory / "profile.csv");

  int solves = 0;
  const ReferenceRunner fresh = [&](const StudyReferenceSolve&, const StudyReferenceSpec&) -> ReferenceResult {
    ++solves;
    ForceProfile p = stale;
    for (ProfileRow& r : p.rows) r.force = Eigen::Vector3d(0.0, 0.0, 1.0);
    return p;
  };
  const StudyResult first = run_study(spec, out, fresh);
  EXPECT_EQ(solves, 1) << "the profile of another solver version was read back";
  EXPECT_EQ(first.reference_runs, 1);
  const ReferenceCacheKey new_key = reference_cache_key(study_reference_scene(scene, 0), settings);
  ASSERT_TRUE(fs::exists(out / "cache" / new_key.directory / "profile.csv"));
  for (const ProfileRow& r : read_profile_csv(out / "cache" / new_key.directory / "profile.csv").rows)
    EXPECT_EQ(r.force.z(), 1.0);
  // The current version's entry is read (the test can tell a read from a solve).
  const StudyResult second = run_study(spec, out, fresh);
  EXPECT_EQ(solves, 1);
  EXPECT_EQ(second.reference_runs, 0);
  fs::remove_all(dir);
}
