// The study runner's pieces: study files (errors name file:line:column), the reference's sample
// selection, subsampling, and a run of two scenes end to end.

#include "experiments/study/study_runner.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

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
                                                        "refinements = [0, 1, 2]\nsamples = 12\n"));
  EXPECT_EQ(s.name, "t");
  ASSERT_EQ(s.scenes.size(), 1u);
  EXPECT_EQ(s.scenes[0].filename(), "potato_rect_cut.toml");
  EXPECT_TRUE(s.has_reference);
  EXPECT_EQ(s.reference.degree, 2);
  EXPECT_EQ(s.reference.refinements, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(s.reference.samples, 12);
}

TEST(StudySpec, ErrorsNameFileLineColumnAndKey) {
  const std::pair<std::string, std::string> cases[] = {
      {"[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\"]\ncolour = 1\n", ":5:10: study.colour"},
      {"[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"no_model\"]\n", ":4:"},
      {"[study]\nname = \"t\"\nscenes = [\"no_scene\"]\nmodels = [\"fracture\"]\n", ":3:"},
      {"[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\"]\n[reference]\ndegree = 3\n",
       ":6:10: reference.degree"},
      {"[study]\nname = \"t\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\"]\n[reference]\nrefinements = [-1]\n",
       ":6:16: reference.refinements"},
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
                  "models = [\"springs\", \"fracture\"]\n[reference]\ndegree = 1\nrefinements = [0]\nsamples = 4\n"));
  const fs::path out = fs::temp_directory_path() / ("kerf_test_study_e2e_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const StudyResult first = run_study(spec, out, finite_element_reference());
  EXPECT_EQ(first.reference_runs, 2);
  bool scored = false;
  for (const StudyRow& row : first.rows) {
    if (row.scene == "clay_pull" && row.model == "springs") {
      ASSERT_TRUE(row.metrics.has_value()) << row.note;
      EXPECT_TRUE(std::isfinite(row.metrics->normalised_rms_force_error));
      EXPECT_EQ(row.metrics->samples, 4u);
      scored = true;
    }
    if (row.scene == "potato_wedge_cut") {
      EXPECT_EQ(row.model, "fracture");
    }
  }
  EXPECT_TRUE(scored);
  const StudyResult second = run_study(spec, out, finite_element_reference());
  EXPECT_EQ(second.reference_runs, 0);
  ASSERT_EQ(second.rows.size(), first.rows.size());
  for (std::size_t k = 0; k < first.rows.size(); ++k) {
    if (first.rows[k].metrics && second.rows[k].metrics) {
      EXPECT_EQ(first.rows[k].metrics->normalised_rms_force_error, second.rows[k].metrics->normalised_rms_force_error);
    }
  }
}
