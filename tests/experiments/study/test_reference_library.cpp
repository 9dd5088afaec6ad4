// The default study's reference library (experiments/references/, [reference] library in
// experiments/studies/default.toml): every entry is one of the solves the study plans, under its
// current key, and re-solving the first samples of each scene's coarsest-level entries now gives
// the forces they hold.
//
// The expected values come from the library itself, written by `kerf study default
// --publish-references`: the re-solve runs the same code on the same mesh and samples, so it
// agrees to the Newton tolerance (|R| <= 1e-9 (|f_int| + |f_ext|), SolverSettings); the check
// allows 1e-6 of the entry's peak force, far below any mesh-level difference the study reports
// and far above round-off. A stale entry (a scene, mesh rule or solver version changed since it
// was published) is named with the command that re-publishes the library.

#include "formats/profile/force_profile.hpp"
#include "realtime/blas_threads.hpp"
#include "experiments/study/study_runner.hpp"
#include "experiments/study/study_spec.hpp"
#include "experiments/calibration/calibration.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include <unistd.h>

namespace kerf {
namespace {

namespace fs = std::filesystem;

const fs::path default_study = fs::path(KERF_SOURCE_DIR) / "experiments" / "studies" / "default.toml";
const char* republish = "re-publish the library: kerf study default --publish-references (docs/studies.md, \"Reference library\")";

std::string read_text(const fs::path& file) {
  std::ifstream f(file);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

/// |F| of every row, by (tool, time).
std::map<std::pair<std::string, double>, double> force_by_row(const ForceProfile& p) {
  std::map<std::pair<std::string, double>, double> f;
  for (const ProfileRow& r : p.rows) f[{r.tool, r.t}] = r.force.norm();
  return f;
}

TEST(ReferenceLibrary, EveryEntryIsAPlannedSolveUnderItsCurrentKey) {
  const StudySpec spec = read_study(default_study);
  ASSERT_FALSE(spec.reference.library.empty()) << default_study << " names no [reference] library";
  ASSERT_TRUE(fs::is_directory(spec.reference.library)) << spec.reference.library;
  std::map<std::string, std::string> planned; // directory name -> key text
  for (const StudyReferenceSolve& s : study_reference_solves(spec, fs::temp_directory_path() / "kerf_library_plan"))
    planned[s.dir.filename().string()] = s.key_text;
  int entries = 0;
  for (const auto& e : fs::directory_iterator(spec.reference.library)) {
    if (!e.is_directory() || e.path().filename() == "fits") continue; // fitted calibrations: below
    ++entries;
    const std::string name = e.path().filename().string();
    SCOPED_TRACE(name);
    const auto it = planned.find(name);
    ASSERT_NE(it, planned.end()) << "library entry " << e.path() << " is no solve the default study plans: " << republish;
    EXPECT_EQ(read_text(e.path() / "key.txt"), it->second) << republish;
    EXPECT_TRUE(fs::exists(e.path() / "profile.csv"));
  }
  EXPECT_GT(entries, 0) << "the library " << spec.reference.library << " is empty: " << republish;
}

// The entries on each scene's coarsest mesh level are re-solved: the same code (solver, tool
// coupling, fracture interface, load path) as on the finer levels, at a few seconds each, where
// every entry's first samples took ~770 s of the suite (the finest potato and sponge meshes,
// 28 000-45 000 tetrahedra). A finer entry whose key is stale fails the test above; one whose
// numbers moved with the code moves the coarse entries with it.
TEST(ReferenceLibrary, FirstSamplesOfEachScenesCoarsestEntriesResolveToTheirForces) {
  limit_blas_to_one_thread();
  const StudySpec spec = read_study(default_study);
  const fs::path work = fs::temp_directory_path() / ("kerf_library_resolve_" + std::to_string(::getpid()));
  const ReferenceRunner solve = finite_element_reference();
  const std::vector<StudyReferenceSolve> solves = study_reference_solves(spec, work);
  std::map<std::string, int> coarsest; // scene name -> its lowest planned level
  for (const StudyReferenceSolve& s : solves) {
    const auto [it, inserted] = coarsest.emplace(s.scene.name, s.level);
    if (!inserted) it->second = std::min(it->second, s.level);
  }
  int checked = 0;
  for (const StudyReferenceSolve& s : solves) {
    if (s.level != coarsest.at(s.scene.name)) continue;
    const fs::path entry = spec.reference.library / s.dir.filename();
    if (!fs::exists(entry / "profile.csv")) continue;
    SCOPED_TRACE(entry.string());
    // The samples up to the first one with a force (at least two): the tool's approach and its
    // first contact (the blade's, the grasp's first pull), a solve from the initial state through
    // the whole setup — mesh, materials, tool coupling, fracture interface — that the entry was
    // solved with. (Samples of a tool still in the air carry no force and would check nothing.)
    const ForceProfile kept = read_profile_csv(entry / "profile.csv");
    std::size_t count = 2;
    for (std::size_t k = 0; k < kept.rows.size() && k < s.indices.size(); ++k)
      if (kept.rows[k].force.norm() > 0.0) {
        count = std::max<std::size_t>(2, k + 1);
        break;
      }
    const std::vector<std::size_t> first(s.indices.begin(), s.indices.begin() + std::min(count, s.indices.size()));
    StudyReferenceSolve head = s;
    head.indices = first;
    head.dir = work / s.dir.filename();
    const ForceProfile again = solve(head, spec.reference).profile;
    double peak = 0.0;
    for (const ProfileRow& r : kept.rows) peak = std::max(peak, r.force.norm());
    const auto kept_force = force_by_row(kept);
    int compared = 0;
    for (const auto& [row, f] : force_by_row(again)) {
      const auto k = kept_force.find(row);
      ASSERT_NE(k, kept_force.end()) << "the re-solve has a row at t = " << row.second << " s the entry lacks";
      EXPECT_NEAR(f, k->second, 1e-6 * peak + 1e-9) << row.first << " at t = " << row.second << " s; " << republish;
      ++compared;
    }
    EXPECT_GE(compared, 2);
    EXPECT_GT(again.rows.back().force.norm(), 0.0) << "no sample with a force was re-solved";
    ++checked;
  }
  fs::remove_all(work);
  EXPECT_GT(checked, 0) << "no library entry to check";
}

// Every fitted calibration the library holds (library/fits/, written by --publish-references from
// the study's [[calibrate]] fits) is one the default study plans under its current key, and its
// parameters, run now on its calibration trajectory, give the fitted error it recorded against its
// target — the library's reference solve of that trajectory — to 1e-9 relative: the fast model
// computes what it computed when it was fitted. A model whose numbers changed fails here, naming
// the version to bump (study_fit_version) and the command that re-publishes.
TEST(ReferenceLibrary, EveryFitGivesItsRecordedErrorOnItsTarget) {
  const StudySpec spec = read_study(default_study);
  const fs::path work = fs::temp_directory_path() / ("kerf_library_fits_" + std::to_string(::getpid()));
  const StudyPlan plan = plan_study(spec, work);
  int checked = 0;
  for (const StudyFitRun& run : plan.fit_runs) {
    if (!run.reference) continue;
    const Scene& scene = plan.scenes[run.scene].scene;
    const StudyReferenceSolve& target = plan.solves[*run.reference];
    SCOPED_TRACE(scene.name + " " + run.fit.model);
    fs::path entry;
    if (fs::exists(spec.reference.library / "fits"))
      for (const auto& e : fs::directory_iterator(spec.reference.library / "fits"))
        if (e.path().filename().string().rfind(scene.name + "-" + run.fit.model + "-", 0) == 0) entry = e.path();
    ASSERT_FALSE(entry.empty()) << "the library holds no fit of " << run.fit.model << " on " << scene.name << ": " << republish;
    std::ifstream in(entry / "fit.json");
    const nlohmann::json record = nlohmann::json::parse(in);
    ASSERT_EQ(record.at("target").get<std::string>(), target.dir.filename().string()) << "the fit's target is no planned solve: " << republish;
    const ForceProfile target_profile = read_profile_csv(spec.reference.library / target.dir.filename() / "profile.csv");
    // As the fit evaluated it: the target's scene (the calibration trajectory at the finest level)
    // with the fitted parameters, the model built on the scene's own mesh (StudyRun::fit).
    const Scene fitted = read_scene(scene.file, {entry / "parameters.toml"});
    const Scene on_target = with_parameters(target.scene, scene_parameters(run.fit.model, fitted));
    const double error = profile_error(run.fit.model, on_target, scene_mesh(scene), target_profile);
    const double recorded = record.at("fitted_error").get<double>();
    // 1e-5 of the recorded error: the parameter file keeps 9 significant digits, and a spring
    // network solved to its Newton tolerance moves by that tolerance's order (clay_pull's springs:
    // 9e-7 relative) when a parameter moves in its 10th digit; a changed model moves it by percents.
    EXPECT_NEAR(error, recorded, 1e-5 * recorded)
        << "the fitted " << run.fit.model << " no longer gives its recorded error: bump study_fit_version (study_runner.hpp) and "
        << republish;
    ++checked;
  }
  EXPECT_EQ(checked, static_cast<int>(plan.fit_runs.size()));
  fs::remove_all(work);
}

} // namespace
} // namespace kerf
