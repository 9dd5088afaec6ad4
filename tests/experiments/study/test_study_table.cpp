// StudyTable's three forms against hand-written expected text.

#include "experiments/study/study_table.hpp"
#include "experiments/study/machine_label.hpp"

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
                               "model & RMS error [\\%] & p99 cost [\\textmu{}s] \\\\\n\\midrule\n"
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

TEST(StudyTable, GroupsByTheFirstColumnTextInANumericColumnAndACaption) {
  // Rows of two scenes: LaTeX rules off each scene's group and names the scene once; a numeric
  // column may hold text ("below reference uncertainty") and stays right-aligned; the
  // caption (the machine of the cost columns) precedes the table in Markdown (the file still ends
  // with the last row), follows it in LaTeX, and is not in CSV.
  StudyTable t({{"scene", "", 3, 1.0}, {"model", "", 3, 1.0}, {"RMS error", "%", 3, 100.0}});
  t.add_row({std::string("a"), std::string("reference L1"), std::optional<double>()});
  t.add_row({std::string("a"), std::string("springs"), std::string("below reference uncertainty")});
  t.add_row({std::string("b"), std::string("edge"), std::optional<double>(0.5)});
  t.set_caption("Costs on: Test CPU, 2 cores");
  t.group_by_first_column(true);
  EXPECT_EQ(t.markdown(), "Costs on: Test CPU, 2 cores\n\n"
                          "| scene | model | RMS error [%] |\n"
                          "|---|---|---:|\n"
                          "| a | reference L1 | – |\n"
                          "| a | springs | below reference uncertainty |\n"
                          "| b | edge | 50 |\n");
  EXPECT_EQ(t.latex(), "\\begin{tabular}{llr}\n\\toprule\n"
                       "scene & model & RMS error [\\%] \\\\\n\\midrule\n"
                       "a & reference L1 & -- \\\\\n"
                       " & springs & below reference uncertainty \\\\\n"
                       "\\midrule\n"
                       "b & edge & 50 \\\\\n"
                       "\\bottomrule\n"
                       "\\multicolumn{3}{l}{\\footnotesize Costs on: Test CPU, 2 cores} \\\\\n"
                       "\\end{tabular}\n");
  EXPECT_EQ(t.csv(), "scene,model,RMS error [%]\na,reference L1,\na,springs,below reference uncertainty\nb,edge,50\n");
  // A "|" in a cell ("GCI on RMS |F|") is escaped in Markdown, or it would end the cell.
  StudyTable pipes({{"note", "", 3, 1.0}});
  pipes.add_row({std::string("GCI 1 % on RMS |F|")});
  EXPECT_EQ(pipes.markdown(), "| note |\n|---|\n| GCI 1 % on RMS \\|F\\| |\n");
}

TEST(MachineLabel, ReadsTheCpuModelFromCpuinfo) {
  // Two excerpts in the kernel's /proc/cpuinfo format: x86 ("model name") and an older ARM kernel
  // ("Processor", "Hardware"); a text without either names no model.
  EXPECT_EQ(cpu_model_name("processor\t: 0\nvendor_id\t: GenuineIntel\nmodel name\t: Intel(R) Xeon(R) CPU @ 2.20GHz\n"
                           "processor\t: 1\nmodel name\t: Intel(R) Xeon(R) CPU @ 2.20GHz\n"),
            "Intel(R) Xeon(R) CPU @ 2.20GHz");
  EXPECT_EQ(cpu_model_name("Processor\t: ARMv7 Processor rev 4 (v7l)\nHardware\t: BCM2835\n"), "BCM2835");
  EXPECT_EQ(cpu_model_name("processor\t: 0\n"), "");
  EXPECT_NE(machine_label().find(" core"), std::string::npos);
}
