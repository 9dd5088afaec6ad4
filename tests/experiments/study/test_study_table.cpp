// StudyTable's three forms against hand-written expected text.

#include "experiments/study/study_table.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

using namespace kerf;

namespace {
StudyTable example() {
  StudyTable t({{"model", "", 3, 1.0}, {"RMS error", "%", 3, 100.0}, {"p99 cost", "µs", 2, 1e6}});
  t.add_row({std::string("fracture"), std::optional<double>(0.0123456), std::optional<double>(4.16e-6)});
  t.add_row({std::string("springs_a&b"), std::optional<double>(), std::optional<double>(1.5e-4)});
  return t;
}
} // namespace

TEST(StudyTable, Markdown) {
  EXPECT_EQ(example().markdown(), "| model | RMS error [%] | p99 cost [µs] |\n"
                                  "|---|---:|---:|\n"
                                  "| fracture | 1.23 | 4.2 |\n"
                                  "| springs_a&b | – | 1.5e+02 |\n");
}

TEST(StudyTable, LatexBooktabsEscapesText) {
  EXPECT_EQ(example().latex(), "\\begin{tabular}{lrr}\n\\toprule\n"
                               "model & RMS error [\\%] & p99 cost [µs] \\\\\n\\midrule\n"
                               "fracture & 1.23 & 4.2 \\\\\n"
                               "springs\\_a\\&b & -- & 1.5e+02 \\\\\n"
                               "\\bottomrule\n\\end{tabular}\n");
}

TEST(StudyTable, CsvKeepsFullPrecision) {
  std::istringstream csv(example().csv());
  std::string header, first, second;
  std::getline(csv, header);
  std::getline(csv, first);
  std::getline(csv, second);
  EXPECT_EQ(header, "model,RMS error [%],p99 cost [µs]");
  // Full precision: each number reads back as exactly the stored value times the column scale.
  EXPECT_EQ(first.substr(0, 9), "fracture,");
  const std::string rms = first.substr(9, first.find(',', 9) - 9), cost = first.substr(first.rfind(',') + 1);
  EXPECT_EQ(std::stod(rms), 0.0123456 * 100.0);
  EXPECT_EQ(std::stod(cost), 4.16e-6 * 1e6);
  EXPECT_EQ(second, "springs_a&b,,150"); // the unmeasured cell is empty
}

TEST(StudyTable, RowsMustMatchColumnsAndFilesAreWritten) {
  StudyTable t = example();
  EXPECT_THROW(t.add_row({std::string("x")}), std::invalid_argument);
  const auto dir = std::filesystem::temp_directory_path() / "kerf_test_study_table";
  std::filesystem::remove_all(dir);
  t.write(dir, "results");
  for (const char* ext : {".md", ".tex", ".csv"}) EXPECT_TRUE(std::filesystem::exists(dir / (std::string("results") + ext)));
  std::ifstream md(dir / "results.md");
  std::stringstream text;
  text << md.rdbuf();
  EXPECT_EQ(text.str(), t.markdown());
}
