// kerf recommend's choice on a synthetic study table whose answer is known by construction.

#include "experiments/study/model_recommendation.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include <unistd.h>

using namespace kerf;
namespace fs = std::filesystem;

namespace {

/// A table in study.csv's form: errors in %, costs in µs. By construction, for potato within 10 %
/// at 1 kHz (1000 µs): "slow" is accurate but too slow, "crude" is fast but 40 % off, "good" (200
/// µs, 8 %) and "best" (90 µs, 9.5 %) both fit — "best" is the cheapest. The reference row is
/// cheaper still but is not a fast model.
fs::path synthetic_table() {
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_recommend_" + std::to_string(::getpid())) / "s";
  fs::create_directories(dir);
  std::ofstream(dir / "study.csv")
      << "scene,model,RMS force error [%],peak force error [%],p99 cost [µs],rate allowed [kHz],note\n"
         "potato,reference L0,2,1,1,1000,\n"
         "potato,slow,1.5,0,2500,0.4,\n"
         "potato,crude,40,3,5,200,\n"
         "potato,good,8,1,200,5,\n"
         "potato,best,9.5,1,90,11.1,\"a note, with a comma\"\n"
         "potato,unscored,,,,,\"not scored: no reference force\"\n"
         "clay,springs,30,1,100,10,\n";
  return dir / "study.csv";
}

} // namespace

TEST(Recommend, ChoosesTheCheapestRowWithinBothBudgets) {
  const auto rows = read_study_rows(synthetic_table());
  ASSERT_EQ(rows.size(), 7u);
  EXPECT_EQ(rows[4].line, 6u);
  const Recommendation r = recommend_model(rows, "potato", 0.10, 1000.0);
  ASSERT_TRUE(r.choice.has_value()) << r.reason;
  EXPECT_EQ(r.choice->model, "best");
  EXPECT_EQ(r.choice->text, "potato,best,9.5,1,90,11.1,\"a note, with a comma\"");
  // Tighter: within 9 % only "slow" and "good" remain; at 1 kHz "good" (200 µs) fits.
  EXPECT_EQ(recommend_model(rows, "potato", 0.09, 1000.0).choice->model, "good");
  // At 10 kHz (100 µs) within 9 %: "good" is too slow, "slow" too — none.
  const Recommendation none = recommend_model(rows, "potato", 0.09, 10000.0);
  EXPECT_FALSE(none.choice.has_value());
  EXPECT_NE(none.reason.find("most accurate, slow"), std::string::npos) << none.reason;
  EXPECT_NE(none.reason.find("cheapest, crude"), std::string::npos) << none.reason;
  // A scene with no scored row says so.
  EXPECT_FALSE(recommend_model(rows, "liver", 0.5, 1000.0).choice.has_value());
}

TEST(Recommend, FindsTablesAndRejectsMalformedOnes) {
  const fs::path table = synthetic_table();
  const auto found = find_study_tables(table.parent_path().parent_path());
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found.front(), table);
  std::ofstream(table.parent_path() / "bad.csv") << "scene,model,p99 cost [µs]\npotato,x,1\n";
  EXPECT_THROW(read_study_rows(table.parent_path() / "bad.csv"), std::runtime_error);
  std::ofstream(table.parent_path() / "bad2.csv") << "scene,model,RMS force error [%],p99 cost [µs]\npotato,x,abc,1\n";
  try {
    read_study_rows(table.parent_path() / "bad2.csv");
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad2.csv:2:"), std::string::npos) << e.what();
  }
}

TEST(Recommend, AnErrorBelowTheReferenceUncertaintyMeetsTheBudget) {
  // A row whose error the reference cannot resolve ("below reference uncertainty", study_runner.hpp)
  // meets any error budget: at 1 kHz within 5 % it is the only choice; cheaper rows that err more lose.
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_recommend_below_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "study.csv") << "scene,model,RMS force error [%],p99 cost [µs],note\n"
                                      "potato,reference L1,,3000,GCI 1 %\n"
                                      "potato,fine,below reference uncertainty,400,\n"
                                      "potato,coarse,12,50,\n";
  const auto rows = read_study_rows(dir / "study.csv");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_TRUE(rows[1].below_reference_uncertainty);
  const Recommendation r = recommend_model(rows, "potato", 0.05, 1000.0);
  ASSERT_TRUE(r.choice.has_value()) << r.reason;
  EXPECT_EQ(r.choice->model, "fine");
  EXPECT_NE(r.reason.find("below the reference's uncertainty"), std::string::npos) << r.reason;
  EXPECT_EQ(recommend_model(rows, "potato", 0.15, 1000.0).choice->model, "coarse"); // cheaper, within 15 %
  std::filesystem::remove_all(dir);
}

TEST(Recommend, AnswersFromAModelsResolutionCurve) {
  // A model at three resolutions ([models.springs] resolutions, one row each): error falls and cost
  // rises with N. Within 10 % at 1 kHz, N = 4 errs too much and N = 12 is too slow: N = 8.
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_recommend_curve_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "study.csv") << "scene,model,RMS force error [%],p99 cost [µs],note\n"
                                      "clay,springs [N = 4],12,50,\n"
                                      "clay,springs [N = 8],6,400,\n"
                                      "clay,springs [N = 12],4,1500,\n";
  const auto rows = read_study_rows(dir / "study.csv");
  EXPECT_EQ(recommend_model(rows, "clay", 0.10, 1000.0).choice->model, "springs [N = 8]");
  EXPECT_EQ(recommend_model(rows, "clay", 0.15, 10000.0).choice->model, "springs [N = 4]"); // 100 µs budget
  EXPECT_EQ(recommend_model(rows, "clay", 0.05, 500.0).choice->model, "springs [N = 12]");  // 2 ms budget
  std::filesystem::remove_all(dir);
}
