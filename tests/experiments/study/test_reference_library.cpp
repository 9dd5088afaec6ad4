// The default study's reference library (experiments/references/, [reference] library in
// experiments/studies/default.toml): every entry is one of the solves the study plans, under its
// current key, and re-solving the entry's first samples now gives the forces it holds.
//
// The expected values come from the library itself, written by `kerf study default
// --publish-references`: the re-solve runs the same code on the same mesh and samples, so it
// agrees to the Newton tolerance (|R| <= 1e-9 (|f_int| + |f_ext|), SolverSettings); the check
// allows 1e-6 of the entry's peak force, far below any mesh-level difference the study reports
// and far above round-off. A stale entry (a scene, mesh rule or solver version changed since it
// was published) is named with the command that re-publishes the library.

#include "experiments/profile/force_profile.hpp"
#include "realtime/blas_threads.hpp"
#include "experiments/study/study_runner.hpp"
#include "experiments/study/study_spec.hpp"

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
    if (!e.is_directory()) continue;
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

TEST(ReferenceLibrary, FirstSamplesOfEveryEntryResolveToItsForces) {
  limit_blas_to_one_thread();
  const StudySpec spec = read_study(default_study);
  const fs::path work = fs::temp_directory_path() / ("kerf_library_resolve_" + std::to_string(::getpid()));
  const ReferenceRunner solve = finite_element_reference();
  int checked = 0;
  for (const StudyReferenceSolve& s : study_reference_solves(spec, work)) {
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
    const ForceProfile again = solve(s.scene, spec.reference, s.level, first, work / s.dir.filename());
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

} // namespace
} // namespace kerf
