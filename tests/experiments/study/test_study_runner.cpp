// The study runner's pieces: study files (errors name file:line:column), the reference's sample
// selection, subsampling, and a run of two scenes end to end.

#include "experiments/study/study_runner.hpp"
#include "experiments/study/model_resolution.hpp"
#include "experiments/study/study_report.hpp"

#include "experiments/models/model_catalogue.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include <unistd.h>

using namespace kerf;
namespace fs = std::filesystem;

namespace {
fs::path write_study(const std::string& name, const std::string& text) {
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_study_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / name) << text;
  return dir / name;
}
} // namespace

TEST(StudySpec, ReadsScenesModelsAndReference) {
  const StudySpec s = read_study(write_study("ok.toml", "[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\n"
                                                        "models = [\"fracture\"]\n[reference]\ndegree = 2\n"
                                                        "refinements = [0, 1, 2]\nsamples = 12\n"
                                                        "scene_degree = { potato_rect_cut = 1 }\n"
                                                        "scene_samples = { potato_rect_cut = 48 }\n"));
  EXPECT_EQ(s.name, "t");
  ASSERT_EQ(s.scenes.size(), 1u);
  EXPECT_EQ(s.scenes[0].filename(), "potato_rect_cut.toml");
  EXPECT_TRUE(s.has_reference);
  EXPECT_EQ(s.reference.degree, 2);
  EXPECT_EQ(s.reference.degree_of("potato_rect_cut", 2), 1); // its own degree in the study
  EXPECT_EQ(s.reference.degree_of("clay_pull", 1), 2);       // the study's, over the scene file's
  EXPECT_EQ(StudyReferenceSpec{}.degree_of("clay_pull", 2), 2); // no degree in the study: the scene file's
  EXPECT_EQ(s.reference.refinements, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(s.reference.samples, 12);
  EXPECT_EQ(s.reference.samples_of("potato_rect_cut"), 48); // its own count
  EXPECT_EQ(s.reference.samples_of("clay_pull"), 12);       // the study's
}

TEST(StudySpec, ErrorsNameFileLineColumnAndKey) {
  const std::pair<std::string, std::string> cases[] = {
      {"[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\"]\ncolour = 1\n", ":5:10: study.colour"},
      {"[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"no_model\"]\n", ":4:"},
      {"[study]\nname = \"t\"\nscenes = [\"no_scene\"]\nmodels = [\"fracture\"]\n", ":3:"},
      {"[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\"]\n[reference]\ndegree = 3\n",
       ":6:10: reference.degree"},
      {"[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\"]\n[reference]\nrefinements = [-4]\n",
       ":6:16: reference.refinements"},
      {"[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\"]\n[reference]\nrefinements = [0, -1]\n",
       ":6:19: reference.refinements"},
      {"[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\"]\n[reference]\n"
       "scene_refinements = { clay_pull = [-1, 0] }\n",
       ":6:35: reference.scene_refinements.clay_pull"},
      {"[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\"]\n[reference]\n"
       "scene_refinements = { potato_rect_cut = [0, -1] }\n",
       ":6:45: reference.scene_refinements.potato_rect_cut"},
      {"[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\"]\n[reference]\n"
       "scene_degree = { potato_rect_cut = 3 }\n",
       ":6:36: reference.scene_degree.potato_rect_cut"},
      {"[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\"]\n[reference]\n"
       "scene_degree = { clay_pull = 2 }\n",
       ":6:30: reference.scene_degree.clay_pull"},
      {"[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\"]\n[reference]\n"
       "scene_samples = { potato_rect_cut = 1 }\n",
       ":6:37: reference.scene_samples.potato_rect_cut"},
      {"[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\"]\n[reference]\n"
       "scene_samples = { clay_pull = 48 }\n",
       ":6:31: reference.scene_samples.clay_pull"},
  };
  int k = 0;
  for (const auto& [text, expected] : cases) {
    const fs::path f = write_study("bad" + std::to_string(k++) + ".toml", text);
    try {
      read_study(f);
      ADD_FAILURE() << "accepted " << text;
    } catch (const StudyError& e) {
      EXPECT_NE(std::string(e.what()).find(f.string() + expected), std::string::npos) << e.what();
    }
  }
}

TEST(StudyRunner, ReferenceSamplesAreEvenlySpacedWithBothEnds) {
  // 11 samples, 5 solves: indices 0, 2.5 -> 2, 5, 7.5 -> 7, 10 (integer division (n-1) i / (m-1)).
  EXPECT_EQ(reference_sample_indices(11, 5), (std::vector<std::size_t>{0, 2, 5, 7, 10}));
  EXPECT_EQ(reference_sample_indices(3, 10), (std::vector<std::size_t>{0, 1, 2})); // never repeats
}

TEST(StudyRunner, SubsampleKeepsTheChosenSamplesOfEveryTool) {
  ForceProfile p;
  for (int k = 0; k < 5; ++k)
    for (const char* tool : {"left", "right"}) {
      ProfileRow r;
      r.t = k;
      r.tool = tool;
      p.rows.push_back(r);
    }
  const ForceProfile s = subsample(p, {1, 3});
  ASSERT_EQ(s.rows.size(), 4u);
  EXPECT_EQ(s.rows[0].t, 1.0);
  EXPECT_EQ(s.rows[1].tool, "right");
  EXPECT_EQ(s.rows[3].t, 3.0);
}

TEST(StudyRunner, TwoScenesWithoutAReferenceReportCostsOnly) {
  const StudySpec spec = read_study(write_study(
      "two.toml", "[study]\nname = \"two\"\nscenes = [\"potato_rect_cut\", \"potato_wedge_cut\"]\nmodels = [\"fracture\"]\n"));
  const fs::path out = fs::temp_directory_path() / ("kerf_test_study_out_" + std::to_string(::getpid()));
  const StudyResult r = run_study(spec, out, {});
  ASSERT_EQ(r.rows.size(), 2u);
  for (const StudyRow& row : r.rows) {
    EXPECT_FALSE(row.metrics.has_value()); // no reference: no error is claimed
    EXPECT_GT(row.cost.steps, 0u);
    EXPECT_TRUE(fs::exists(out / row.scene / row.model / "profile.csv"));
  }
  EXPECT_EQ(r.reference_runs, 0);
  EXPECT_EQ(r.table().row_count(), 2u);
}

TEST(StudySpec, ACoarseLevelBelowTheScenesMesh) {
  // refinements = [-1, 0]: the scene meshed at twice its element size, then its own mesh (finest).
  const StudySpec s = read_study(write_study("coarse.toml", "[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\n"
                                                            "models = [\"fracture\"]\n[reference]\nrefinements = [-1, 0]\n"));
  EXPECT_EQ(s.reference.refinements, (std::vector<int>{-1, 0}));
}

TEST(StudyRunner, AModelIsScoredOnlyOverThePhasesItRepresents) {
  // A reference that cuts (paper 001 Fig. 11's sequence, one sample per mode and two before the
  // cut): a model without cutting is compared on the samples before the first rupture only.
  ForceProfile reference;
  const InteractionMode modes[] = {InteractionMode::no_contact, InteractionMode::deformation_1, InteractionMode::deformation_1,
                                   InteractionMode::rupture,    InteractionMode::cutting,       InteractionMode::deformation_2};
  for (int k = 0; k < 6; ++k) {
    ProfileRow r;
    r.tool = "blade";
    r.t = k;
    r.mode = modes[k];
    r.crack_extent = k >= 3 ? 1e-3 * (k - 2) : 0.0;
    reference.rows.push_back(r);
  }
  const PhenomenonSet cut_scene{Phenomenon::deformation, Phenomenon::cutting, Phenomenon::friction};
  const ScoredSamples deformation_only = represented_samples(reference, cut_scene, PhenomenonSet{Phenomenon::deformation});
  ASSERT_EQ(deformation_only.reference.rows.size(), 3u);
  EXPECT_EQ(deformation_only.reference.rows.back().t, 2.0);
  EXPECT_NE(deformation_only.note.find("3 of 6 reference samples"), std::string::npos) << deformation_only.note;
  // A cutting model, or a scene that never separates, is scored everywhere, with no note.
  const ScoredSamples cutting = represented_samples(reference, cut_scene, cut_scene);
  EXPECT_EQ(cutting.reference.rows.size(), 6u);
  EXPECT_TRUE(cutting.note.empty());
  EXPECT_EQ(represented_samples(reference, PhenomenonSet{Phenomenon::deformation}, PhenomenonSet{Phenomenon::deformation})
                .reference.rows.size(),
            6u);
  // A crack without a mode change (a tearing reference) separates the body too.
  reference.rows[2].crack_extent = 1e-4;
  EXPECT_EQ(represented_samples(reference, PhenomenonSet{Phenomenon::deformation, Phenomenon::tearing},
                                PhenomenonSet{Phenomenon::deformation})
                .reference.rows.size(),
            2u);
  // The spring network on a blade scene represents its deformation phase only (model_catalogue.hpp);
  // the fracture model all of the potato cut; the springs all of clay_pull.
  const Scene potato = read_scene(fs::path(KERF_SCENES_DIR) / "potato_rect_cut.toml");
  const Scene clay = read_scene(fs::path(KERF_SCENES_DIR) / "clay_pull.toml");
  EXPECT_EQ(represented_phenomena("springs", potato), PhenomenonSet{Phenomenon::deformation});
  EXPECT_EQ(represented_phenomena("fracture", potato), cut_scene);
  EXPECT_EQ(represented_phenomena("springs", clay), PhenomenonSet{Phenomenon::deformation});
}

TEST(StudyRunner, AModelThatCannotRunOnASceneHasARowSayingWhy) {
  // The voxel model needs paper 002's Table 1 ([models.voxel]); potato_rect_cut gives none.
  const StudySpec spec = read_study(write_study(
      "na.toml", "[study]\nname = \"na\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\", \"voxel\"]\n"));
  const fs::path out = fs::temp_directory_path() / ("kerf_test_study_na_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const StudyResult r = run_study(spec, out, {});
  ASSERT_EQ(r.rows.size(), 2u);
  EXPECT_EQ(r.rows[1].model, "voxel");
  EXPECT_FALSE(r.rows[1].metrics.has_value());
  EXPECT_EQ(r.rows[1].cost.steps, 0u);
  EXPECT_EQ(r.rows[1].note.rfind("not run: ", 0), 0u) << r.rows[1].note;
  EXPECT_NE(r.rows[1].note.find("[models.voxel]"), std::string::npos) << r.rows[1].note;
  EXPECT_FALSE(fs::exists(out / "potato_rect_cut" / "voxel" / "profile.csv"));
  EXPECT_EQ(r.table().row_count(), 2u);
  fs::remove_all(out);
}

TEST(StudyRunner, ANotRunNoteCarriesNoAbsolutePath) {
  // clay_pull has a sphere but no [models.voxel] section; the voxel builder's message names the
  // scene file by the absolute path the study resolved. The table is published
  // (docs/results.md): the note names it relative to the working directory, or by its file name
  // when the scene lies outside it (here: ctest runs in the build tree, the scene in the source).
  const StudySpec spec =
      read_study(write_study("abs.toml", "[study]\nname = \"abs\"\nscenes = [\"clay_pull\"]\nmodels = [\"voxel\"]\n"));
  const fs::path out = fs::temp_directory_path() / ("kerf_test_study_abs_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const StudyResult r = run_study(spec, out, {});
  ASSERT_EQ(r.rows.size(), 1u);
  const std::string& note = r.rows[0].note;
  ASSERT_EQ(note.rfind("not run: ", 0), 0u) << note;
  EXPECT_NE(note.find("[models.voxel]"), std::string::npos) << note;
  EXPECT_EQ(note.find(spec.scenes.front().string()), std::string::npos) << note;
  const fs::path shown = fs::relative(spec.scenes.front(), fs::current_path());
  const std::string expected = *shown.begin() == ".." ? spec.scenes.front().filename().string() : shown.string();
  EXPECT_NE(note.find(" in " + expected), std::string::npos) << note;
  fs::remove_all(out);
}

TEST(StudyRunner, CommonTimesKeepOnlyTheSamplesBothRunsHave) {
  // A reference that stopped after t = 2 is compared with a model on t = 0, 1, 2 only.
  ForceProfile model, reference;
  for (int k = 0; k < 6; ++k) {
    ProfileRow r;
    r.tool = "blade";
    r.t = 0.5 * k; // 0, 0.5, ..., 2.5
    model.rows.push_back(r);
  }
  for (int k = 0; k < 3; ++k) {
    ProfileRow r;
    r.tool = "blade";
    r.t = k + 1e-12; // 0, 1, 2 (within the 1e-9 s tolerance)
    reference.rows.push_back(r);
  }
  const ForceProfile common = at_common_times(model, reference);
  ASSERT_EQ(common.rows.size(), 3u);
  EXPECT_EQ(common.rows[1].t, 1.0);
  EXPECT_EQ(common.rows[2].t, 2.0);
  EXPECT_EQ(at_common_times(reference, model).rows.size(), 3u);
}

TEST(StudyRunner, EndToEndWithTheReferenceAndItsCache) {
  // Two scenes, two models, the finite-element reference at one coarse level on 4 samples. The
  // springs model on clay_pull is scored against the reference; the fracture model on the wedge
  // is run but, the uncut reference transmitting no force through a sharp blade, not scored (the
  // note says why). A second run takes the reference from the cache: no reference solve.
  const StudySpec spec = read_study(write_study(
      "e2e.toml", "[study]\nname = \"e2e\"\nscenes = [\"clay_pull\", \"potato_wedge_cut\"]\n"
                  "models = [\"springs\", \"fracture\"]\n[reference]\ndegree = 1\nrefinements = [0]\nsamples = 4\nadaptive = 0\n"));
  const fs::path out = fs::temp_directory_path() / ("kerf_test_study_e2e_" + std::to_string(::getpid()));
  fs::remove_all(out);
  StudyExecution execution;
  execution.timing_runs = 1;
  const StudyResult first = run_study(spec, out, finite_element_reference(), execution);
  // Each scene's level and the same level at half the load increment (the verification in time).
  EXPECT_EQ(first.reference_runs, 4);
  bool scored = false;
  for (const StudyRow& row : first.rows) {
    if (row.scene == "clay_pull" && row.model == "springs") {
      ASSERT_TRUE(row.metrics.has_value()) << row.note;
      EXPECT_TRUE(std::isfinite(row.metrics->normalised_rms_force_error));
      // The 4 requested samples and the end of the pull at t = 1.6 s, a vertex of the motion.
      EXPECT_EQ(row.metrics->samples, 5u);
      scored = true;
    }
    if (row.scene == "potato_wedge_cut") { // its reference first; springs there: the blade's deformation phase
      EXPECT_TRUE(row.model == "reference L0" || row.model == "reference L0 (half increment)" || row.model == "fracture" ||
                  row.model == "springs")
          << row.model;
    }
  }
  EXPECT_TRUE(scored);
  // Verified in time: the first row of each scene says how far the half increment moves the profile.
  EXPECT_NE(first.rows[0].note.find("sampling uncertainty"), std::string::npos) << first.rows[0].note;
  const StudyResult second = run_study(spec, out, finite_element_reference(), execution);
  EXPECT_EQ(second.reference_runs, 0);
  ASSERT_EQ(second.rows.size(), first.rows.size());
  for (std::size_t k = 0; k < first.rows.size(); ++k) {
    if (first.rows[k].metrics && second.rows[k].metrics) {
      EXPECT_EQ(first.rows[k].metrics->normalised_rms_force_error, second.rows[k].metrics->normalised_rms_force_error);
    }
  }
}

namespace {

/// The study's CSV table without its cost columns (median, p99, max cost and the rate they
/// allow): the columns a run beside another may change. RFC 4180 fields, quotes kept.
std::string without_cost_columns(const std::string& csv) {
  std::string out;
  std::vector<bool> keep;
  std::size_t start = 0;
  while (start < csv.size()) {
    const std::size_t end = csv.find('\n', start);
    const std::string line = csv.substr(start, end - start);
    start = end == std::string::npos ? csv.size() : end + 1;
    std::vector<std::string> fields(1);
    bool quoted = false;
    for (char c : line) {
      if (c == '"') quoted = !quoted;
      if (c == ',' && !quoted) fields.emplace_back();
      else fields.back() += c;
    }
    if (keep.empty())
      for (const std::string& f : fields) keep.push_back(f.find("cost") == std::string::npos && f.find("rate allowed") == std::string::npos);
    for (std::size_t k = 0; k < fields.size(); ++k)
      if (k < keep.size() && keep[k]) out += fields[k] + ",";
    out += "\n";
  }
  return out;
}

} // namespace

TEST(StudyRunner, ParallelRunsGiveTheSerialTablesApartFromCosts) {
  // Two scenes, three models (seven runs, two of them with calibrated parameters) and a fake
  // reference whose profile is the fracture model's own: one job, then three jobs. The tables must be
  // byte-identical once the cost columns (timing, disturbed by neighbours) are dropped — and the
  // cost columns must be there (the test would pass vacuously on an empty table otherwise).
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_study_jobs_" + std::to_string(::getpid()));
  fs::create_directories(dir / "calibration");
  std::ofstream(dir / "calibration" / "fracture.toml") << "[models.fracture]\nrupture_force_per_length = \"350 N/m\"\n";
  const StudySpec spec = read_study(write_study(
      "jobs.toml", "[study]\nname = \"jobs\"\nscenes = [\"potato_rect_cut\", \"potato_wedge_cut\"]\n"
                   "models = [\"fracture\", \"edge\", \"springs\"]\n[reference]\nrefinements = [0]\nsamples = 40\ntime_verification = false\n"
                   "[calibration]\npotato_rect_cut = [\"" + (dir / "calibration" / "fracture.toml").string() + "\"]\n"));
  // The fake reference: the fracture model's profile of the scene at the chosen samples.
  const ReferenceRunner fake = [](const StudyReferenceSolve& solve, const StudyReferenceSpec&) -> ReferenceResult {
    const Scene& scene = solve.scene;
    const std::vector<std::size_t>& indices = solve.indices;
    const TetMesh mesh = scene_mesh(scene);
    BuiltModel built = make_model("fracture", scene, mesh);
    return subsample(run_model(*built.model, {scene.tools.front().name}, sample_scene_trajectories(scene)), indices);
  };
  StudyExecution serial, parallel;
  serial.timing_runs = parallel.timing_runs = 1;
  parallel.jobs = 3;
  const fs::path a = dir / "serial", b = dir / "parallel";
  fs::remove_all(a);
  fs::remove_all(b);
  const StudyResult one = run_study(spec, a, fake, serial);
  const StudyResult three = run_study(spec, b, fake, parallel);
  // 2 x (reference L0, fracture, edge, springs: the blade's deformation phase) + fracture (calibrated).
  ASSERT_EQ(one.rows.size(), 9u);
  EXPECT_EQ(one.rows[0].model, "reference L0");
  EXPECT_EQ(one.rows[2].model, "fracture (calibrated)");
  EXPECT_TRUE(one.rows[1].metrics.has_value());
  EXPECT_EQ(one.reference_runs, 2);
  EXPECT_EQ(three.reference_runs, 2);
  const std::string csv_one = one.table().csv(), csv_three = three.table().csv();
  EXPECT_NE(csv_one.find("p99 cost"), std::string::npos);
  // The filter drops exactly the five cost columns (median, p99, p99 spread, max, rate allowed) of 14.
  const std::string header = without_cost_columns(csv_one.substr(0, csv_one.find('\n')));
  EXPECT_EQ(std::count(header.begin(), header.end(), ','), 9);
  // Same tables to round-off: a run beside others may sum its samples in another order (a metric of
  // exactly 0 serially came out 4e-15 with three jobs), so numeric cells agree to 1e-9 relative and
  // every other cell exactly.
  const std::string table_one = without_cost_columns(csv_one), table_three = without_cost_columns(csv_three);
  std::vector<std::string> cells_one, cells_three;
  for (auto [table, cells] : {std::pair{&table_one, &cells_one}, std::pair{&table_three, &cells_three}}) {
    std::string cell;
    for (char c : *table)
      if (c == ',' || c == '\n') {
        cells->push_back(cell);
        cell.clear();
      } else {
        cell += c;
      }
  }
  ASSERT_EQ(cells_one.size(), cells_three.size());
  for (std::size_t k = 0; k < cells_one.size(); ++k) {
    char* end_one = nullptr;
    char* end_three = nullptr;
    const double a = std::strtod(cells_one[k].c_str(), &end_one), b = std::strtod(cells_three[k].c_str(), &end_three);
    if (!cells_one[k].empty() && *end_one == '\0' && !cells_three[k].empty() && *end_three == '\0')
      EXPECT_NEAR(a, b, 1e-9 * std::max({1.0, std::abs(a), std::abs(b)})) << "cell " << k << " of the table";
    else
      EXPECT_EQ(cells_one[k], cells_three[k]) << "cell " << k << " of the table";
  }
  // Calibrated parameters (f_r 350 instead of 300 N/m) change the fracture model's deformation-1 samples
  // (40 samples over the 22.5 s trajectory: one per 0.58 mm of cut, two or three within δ_r = 1.5 mm),
  // so its row differs from the plain one, which is the fake reference itself (error 0).
  EXPECT_NE(one.rows[1].metrics->normalised_rms_force_error, one.rows[2].metrics->normalised_rms_force_error);
}

TEST(StudySpec, ReadsSolverSettingsAndFittedCalibrations) {
  const StudySpec s = read_study(write_study(
      "solver.toml", "[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\", \"clay_pull\"]\nmodels = [\"fracture\", \"springs\"]\n"
                     "[reference]\nlinear_solver = \"iterative\"\nfracture = \"auto\"\n"
                     "[[calibrate]]\nscene = \"clay_pull\"\nmodel = \"springs\"\nspeed = 4.0\nmax_evaluations = 12\nsamples = 5\n"));
  EXPECT_EQ(s.reference.linear_solver, reference::LinearSolverChoice::iterative);
  EXPECT_EQ(s.reference.fracture, ReferenceFracture::automatic);
  ASSERT_EQ(s.fits.size(), 1u);
  EXPECT_EQ(s.fits[0].scene, "clay_pull");
  EXPECT_EQ(s.fits[0].model, "springs");
  EXPECT_EQ(s.fits[0].speed, 4.0);
  EXPECT_EQ(s.fits[0].max_evaluations, 12);
  EXPECT_EQ(s.fits[0].samples, 5);
  // Defaults: the automatic solver, no fracture (as `kerf reference`).
  const StudySpec d = read_study(write_study("solver_default.toml", "[study]\nname = \"t\"\nscenes = [\"clay_pull\"]\n"
                                                                    "models = [\"springs\"]\n[reference]\n"));
  EXPECT_EQ(d.reference.linear_solver, reference::LinearSolverChoice::automatic);
  EXPECT_EQ(d.reference.fracture, ReferenceFracture::off);
}

TEST(StudySpec, ReadsTheReferencesSamplingAndItsVerificationInTime) {
  // Defaults: adaptive sampling at 20 % of the peak, the finest level verified in time.
  const std::string head = "[study]\nname = \"t\"\nscenes = [\"clay_pull\"]\nmodels = [\"springs\"]\n[reference]\n";
  const StudySpec defaults = read_study(write_study("sampling0.toml", head));
  EXPECT_EQ(defaults.reference.adaptive, 0.2);
  EXPECT_TRUE(defaults.reference.time_verification);
  const StudySpec set = read_study(write_study("sampling1.toml", head + "adaptive = 0\ntime_verification = false\n"));
  EXPECT_EQ(set.reference.adaptive, 0.0);
  EXPECT_FALSE(set.reference.time_verification);
  // Into each solve's settings: the force change, and a least travel of 1/40 of the scene's element
  // size (clay_pull: 2.5 mm) at every level, halved at half the increment.
  const Scene clay = read_scene(fs::path(KERF_SCENES_DIR) / "clay_pull.toml");
  for (int level : {-2, 0}) {
    const Scene s = study_reference_scene(clay, level);
    const ReferenceRunSettings whole = study_reference_settings(defaults.reference, s, level, {0, 1}, LoadIncrement::whole);
    const ReferenceRunSettings half = study_reference_settings(defaults.reference, s, level, {0, 1}, LoadIncrement::half);
    EXPECT_EQ(whole.adaptive_force_change, 0.2);
    EXPECT_DOUBLE_EQ(whole.adaptive_min_travel, 2.5e-3 / 40.0) << level;
    EXPECT_DOUBLE_EQ(half.adaptive_min_travel, 2.5e-3 / 80.0) << level;
  }
}

TEST(StudySpec, BadSolverSettingsAndFitsNameFileLineColumnAndKey) {
  const std::string head = "[study]\nname = \"t\"\nscenes = [\"clay_pull\"]\nmodels = [\"springs\", \"edge\"]\n[reference]\n";
  const std::pair<std::string, std::string> cases[] = {
      {head + "linear_solver = \"cholesky\"\n", ":6:17: reference.linear_solver"},
      {head + "fracture = \"yes\"\n", ":6:12: reference.fracture"},
      {head + "adaptive = 1.5\n", ":6:12: reference.adaptive"},
      {head + "adaptive = -0.1\n", ":6:12: reference.adaptive"},
      {head + "time_verification = 1\n", ":6:21: reference.time_verification"},
      {head + "[[calibrate]]\nscene = \"potato_rect_cut\"\nmodel = \"springs\"\n", ":7:9: calibrate.scene"},
      {head + "[[calibrate]]\nscene = \"clay_pull\"\nmodel = \"voxel\"\n", ":8:9: calibrate.model"},
      {head + "[[calibrate]]\nscene = \"clay_pull\"\nmodel = \"edge\"\n", ":8:9: calibrate.model"}, // no free parameters
      {head + "[[calibrate]]\nscene = \"clay_pull\"\nmodel = \"springs\"\nspeed = 1.0\n", ":9:9: calibrate.speed"}, // not held out
      {head + "[[calibrate]]\nscene = \"clay_pull\"\nmodel = \"springs\"\nmax_evaluations = 0\n", ":9:19: calibrate.max_evaluations"},
      {head + "[[calibrate]]\nscene = \"clay_pull\"\nmodel = \"springs\"\nsamples = 1\n", ":9:11: calibrate.samples"},
      {"[study]\nname = \"t\"\nscenes = [\"clay_pull\"]\nmodels = [\"springs\"]\n[[calibrate]]\nscene = \"clay_pull\"\nmodel = \"springs\"\n",
       ": calibrate: a fitted calibration needs the study's [reference]"},
  };
  int k = 0;
  for (const auto& [text, expected] : cases) {
    const fs::path f = write_study("bad_fit" + std::to_string(k++) + ".toml", text);
    try {
      read_study(f);
      ADD_FAILURE() << "accepted " << text;
    } catch (const StudyError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(f.string()), std::string::npos) << e.what();
    }
  }
}

namespace {

/// A stand-in for the finite-element reference, counting its solves: the fracture model's profile
/// of the scene at the chosen samples, with f_r = `rupture_force_per_length` (the "truth").
ReferenceRunner fracture_as_reference(std::atomic<int>& solves, double rupture_force_per_length) {
  return [&solves, rupture_force_per_length](const StudyReferenceSolve& solve, const StudyReferenceSpec&) -> ReferenceResult {
    const Scene& scene = solve.scene;
    const std::vector<std::size_t>& indices = solve.indices;
    ++solves;
    Scene truth = scene;
    truth.fracture->rupture_force_per_length = rupture_force_per_length;
    const TetMesh mesh = scene_mesh(truth);
    BuiltModel built = make_model("fracture", truth, mesh);
    return subsample(run_model(*built.model, {truth.tools.front().name}, sample_scene_trajectories(truth)), indices);
  };
}

} // namespace

TEST(StudyRunner, AChangedSolverSettingMissesTheCacheAnUnchangedOneHitsIt) {
  // The reference is cached by the hash of the scene and the solver settings. One scene,
  // one level: each run below says how many reference solves it did.
  StudySpec spec = read_study(write_study("cache.toml", "[study]\nname = \"cache\"\nscenes = [\"potato_rect_cut\"]\n"
                                                        "models = [\"fracture\"]\n[reference]\nrefinements = [0]\nsamples = 8\n"
                                                        "time_verification = false\n"));
  const fs::path out = fs::temp_directory_path() / ("kerf_test_study_cache_" + std::to_string(::getpid()));
  fs::remove_all(out);
  std::atomic<int> solves{0};
  const ReferenceRunner fake = fracture_as_reference(solves, 300.0);
  const auto run = [&] {
    const int before = solves;
    const StudyResult r = run_study(spec, out, fake);
    EXPECT_EQ(r.reference_runs, solves - before);
    return r.reference_runs;
  };
  EXPECT_EQ(run(), 1);
  EXPECT_EQ(run(), 0); // unchanged: from the cache
  spec.reference.linear_solver = reference::LinearSolverChoice::iterative;
  EXPECT_EQ(run(), 1);
  EXPECT_EQ(run(), 0);
  spec.reference.fracture = ReferenceFracture::automatic;
  EXPECT_EQ(run(), 1);
  spec.reference.degree = 2;
  EXPECT_EQ(run(), 1);
  spec.reference.samples = 9;
  EXPECT_EQ(run(), 1);
  spec.reference = StudyReferenceSpec{}; // back to the first settings: still cached
  spec.reference.samples = 8;
  spec.reference.time_verification = false;
  EXPECT_EQ(run(), 0);
  // One entry per distinct setting, each with its key written beside the profile.
  int entries = 0;
  for (const auto& e : fs::directory_iterator(out / "cache")) {
    EXPECT_TRUE(fs::exists(e.path() / "key.txt")) << e.path();
    ++entries;
  }
  EXPECT_EQ(entries, 5);
}

TEST(StudyRunner, ACoarseLevelIsItsOwnSolveOnTheCoarserMesh) {
  // refinements = [-1, 0]: two solves, the first given the scene at twice its element size (4 mm
  // for potato_rect_cut's 2 mm), each in its own cache entry. The stand-in reference is the
  // fracture model on the scene's own mesh plus (h / 2 mm - 1) x 1 N along x: the L-1 profile is
  // the finest one offset by exactly 1 N at every sample, so its RMS error is 1 N / max|f_L0|.
  StudySpec spec = read_study(write_study("levels.toml", "[study]\nname = \"levels\"\nscenes = [\"potato_rect_cut\"]\n"
                                                         "models = [\"fracture\"]\n[reference]\nrefinements = [-1, 0]\nsamples = 8\n"
                                                         "time_verification = false\n"));
  const fs::path out = fs::temp_directory_path() / ("kerf_test_study_levels_" + std::to_string(::getpid()));
  fs::remove_all(out);
  std::atomic<int> solves{0};
  std::vector<double> sizes;
  double finest_peak = 0.0;
  const ReferenceRunner truth = fracture_as_reference(solves, 300.0);
  const ReferenceRunner offset = [&](const StudyReferenceSolve& solve, const StudyReferenceSpec& settings) -> ReferenceResult {
    const double h = solve.scene.geometry.element_size;
    sizes.push_back(h);
    StudyReferenceSolve own = solve;
    own.scene.geometry.element_size = 2e-3;
    ForceProfile p = truth(own, settings).profile;
    for (ProfileRow& r : p.rows) {
      r.force.x() += h / 2e-3 - 1.0;
      if (h == 2e-3) finest_peak = std::max(finest_peak, r.force.norm());
    }
    return p;
  };
  const StudyResult r = run_study(spec, out, offset);
  EXPECT_EQ(r.reference_runs, 2);
  ASSERT_EQ(sizes.size(), 2u);
  EXPECT_DOUBLE_EQ(sizes[0], 4e-3);
  EXPECT_DOUBLE_EQ(sizes[1], 2e-3);
  ASSERT_GE(r.rows.size(), 3u);
  EXPECT_EQ(r.rows[0].model, "reference L0"); // the finest first; two levels: no GCI, and its note says so
  EXPECT_NE(r.rows[0].note.find("no GCI available"), std::string::npos) << r.rows[0].note;
  EXPECT_EQ(r.rows[1].model, "reference L-1");
  ASSERT_TRUE(r.rows[1].metrics.has_value()) << r.rows[1].note;
  ASSERT_GT(finest_peak, 0.0);
  EXPECT_NEAR(r.rows[1].metrics->normalised_rms_force_error, 1.0 / finest_peak, 1e-9);
  EXPECT_NE(r.rows[1].note.find("h = 4 mm"), std::string::npos) << r.rows[1].note;
  EXPECT_EQ(r.rows[2].model, "fracture");
  ASSERT_TRUE(r.rows[2].metrics.has_value()) << r.rows[2].note;
  EXPECT_NEAR(r.rows[2].metrics->normalised_rms_force_error, 0.0, 1e-12); // the finest is the model itself
  EXPECT_EQ(std::distance(fs::directory_iterator(out / "cache"), fs::directory_iterator{}), 2);
  EXPECT_EQ(run_study(spec, out, offset).reference_runs, 0); // both cached
  fs::remove_all(out);
}

TEST(StudyRunner, AFittedCalibrationIsScoredOnTheHeldOutTrajectory) {
  // The "reference" is the fracture model with f_r = 500 N/m; the scene says 300 N/m. The study
  // fits f_r, δ_r, δ_c (and the exponents: all nine pairs tried) on the trajectory at double speed, and scores the fitted model on the scene's own trajectory, which the fit never
  // saw. The fracture model is rate-independent (paper 001's states depend on travel, not on
  // time), so the fit transfers: the calibrated row's error must fall well below the plain row's.
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_study_fit_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const StudySpec spec = read_study(write_study(
      "fit.toml", "[study]\nname = \"fit\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\", \"edge\"]\n"
                  "[reference]\nrefinements = [0]\nsamples = 40\nfracture = \"auto\"\ntime_verification = false\n"
                  "[[calibrate]]\nscene = \"potato_rect_cut\"\nmodel = \"fracture\"\nspeed = 2.0\nmax_evaluations = 10\n"));
  std::atomic<int> solves{0};
  const StudyResult r = run_study(spec, dir, fracture_as_reference(solves, 500.0));
  EXPECT_EQ(r.reference_runs, 2); // the scene's trajectory, and the calibration trajectory
  ASSERT_EQ(r.rows.size(), 4u);
  EXPECT_EQ(r.rows[0].model, "reference L0");
  EXPECT_EQ(r.rows[1].model, "fracture");
  EXPECT_EQ(r.rows[2].model, "fracture (calibrated)"); // right after its model
  EXPECT_EQ(r.rows[3].model, "edge");
  ASSERT_TRUE(r.rows[1].metrics && r.rows[2].metrics) << r.rows[2].note;
  EXPECT_GT(r.rows[1].metrics->normalised_rms_force_error, 0.05);
  EXPECT_LT(r.rows[2].metrics->normalised_rms_force_error, 0.5 * r.rows[1].metrics->normalised_rms_force_error);
  EXPECT_EQ(r.rows[2].metrics->samples, 40u); // scored on the scene's own 40 samples
  EXPECT_NE(r.rows[2].note.find("fitted at speed ×2"), std::string::npos) << r.rows[2].note;
  EXPECT_NE(r.rows[2].note.find("f_r 300 → "), std::string::npos) << r.rows[2].note;
  // The parameter file recovers the truth (f_r = 500 N/m; δ_r, δ_c as in the scene), within 3 %:
  // ten runs per simplex search stop it short of its 0.1 % tolerance (measured: 494.6 N/m).
  const fs::path parameters = dir / "potato_rect_cut" / "fracture-calibrated" / "parameters.toml";
  ASSERT_TRUE(fs::exists(parameters));
  const Scene fitted = read_scene(spec.scenes.front(), {parameters});
  EXPECT_NEAR(fitted.fracture->rupture_force_per_length, 500.0, 15.0);
  // Re-run: both references from the cache, the same fit.
  const StudyResult again = run_study(spec, dir, fracture_as_reference(solves, 500.0));
  EXPECT_EQ(again.reference_runs, 0);
  ASSERT_EQ(again.rows.size(), 4u);
  ASSERT_TRUE(again.rows[2].metrics.has_value());
  EXPECT_EQ(again.rows[2].metrics->normalised_rms_force_error, r.rows[2].metrics->normalised_rms_force_error);
}

TEST(StudyRunner, AFitAgainstAForcelessReferenceSaysWhy) {
  // A reference that transmits no force (today's blade scenes) cannot be fitted to: the row is
  // there, with no metrics and a note, never a made-up fit.
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_study_fit0_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const StudySpec spec = read_study(write_study(
      "fit0.toml", "[study]\nname = \"fit0\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\"]\n"
                   "[reference]\nrefinements = [0]\nsamples = 6\nfracture = \"on\"\ntime_verification = false\n"
                   "[[calibrate]]\nscene = \"potato_rect_cut\"\nmodel = \"fracture\"\nspeed = 0.5\n"));
  const ReferenceRunner forceless = [](const StudyReferenceSolve& solve, const StudyReferenceSpec&) -> ReferenceResult {
    const Scene& scene = solve.scene;
    const std::vector<std::size_t>& indices = solve.indices;
    ForceProfile p;
    const SampledTrajectory t = sample_scene_trajectories(scene).front();
    for (std::size_t k : indices) {
      ProfileRow row;
      row.t = t.samples[k].time;
      row.tool = scene.tools.front().name;
      row.position = t.samples[k].position;
      p.rows.push_back(row);
    }
    return p;
  };
  const StudyResult r = run_study(spec, dir, forceless);
  ASSERT_EQ(r.rows.size(), 3u); // reference L0, fracture, fracture (calibrated)
  EXPECT_EQ(r.rows[2].model, "fracture (calibrated)");
  EXPECT_FALSE(r.rows[2].metrics.has_value());
  EXPECT_EQ(r.rows[2].note.rfind("not calibrated: ", 0), 0u) << r.rows[2].note;
}

TEST(StudyRunner, AReferenceThatStoppedShortSaysSoOnItsRow) {
  // A reference whose load path stopped before the trajectory's end (run_reference writes the reason
  // into its manifest's `stopped` and the profile up to the last converged sample) is verified and
  // scored on the samples it reached only: the reference row says so before anything else.
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_study_stopped_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const StudySpec spec = read_study(write_study(
      "stopped.toml", "[study]\nname = \"stopped\"\nscenes = [\"potato_wedge_cut\"]\nmodels = [\"fracture\"]\n"
                      "[reference]\nrefinements = [0]\nsamples = 6\ntime_verification = false\n"));
  const ReferenceRunner stops_half_way = [](const StudyReferenceSolve& solve, const StudyReferenceSpec&) -> ReferenceResult {
    const Scene& scene = solve.scene;
    const std::vector<std::size_t>& indices = solve.indices;
    const fs::path& out = solve.dir;
    const TetMesh mesh = scene_mesh(scene);
    BuiltModel built = make_model("fracture", scene, mesh);
    const std::vector<std::size_t> reached(indices.begin(), indices.begin() + static_cast<long>(indices.size() / 2));
    fs::create_directories(out);
    const std::string why = "load path: sample 9 did not converge after 6 cut-backs";
    std::ofstream(out / "manifest.json") << R"({"stopped": ")" << why << R"("})";
    return ReferenceResult{subsample(run_model(*built.model, {scene.tools.front().name}, sample_scene_trajectories(scene)), reached), why};
  };
  const StudyResult r = run_study(spec, dir, stops_half_way);
  ASSERT_FALSE(r.rows.empty());
  // The study lists it among the stopped references: `kerf study` ends with status 4 after writing its tables.
  ASSERT_EQ(r.stopped_references.size(), 1u);
  EXPECT_NE(r.stopped_references.front().find("potato_wedge_cut L0: load path: sample 9"), std::string::npos) << r.stopped_references.front();
  EXPECT_EQ(r.rows[0].model, "reference L0");
  EXPECT_NE(r.rows[0].note.find("L0 stopped before the trajectory's end (load path: sample 9 did not converge"),
            std::string::npos)
      << r.rows[0].note;
  fs::remove_all(dir);
}

TEST(StudyRunner, PublishingReplacesTheLibrarysStaleEntries) {
  // A library holds the study's planned solves only: publishing copies each solved one in and
  // removes an entry under any other key (a stale one, e.g. from an older solver version), and
  // leaves alone what is no entry (a folder without key.txt).
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_publish_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const fs::path library = dir / "library", cache = dir / "cache";
  auto entry = [](const fs::path& d, const std::string& key) {
    fs::create_directories(d);
    std::ofstream(d / "key.txt") << key;
    std::ofstream(d / "profile.csv") << "t,tool\n";
  };
  entry(cache / "planned-key", "planned");
  entry(library / "stale-key", "stale");
  entry(library / "planned-key", "old text of the planned key");
  fs::create_directories(library / "notes");
  StudyReferenceSolve solve;
  solve.dir = cache / "planned-key";
  EXPECT_EQ(publish_references({solve}, library, "kerf study default --publish-references"), 1);
  EXPECT_FALSE(fs::exists(library / "stale-key"));
  EXPECT_TRUE(fs::exists(library / "notes"));
  std::ifstream key(library / "planned-key" / "key.txt");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(key), {}), "planned");
  EXPECT_TRUE(fs::exists(library / "planned-key" / "command.txt"));
  fs::remove_all(dir);
}

TEST(StudyRunner, NoFitToTheUncutReferenceOfACuttingScene) {
  // potato_rect_cut cuts; with [reference] fracture = "off" its reference is an uncut body, and a
  // cutting model fitted to it would be fitted to that. The row says so, and the calibration
  // trajectory's reference is not even solved.
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_study_fitoff_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const StudySpec spec = read_study(write_study(
      "fitoff.toml", "[study]\nname = \"fitoff\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\"]\n"
                     "[reference]\nrefinements = [0]\nsamples = 6\ntime_verification = false\n"
                     "[[calibrate]]\nscene = \"potato_rect_cut\"\nmodel = \"fracture\"\n"));
  std::atomic<int> solves{0};
  const StudyResult r = run_study(spec, dir, fracture_as_reference(solves, 500.0));
  EXPECT_EQ(r.reference_runs, 1);
  ASSERT_EQ(r.rows.size(), 3u); // reference L0, fracture, fracture (calibrated)
  EXPECT_EQ(r.rows[2].model, "fracture (calibrated)");
  EXPECT_FALSE(r.rows[2].metrics.has_value());
  EXPECT_EQ(r.rows[2].note.rfind("not calibrated: scene potato_rect_cut cuts or tears", 0), 0u) << r.rows[2].note;
}

TEST(StudyRunner, TheCalibrationTrajectoryIsTheSamePathPlayedFaster) {
  // clay_pull: a 6 mm pull at 3.75 mm/s (1.6 s) and a 1 s hold. Played 4 times as fast: 0.4 s + 0.25 s,
  // through the same positions (the end point, and the point half way up the pull).
  const Scene scene = read_scene(fs::path(KERF_SCENES_DIR) / "clay_pull.toml");
  const Scene fast = calibration_scene(scene, 4.0);
  const SampledTrajectory a = sample_scene_trajectories(scene).front(), b = sample_scene_trajectories(fast).front();
  EXPECT_NEAR(a.duration(), 2.6, 1e-9);
  EXPECT_NEAR(b.duration(), 0.65, 1e-9);
  EXPECT_LT((a.samples.back().position - b.samples.back().position).norm(), 1e-12);
  EXPECT_LT((a.samples[800].position - b.samples[200].position).norm(), 1e-9); // t = 0.8 s and 0.2 s: 3 mm up
  EXPECT_THROW(calibration_scene(scene, 0.0), std::invalid_argument);
}

TEST(StudySpec, TheDefaultStudyCarriesCalibratedRows) {
  // The study reports calibrated and uncalibrated rows side by side: the default study
  // fits every model `kerf calibrate` supports that runs on its scenes: the springs on clay_pull,
  // the fracture model on both potato cuts and the voxel model on the sponge knife cut.
  const StudySpec s = read_study(fs::path(KERF_STUDIES_DIR) / "default.toml");
  ASSERT_TRUE(s.has_reference);
  std::set<std::pair<std::string, std::string>> fits;
  for (const StudyCalibrationFit& f : s.fits) {
    fits.emplace(f.scene, f.model);
    EXPECT_NE(f.speed, 1.0); // the scene's own trajectory stays held out
  }
  EXPECT_EQ(fits, (std::set<std::pair<std::string, std::string>>{
                      {"clay_pull", "springs"}, {"potato_rect_cut", "fracture"}, {"potato_wedge_cut", "fracture"},
                      {"sponge_knife_cut_proportional", "voxel"}}));
  // Solution verification: three mesh levels for every scene (Reference III). The default study
  // keeps its library affordable: clay_pull and the potato cuts on [-2, -1, 0], their finest the
  // scene's own mesh (the potatoes' 1 mm level is the full study's, experiments/studies/full.toml);
  // the sponge's finest half its own ([reference] scene_refinements); the potato cuts on more
  // samples ([reference] scene_samples).
  EXPECT_EQ(s.reference.levels_of("clay_pull"), (std::vector<int>{-2, -1, 0}));
  EXPECT_EQ(s.reference.levels_of("potato_rect_cut"), (std::vector<int>{-2, -1, 0}));
  EXPECT_EQ(s.reference.levels_of("potato_wedge_cut"), (std::vector<int>{-2, -1, 0}));
  EXPECT_EQ(s.reference.levels_of("sponge_knife_cut_proportional"), (std::vector<int>{-1, 0, 1}));
  EXPECT_GT(s.reference.samples_of("potato_rect_cut"), s.reference.samples);
  // The shipped references, beside the study files.
  EXPECT_EQ(s.reference.library, (fs::path(KERF_STUDIES_DIR) / ".." / "references").lexically_normal());
}

TEST(StudySpec, EveryFastModelOfTheDefaultStudyRunsOnOneOfItsScenes) {
  // Studies II: the default study scores every fast model of the catalogue against the reference,
  // so each must accept (require_model_for_scene: tools, sections, phenomena) at least one of its
  // scenes — the voxel model the sponge knife cut, which no other default scene gives it.
  const StudySpec s = read_study(fs::path(KERF_STUDIES_DIR) / "default.toml");
  std::set<std::string> listed(s.models.begin(), s.models.end());
  for (const ModelDescription& m : model_catalogue()) EXPECT_TRUE(listed.count(std::string(m.name))) << m.name;
  for (const std::string& model : s.models) {
    std::vector<std::string> accepted;
    for (const fs::path& scene : s.scenes) {
      try {
        require_model_for_scene(model, read_scene(scene));
        accepted.push_back(scene.stem().string());
      } catch (const ModelMismatch&) {
      }
    }
    EXPECT_FALSE(accepted.empty()) << model << " runs on none of the default study's scenes";
  }
}

TEST(StudySpec, TheReferenceLibraryIsAFolderBesideTheStudy) {
  const StudySpec s = read_study(write_study("lib.toml", "[study]\nname = \"t\"\nscenes = [\"clay_pull\"]\nmodels = [\"springs\"]\n"
                                                         "[reference]\nlibrary = \"kept/refs\"\n"));
  EXPECT_EQ(s.reference.library.filename(), "refs");
  EXPECT_EQ(s.reference.library.parent_path().filename(), "kept");
  for (const char* bad : {"library = \"\"", "library = 3"}) {
    SCOPED_TRACE(bad);
    try {
      (void)read_study(write_study("bad.toml", std::string("[study]\nname = \"t\"\nscenes = [\"clay_pull\"]\nmodels = [\"springs\"]\n[reference]\n") +
                                                   bad + "\n"));
      ADD_FAILURE() << "no StudyError";
    } catch (const StudyError& e) {
      EXPECT_NE(std::string(e.what()).find("reference.library"), std::string::npos) << e.what();
    }
  }
}

TEST(StudySpec, ReadsModelResolutions) {
  const StudySpec s = read_study(write_study("res.toml", "[study]\nname = \"t\"\nscenes = [\"clay_pull\"]\nmodels = [\"springs\", \"edge\"]\n"
                                                         "[models.springs]\nresolutions = [2, 4, 8]\n"));
  EXPECT_EQ(s.resolutions.at("springs"), (std::vector<int>{2, 4, 8}));
  const std::string head = "[study]\nname = \"t\"\nscenes = [\"clay_pull\"]\nmodels = [\"springs\", \"edge\"]\n";
  const std::pair<std::string, std::string> cases[] = {
      {head + "[models.springs]\nresolutions = [4, 2]\n", ":6:19: models.springs.resolutions"},  // not ascending
      {head + "[models.springs]\nresolutions = [0]\n", ":6:16: models.springs.resolutions"},     // below 1
      {head + "[models.edge]\nresolutions = [2]\n", ":6:15: models.edge.resolutions: model edge has no resolution"},
      {head + "[models.voxel]\nresolutions = [2]\n", ":5:9: models.voxel: expected a model of study.models"},
      {head + "[models.springs]\ncells = [2]\n", ":6:9: models.springs.cells"},
  };
  int k = 0;
  for (const auto& [text, expected] : cases) {
    const fs::path f = write_study("bad_res" + std::to_string(k++) + ".toml", text);
    try {
      read_study(f);
      ADD_FAILURE() << "accepted " << text;
    } catch (const StudyError& e) {
      EXPECT_NE(std::string(e.what()).find(f.string() + expected), std::string::npos) << e.what();
    }
  }
}

TEST(ModelResolution, SetsEachModelsKnobOnTheScene) {
  // Springs: N cells per side; a scene that fixes the cell size (clay_tear: 12 cells of 5 mm) keeps
  // its block's 60 mm extent. Voxel: paper 002's 10 × 20 × 20 grid scaled to n along its first axis.
  const Scene clay = read_scene(fs::path(KERF_SCENES_DIR) / "clay_pull.toml");
  const ModelResolution four = at_resolution("springs", clay, 4);
  EXPECT_EQ(four.scene.springs->cells, 4);
  EXPECT_EQ(four.label, "springs [N = 4]");
  const Scene tear = read_scene(fs::path(KERF_SCENES_DIR) / "clay_tear.toml");
  ASSERT_TRUE(tear.springs && tear.springs->cells && tear.springs->cell_size);
  const ModelResolution six = at_resolution("springs", tear, 6);
  EXPECT_NEAR(*six.scene.springs->cell_size * 6, *tear.springs->cell_size * *tear.springs->cells, 1e-15);
  const Scene sponge = read_scene(fs::path(KERF_SCENES_DIR) / "sponge_cut_proportional.toml");
  ASSERT_TRUE(sponge.voxel.has_value());
  EXPECT_EQ(sponge.voxel->grid, (std::array<int, 3>{10, 20, 20}));
  const ModelResolution five = at_resolution("voxel", sponge, 5);
  EXPECT_EQ(five.scene.voxel->grid, (std::array<int, 3>{5, 10, 10}));
  EXPECT_EQ(five.label, "voxel [grid 5×10×10]");
  EXPECT_THROW(at_resolution("voxel", clay, 5), ModelMismatch); // no [models.voxel]
  EXPECT_THROW(at_resolution("edge", clay, 5), std::invalid_argument);
  EXPECT_THROW(at_resolution("springs", clay, 0), std::invalid_argument);
}

TEST(StudyRunner, AModelRunsAtEachOfItsResolutions) {
  // [models.springs] resolutions = [2, 3]: two rows instead of the plain one, each built with its N
  // (the run's manifest records the network the builder made: cells_per_side), each with a profile.
  const StudySpec spec = read_study(write_study(
      "sweep.toml", "[study]\nname = \"sweep\"\nscenes = [\"clay_pull\"]\nmodels = [\"springs\"]\n[models.springs]\nresolutions = [2, 3]\n"));
  const fs::path out = fs::temp_directory_path() / ("kerf_test_study_sweep_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const StudyResult r = run_study(spec, out, {});
  ASSERT_EQ(r.rows.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    const int n = 2 + k;
    EXPECT_EQ(r.rows[k].model, "springs [N = " + std::to_string(n) + "]");
    EXPECT_GT(r.rows[k].cost.steps, 0u) << r.rows[k].note;
    ASSERT_TRUE(fs::exists(r.rows[k].profile));
    std::ifstream manifest(r.rows[k].profile.parent_path() / "manifest.json");
    std::stringstream text;
    text << manifest.rdbuf();
    EXPECT_NE(text.str().find("\"cells_per_side\": " + std::to_string(n)), std::string::npos) << text.str().substr(0, 400);
  }
  // Both are drawn, by their labels (which hold "="), in the scene's profile plot.
  write_study_report(spec, r, out);
  std::ifstream plotted(out / "clay_pull_profiles.csv");
  std::stringstream data;
  data << plotted.rdbuf();
  for (const char* label : {",springs [N = 2],", ",springs [N = 3],"}) EXPECT_NE(data.str().find(label), std::string::npos) << label;
  fs::remove_all(out);
}

TEST(StudySpec, TheFullStudyVerifiesItsReferenceAndSweepsTheSprings) {
  // experiments/studies/full.toml: three mesh levels (the GCI needs three) and a resolution curve.
  const StudySpec s = read_study(fs::path(KERF_STUDIES_DIR) / "full.toml");
  ASSERT_TRUE(s.has_reference);
  EXPECT_GE(s.reference.refinements.size(), 3u);
  ASSERT_TRUE(s.resolutions.count("springs"));
  EXPECT_GE(s.resolutions.at("springs").size(), 2u);
}

namespace kerf {
namespace {

TEST(CostTiming, TheMedianOfTheRunsAndTheSpreadOfTheirP99) {
  // Five runs of 200 steps; run r costs (r + 1) µs per step except its two slowest steps, 50 µs.
  // Each run's p99 over 200 steps (the nearest-rank 99th percentile, run_model.hpp) is (r + 1) µs,
  // its median (r + 1) µs and its max 50 µs; runs in the order 3, 1, 5, 2, 4 µs.
  const int order[] = {2, 0, 4, 1, 3};
  int call = 0;
  const auto run = [&] {
    const double c = (order[call++] + 1) * 1e-6;
    ForceProfile p;
    for (int k = 0; k < 200; ++k) {
      ProfileRow row;
      row.tool = "blade";
      row.t = k * 1e-3;
      row.cost_s = k < 2 ? 50e-6 : c;
      p.rows.push_back(row);
    }
    return p;
  };
  const ForceProfile scored = run();
  call = 0;
  const TimedCost t = time_model_runs(run, 5, &scored);
  EXPECT_EQ(t.runs, 5);
  EXPECT_EQ(t.steps, 200u);
  EXPECT_DOUBLE_EQ(t.p99, 3e-6);
  EXPECT_DOUBLE_EQ(t.p99_low, 1e-6);
  EXPECT_DOUBLE_EQ(t.p99_high, 5e-6);
  EXPECT_DOUBLE_EQ(t.median, 3e-6);
  EXPECT_DOUBLE_EQ(t.max, 50e-6);
  EXPECT_NEAR(t.p99_spread(), 4.0 / 3.0, 1e-15);
  EXPECT_TRUE(t.reproduces_scored_run); // the forces (zero) are the scored run's
  EXPECT_THROW(time_model_runs(run, 0), std::invalid_argument);
}

TEST(CostTiming, ModelsAreTimedInTurn) {
  // Two models, three rounds: the calls go A, B, A, B, A, B (a slow spell of the machine falls on
  // one run of each, not on every run of one), and each model's summary is the one
  // time_model_runs gives for its own runs. Model A's second run is slow throughout (a spell):
  // its median over the runs leaves it out.
  std::vector<std::string> calls;
  const auto profile = [](double cost) {
    ForceProfile p;
    for (int k = 0; k < 100; ++k) {
      ProfileRow row;
      row.tool = "blade";
      row.t = k * 1e-3;
      row.cost_s = cost;
      p.rows.push_back(row);
    }
    return p;
  };
  int a_runs = 0;
  const std::vector<TimedModel> models{
      {[&] {
         calls.push_back("A");
         return profile(++a_runs == 2 ? 90e-6 : 2e-6);
       },
       nullptr},
      {[&] {
         calls.push_back("B");
         return profile(7e-6);
       },
       nullptr}};
  std::vector<int> rounds;
  const std::vector<TimedCost> t = time_models_in_turn(models, 3, [&](int round, double seconds) {
    rounds.push_back(round);
    EXPECT_GE(seconds, 0.0);
  });
  EXPECT_EQ(calls, (std::vector<std::string>{"A", "B", "A", "B", "A", "B"}));
  EXPECT_EQ(rounds, (std::vector<int>{1, 2, 3}));
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0].runs, 3);
  EXPECT_DOUBLE_EQ(t[0].p99, 2e-6);
  EXPECT_DOUBLE_EQ(t[0].p99_high, 90e-6);
  EXPECT_DOUBLE_EQ(t[1].p99, 7e-6);
  EXPECT_DOUBLE_EQ(t[1].p99_spread(), 0.0);
  EXPECT_THROW(time_models_in_turn(models, 0), std::invalid_argument);
}

TEST(CostTiming, AShortTrajectoryIsPassedAgainWithinARun) {
  // A run passes at least timing_min_steps (5000) steps: ⌈5000 / steps⌉ passes — the sponge knife
  // cut's 1341 steps 4 passes, clay_pull's 2601 two, a potato cut's 22 501 one.
  EXPECT_EQ(timing_min_steps, 5000u);
  EXPECT_EQ(passes_per_timed_run(1341), 4);
  EXPECT_EQ(passes_per_timed_run(2601), 2);
  EXPECT_EQ(passes_per_timed_run(5000), 1);
  EXPECT_EQ(passes_per_timed_run(22501), 1);
  // Three passes of 100 steps pool into one run of 300: pass p costs (p + 1) µs per step except
  // its first step, 40 µs. Pooled, the 3 slow steps are the 3 largest of 300, so the nearest-rank
  // p99 (index round(0.99 × 299) = 296 of the sorted 300) is the 297th smallest: a 3 µs step; a
  // pass alone would give its 1 slow step at index 98 of 100 → its own (p + 1) µs.
  int pass = 0;
  const TimedModel model{[&] {
                           ForceProfile p;
                           const double c = (pass % 3 + 1) * 1e-6;
                           for (int k = 0; k < 100; ++k) {
                             ProfileRow row;
                             row.tool = "blade";
                             row.t = k * 1e-3;
                             row.cost_s = k == 0 ? 40e-6 : c;
                             p.rows.push_back(row);
                           }
                           ++pass;
                           return p;
                         },
                         nullptr, 3};
  const std::vector<TimedCost> t = time_models_in_turn({model}, 2);
  EXPECT_EQ(pass, 6); // 2 runs × 3 passes
  EXPECT_EQ(t[0].steps, 300u);
  EXPECT_DOUBLE_EQ(t[0].p99, 3e-6);
  EXPECT_DOUBLE_EQ(t[0].median, 2e-6);
  EXPECT_DOUBLE_EQ(t[0].max, 40e-6);
}

TEST(StudyRunner, TheCostColumnsComeFromATimingPassOfTheirOwn) {
  // A study without a reference (costs only): the fracture model on potato_rect_cut, timed three
  // times after its scored run. Its row carries the timing pass's statistics, every timed run
  // reproduced the scored forces (the model does not depend on the clock), and the table's caption
  // says how the costs were measured.
  const StudySpec spec = read_study(write_study("timing.toml", "[study]\nname = \"timing\"\nscenes = [\"potato_rect_cut\"]\n"
                                                               "models = [\"fracture\"]\n"));
  const fs::path out = fs::temp_directory_path() / ("kerf_test_study_timing_" + std::to_string(::getpid()));
  fs::remove_all(out);
  StudyExecution execution;
  execution.timing_runs = 3;
  const StudyResult r = run_study(spec, out, {}, execution);
  ASSERT_EQ(r.rows.size(), 1u);
  ASSERT_TRUE(r.rows[0].timed.has_value());
  const TimedCost& t = *r.rows[0].timed;
  EXPECT_EQ(t.runs, 3);
  EXPECT_EQ(t.steps, r.rows[0].cost.steps); // every step of the trajectory, as in the scored run
  EXPECT_TRUE(t.reproduces_scored_run);
  EXPECT_LE(t.p99_low, t.p99);
  EXPECT_LE(t.p99, t.p99_high);
  EXPECT_EQ(r.timing_runs, 3);
  EXPECT_NE(r.table().markdown().find("each model timed alone after every other run of the study, the models in turn (3 runs each"), std::string::npos);
  fs::remove_all(out);
}

TEST(StudyRunner, TheAccuracyIsReportedBeforeTheTimingPass) {
  // StudyExecution::scored is called once, before the timing pass (no row timed yet), with every
  // error the final table holds: the same metrics row by row, the accuracy table the study table
  // without its five cost columns. The stand-in reference is the fracture model's own profile.
  const StudySpec spec = read_study(write_study("scored.toml", "[study]\nname = \"scored\"\nscenes = [\"potato_rect_cut\"]\n"
                                                               "models = [\"fracture\", \"edge\"]\n[reference]\nrefinements = [0]\nsamples = 8\n"
                                                               "time_verification = false\n"));
  const fs::path out = fs::temp_directory_path() / ("kerf_test_study_scored_" + std::to_string(::getpid()));
  fs::remove_all(out);
  std::atomic<int> solves{0};
  StudyExecution execution;
  execution.timing_runs = 1;
  int calls = 0;
  StudyResult scored;
  execution.scored = [&](const StudyResult& s) {
    ++calls;
    scored = s;
  };
  const StudyResult r = run_study(spec, out, fracture_as_reference(solves, 300.0), execution);
  EXPECT_EQ(calls, 1);
  ASSERT_EQ(scored.rows.size(), r.rows.size());
  int scored_models = 0;
  for (std::size_t k = 0; k < r.rows.size(); ++k) {
    SCOPED_TRACE(r.rows[k].model);
    EXPECT_EQ(scored.rows[k].model, r.rows[k].model);
    EXPECT_FALSE(scored.rows[k].timed.has_value()); // before the timing pass
    ASSERT_EQ(scored.rows[k].metrics.has_value(), r.rows[k].metrics.has_value());
    if (!r.rows[k].metrics) continue;
    EXPECT_EQ(scored.rows[k].metrics->normalised_rms_force_error, r.rows[k].metrics->normalised_rms_force_error);
    EXPECT_EQ(scored.rows[k].metrics->work_error, r.rows[k].metrics->work_error);
    if (r.rows[k].model.rfind("reference", 0) != 0) {
      EXPECT_TRUE(r.rows[k].timed.has_value());
      ++scored_models;
    }
  }
  EXPECT_EQ(scored_models, 2);
  const StudyTable accuracy = scored.accuracy_table(), full = r.table();
  EXPECT_EQ(accuracy.columns().size() + 5, full.columns().size());
  EXPECT_EQ(accuracy.markdown().find("p99 cost"), std::string::npos);
  EXPECT_EQ(accuracy.row_count(), full.row_count());
  fs::remove_all(out);
}

TEST(StudyRunner, TheFinestLevelAtHalfTheIncrementGivesTheSamplingUncertainty) {
  // The stand-in reference is the fracture model's profile at the solved samples; at half the load
  // increment it is offset by 10 mN along x at every sample. The half-increment run solves 2N − 1
  // samples, the N of the first among them: the sampling uncertainty — the time-weighted RMS of the
  // two profiles' difference at their common times — is 10 mN exactly, the half-increment row's
  // RMS error 10 mN over the peak, and with one mesh level (no GCI) the reference's uncertainty is
  // that alone.
  const StudySpec spec = read_study(write_study("time.toml", "[study]\nname = \"time\"\nscenes = [\"potato_rect_cut\"]\n"
                                                             "models = [\"fracture\"]\n[reference]\nrefinements = [0]\nsamples = 8\n"));
  const fs::path out = fs::temp_directory_path() / ("kerf_test_study_time_" + std::to_string(::getpid()));
  fs::remove_all(out);
  std::atomic<int> solves{0};
  const ReferenceRunner truth = fracture_as_reference(solves, 300.0);
  std::vector<std::size_t> whole, half;
  const ReferenceRunner offset = [&](const StudyReferenceSolve& solve, const StudyReferenceSpec& settings) -> ReferenceResult {
    ForceProfile p = truth(solve, settings).profile;
    if (solve.increment == LoadIncrement::half) {
      half = solve.indices;
      for (ProfileRow& row : p.rows) row.force.x() += 0.01;
    } else {
      whole = solve.indices;
    }
    return p;
  };
  StudyExecution execution;
  execution.timing_runs = 1;
  const StudyResult r = run_study(spec, out, offset, execution);
  EXPECT_EQ(r.reference_runs, 2);
  ASSERT_EQ(whole.size(), 8u);
  ASSERT_EQ(half.size(), 15u);
  EXPECT_TRUE(std::includes(half.begin(), half.end(), whole.begin(), whole.end()));
  ASSERT_EQ(r.references.size(), 1u);
  ASSERT_TRUE(r.references[0].sampling.has_value());
  const SamplingVerification& v = *r.references[0].sampling;
  EXPECT_EQ(v.samples, 8u);
  EXPECT_NEAR(v.rms_difference, 0.01, 1e-12);
  // The uncertainty is the larger of that and the shift of the time-averaged RMS |F| between the
  // runs (the 15 samples weigh the fracture profile's time otherwise than the 8).
  EXPECT_GT(v.rms_shift, 0.0);
  ASSERT_TRUE(r.references[0].uncertainty().has_value());
  EXPECT_DOUBLE_EQ(*r.references[0].uncertainty(), std::max(0.01, v.rms_shift));
  EXPECT_NEAR(v.uncertainty(), std::max(v.rms_difference, v.rms_shift), 1e-15);
  EXPECT_NE(r.rows[0].note.find("sampling uncertainty"), std::string::npos) << r.rows[0].note;
  ASSERT_GE(r.rows.size(), 3u);
  EXPECT_EQ(r.rows[1].model, "reference L0 (half increment)");
  ASSERT_TRUE(r.rows[1].metrics.has_value()) << r.rows[1].note;
  EXPECT_NEAR(r.rows[1].metrics->normalised_rms_force_error * r.rows[1].metrics->reference_peak_force, 0.01, 1e-12);
  EXPECT_EQ(r.rows[2].model, "fracture");
  // The model is the reference itself: its error (zero) is below the reference's uncertainty.
  EXPECT_TRUE(r.rows[2].rms_below_reference_uncertainty);
  // Per phase: a table with the fracture row, its error zero in every phase (no dominant phase).
  const std::string phases = r.phase_table().markdown();
  EXPECT_NE(phases.find("| potato_rect_cut | fracture |"), std::string::npos) << phases;
  fs::remove_all(out);
}

} // namespace
} // namespace kerf

namespace kerf {
namespace {

TEST(StudyRunner, TheTableIsBuiltFromTheResultsInMemoryNotFromTheRecords) {
  // The runs' records cannot be written: the scene's folder under the study's output is a file
  // (which no process can make a folder of, root included). The reference cache is writable (the
  // cache is the cache); every model run records nothing. The table is built from the results in
  // memory all the same: the fracture row is scored (the stand-in reference is the model itself:
  // zero error) and timed, and its note says its record was not written.
  const StudySpec spec = read_study(write_study("memory.toml", "[study]\nname = \"memory\"\nscenes = [\"potato_rect_cut\"]\n"
                                                               "models = [\"fracture\"]\n[reference]\nrefinements = [0]\nsamples = 8\n"
                                                               "time_verification = false\n"));
  const fs::path out = fs::temp_directory_path() / ("kerf_test_study_memory_" + std::to_string(::getpid()));
  fs::remove_all(out);
  fs::create_directories(out);
  std::ofstream(out / "potato_rect_cut") << "not a folder\n";
  std::atomic<int> solves{0};
  StudyExecution execution;
  execution.timing_runs = 2;
  const StudyResult r = run_study(spec, out, fracture_as_reference(solves, 300.0), execution);
  ASSERT_EQ(r.rows.size(), 2u);
  EXPECT_EQ(r.rows[0].model, "reference L0");
  const StudyRow& model = r.rows[1];
  EXPECT_EQ(model.model, "fracture");
  ASSERT_TRUE(model.metrics.has_value()) << model.note;
  EXPECT_NEAR(model.metrics->normalised_rms_force_error, 0.0, 1e-12);
  ASSERT_TRUE(model.timed.has_value());
  EXPECT_EQ(model.timed->runs, 2);
  EXPECT_NE(model.note.find("its record was not written"), std::string::npos) << model.note;
  EXPECT_TRUE(model.profile.empty());
  EXPECT_FALSE(fs::is_directory(out / "potato_rect_cut"));
  fs::remove_all(out);
}

} // namespace
} // namespace kerf
