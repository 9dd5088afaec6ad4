// A study with three reference levels, end to end without a finite-element solve: the stand-in
// reference converges as a power law in the element size, so its solution verification is known in
// closed form; the table's first row per scene carries the GCI, errors below it are not shown as
// numbers, and the plots' data (written beside each figure) hold the reference, its band and every
// model of the table.

#include "experiments/study/study_report.hpp"

#include "experiments/models/model_catalogue.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "experiments/study/study_runner.hpp"
#include "experiments/study/study_plots.hpp"
#include "formats/scene/scene_reader.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <unistd.h>

using namespace kerf;
namespace fs = std::filesystem;

namespace {

/// The fracture model's profile of the scene on its own mesh (2 mm), its forces scaled by
/// 1 + c (h / 2 mm)^2 at a level of element size h: RMS |F| and peak |F| follow f0 (1 + c (h/h0)^2)
/// exactly, a second-order convergence to the unscaled model (f0) as h -> 0.
constexpr double scale_at_h0 = 0.004;

ReferenceRunner power_law_reference() {
  return [](const StudyReferenceSolve& solve, const StudyReferenceSpec&) -> ReferenceResult {
    const Scene& scene = solve.scene;
    const std::vector<std::size_t>& indices = solve.indices;
    const double h = scene.geometry.element_size;
    Scene own = scene;
    own.geometry.element_size = 2e-3;
    const TetMesh mesh = scene_mesh(own);
    BuiltModel built = make_model("fracture", own, mesh);
    ForceProfile p = subsample(run_model(*built.model, {own.tools.front().name}, sample_scene_trajectories(own)), indices);
    for (ProfileRow& r : p.rows) r.force *= 1.0 + scale_at_h0 * (h / 2e-3) * (h / 2e-3);
    return p;
  };
}

fs::path write_file(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
  return path;
}

std::vector<std::map<std::string, std::string>> read_csv(const fs::path& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::string line;
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> fields(1);
    bool quoted = false;
    for (char c : line) {
      if (c == '"') quoted = !quoted;
      else if (c == ',' && !quoted) fields.emplace_back();
      else if (c != '\r') fields.back() += c;
    }
    if (header.empty()) {
      header = fields;
      continue;
    }
    std::map<std::string, std::string> row;
    for (std::size_t k = 0; k < header.size() && k < fields.size(); ++k) row[header[k]] = fields[k];
    rows.push_back(row);
  }
  return rows;
}

struct ThreeLevelStudy {
  StudySpec spec;
  fs::path out;
  StudyResult result;
};

/// potato_rect_cut at levels -2, -1, 0 (h = 8, 4, 2 mm), 40 samples (two or three within the rupture
/// deflection, so that f_r shows); the fracture model, and the
/// fracture model with f_r = 450 N/m instead of 300 (calibrated parameters) as a second row.
const ThreeLevelStudy& three_level_study() {
  static const ThreeLevelStudy study = [] {
    const fs::path dir = fs::temp_directory_path() / ("kerf_test_study_report_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    const fs::path parameters = write_file(dir / "f450.toml", "[models.fracture]\nrupture_force_per_length = \"450 N/m\"\n");
    ThreeLevelStudy s;
    s.spec = read_study(write_file(dir / "three.toml", "[study]\nname = \"three\"\nscenes = [\"potato_rect_cut\"]\nmodels = [\"fracture\"]\n"
                                                        "[reference]\nrefinements = [-2, -1, 0]\nsamples = 40\n"
                                                        "[calibration]\npotato_rect_cut = [\"" + parameters.string() + "\"]\n"));
    s.out = dir / "out";
    s.result = run_study(s.spec, s.out, power_law_reference());
    return s;
  }();
  return study;
}

} // namespace

TEST(StudyReport, ThreeLevelsGiveTheGciOnTheReferenceRow) {
  const StudyResult& r = three_level_study().result;
  ASSERT_EQ(r.references.size(), 1u);
  ASSERT_TRUE(r.references[0].verification.has_value()) << r.references[0].note;
  const ReferenceVerification& v = *r.references[0].verification;
  // The closed form: φ(h) = f0 (1 + c (h/h0)^2) on h = 2, 4, 8 mm: p = 2, φ_ext = f0 = φ1 / (1 + c),
  // GCI = Fs |φ1 - f0| / φ1 = Fs c / (1 + c), for RMS |F| and for peak |F| alike.
  EXPECT_EQ(v.levels, (std::array<int, 3>{0, -1, -2}));
  ASSERT_TRUE(v.rms.usable()) << v.rms.unusable;
  EXPECT_NEAR(*v.rms.observed_order, 2.0, 1e-9);
  EXPECT_NEAR(*v.rms.extrapolated, v.rms_force / (1.0 + scale_at_h0), 1e-9 * v.rms_force);
  EXPECT_NEAR(*v.rms.gci_fine, gci_safety_factor * scale_at_h0 / (1.0 + scale_at_h0), 1e-9);
  ASSERT_TRUE(v.peak.usable()) << v.peak.unusable;
  EXPECT_NEAR(*v.peak.observed_order, 2.0, 1e-9);
  EXPECT_EQ(v.samples, 40u);
  // The scene's first row is the finest reference, its note the verification.
  ASSERT_GE(r.rows.size(), 5u);
  EXPECT_EQ(r.rows[0].model, "reference L0");
  EXPECT_FALSE(r.rows[0].metrics.has_value());
  EXPECT_NE(r.rows[0].note.find("GCI 0.5 % on RMS |F|"), std::string::npos) << r.rows[0].note; // 1.25 × 0.004 / 1.004
  EXPECT_NE(r.rows[0].note.find("p = 2"), std::string::npos) << r.rows[0].note;
  EXPECT_EQ(r.rows[1].model, "reference L-2");
  EXPECT_EQ(r.rows[2].model, "reference L-1");
}

TEST(StudyReport, AnErrorBelowTheReferenceUncertaintyIsNotANumber) {
  // The plain fracture model is the reference's limit f0: its RMS difference to the finest level is
  // c f0 RMS, below the uncertainty Fs c / (1 + c) φ1 = Fs c f0 RMS. The calibrated model (f_r = 450
  // instead of 300 N/m) differs by far more than 0.5 %.
  const StudyResult& r = three_level_study().result;
  const StudyRow* plain = nullptr;
  const StudyRow* calibrated = nullptr;
  for (const StudyRow& row : r.rows) {
    if (row.model == "fracture") plain = &row;
    if (row.model == "fracture (calibrated)") calibrated = &row;
  }
  ASSERT_TRUE(plain && calibrated);
  ASSERT_TRUE(plain->metrics.has_value()) << plain->note;
  EXPECT_NEAR(plain->metrics->normalised_rms_force_error * plain->metrics->reference_peak_force,
              scale_at_h0 / (1.0 + scale_at_h0) * r.references[0].verification->rms_force, 1e-9);
  EXPECT_TRUE(plain->rms_below_reference_uncertainty);
  EXPECT_TRUE(plain->peak_below_reference_uncertainty);
  ASSERT_TRUE(calibrated->metrics.has_value()) << calibrated->note;
  EXPECT_FALSE(calibrated->rms_below_reference_uncertainty) << calibrated->metrics->normalised_rms_force_error;
  const std::string csv = r.table().csv(), md = r.table().markdown(), tex = r.table().latex();
  for (const std::string* form : {&csv, &md, &tex}) EXPECT_NE(form->find(below_reference_uncertainty), std::string::npos) << *form;
  EXPECT_NE(md.find("Costs: wall time per servo step on "), std::string::npos) << md; // the machine under the table
}

TEST(StudyReport, FewerThanThreeLevelsSayNoGciIsAvailable) {
  // Two levels: the coarser-level row as before, and the reference row saying why there is no GCI.
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_study_report2_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const StudySpec spec = read_study(write_file(dir / "two.toml", "[study]\nname = \"two\"\nscenes = [\"potato_rect_cut\"]\n"
                                                                 "models = [\"fracture\"]\n[reference]\nrefinements = [-1, 0]\nsamples = 6\n"
                                                                 "time_verification = false\n"));
  const StudyResult r = run_study(spec, dir / "out", power_law_reference());
  ASSERT_EQ(r.rows.size(), 3u);
  EXPECT_EQ(r.rows[0].model, "reference L0");
  EXPECT_NE(r.rows[0].note.find("no GCI available: 2 mesh level(s)"), std::string::npos) << r.rows[0].note;
  EXPECT_EQ(r.rows[1].model, "reference L-1");
  ASSERT_TRUE(r.rows[1].metrics.has_value());
  EXPECT_FALSE(r.rows[2].rms_below_reference_uncertainty);
  fs::remove_all(dir);
}

TEST(StudyReport, PlotsDrawTheReferenceWithItsBandAndEveryModel) {
  const ThreeLevelStudy& s = three_level_study();
  write_study_report(s.spec, s.result, s.out);
  for (const char* file : {"study.md", "study.tex", "study.csv", "verification.csv", "potato_rect_cut_profiles.png",
                           "potato_rect_cut_profiles.pdf", "potato_rect_cut_pareto.png"})
    EXPECT_TRUE(fs::exists(s.out / file)) << file;
  // The profile plot's data: the reference in both panels (potato_rect_cut holds, then retreats),
  // every sample with a band that holds the curve, of half-width U = Fs |f1 - f2| / (2^2 - 1) =
  // Fs (c/(1+c)) |f1| × 3 / 3 = Fs c / (1 + c) |f1| (the closed form); every model row of the table drawn.
  const auto rows = read_csv(s.out / "potato_rect_cut_profiles.csv");
  std::set<std::string> series;
  std::size_t reference_rows = 0;
  std::set<std::string> panels;
  for (const auto& row : rows) {
    series.insert(row.at("series"));
    panels.insert(row.at("panel"));
    if (row.at("series") != "reference L0") {
      EXPECT_TRUE(row.at("band_low").empty() && row.at("band_high").empty());
      continue;
    }
    ++reference_rows;
    ASSERT_FALSE(row.at("band_low").empty());
    const double y = std::stod(row.at("y")), low = std::stod(row.at("band_low")), high = std::stod(row.at("band_high"));
    const double u = gci_safety_factor * scale_at_h0 / (1.0 + scale_at_h0) * std::abs(y);
    EXPECT_NEAR(high - y, u, 1e-9 * (1.0 + std::abs(y)));
    EXPECT_NEAR(y - low, u, 1e-9 * (1.0 + std::abs(y)));
  }
  EXPECT_EQ(reference_rows, 2u * 40u); // 40 samples in each panel
  EXPECT_EQ(panels, (std::set<std::string>{"travel", "time"}));
  for (const StudyRow& row : s.result.rows)
    if (!row.profile.empty() && row.model.rfind("reference", 0) != 0) {
      EXPECT_TRUE(series.count(row.model)) << row.model;
    }
  EXPECT_TRUE(series.count("fracture (calibrated)"));
  // The speed/accuracy chart's data: a point per scored model, the reference floor, both budgets.
  const auto pareto = read_csv(s.out / "potato_rect_cut_pareto.csv");
  std::set<std::string> pareto_series;
  for (const auto& row : pareto) pareto_series.insert(row.at("series"));
  EXPECT_TRUE(pareto_series.count("fracture (calibrated)"));
  EXPECT_TRUE(pareto_series.count("fracture")); // on the floor, below the reference uncertainty
  EXPECT_TRUE(pareto_series.count("reference uncertainty"));
  EXPECT_TRUE(pareto_series.count("budget 1 kHz") && pareto_series.count("budget 10 kHz"));
}

TEST(StudyReport, ProfilesAlongAnInclinedBladeAreTheForceAlongItsCuttingDirection) {
  // A knife whose cutting direction d = (0.8, 0, -0.6) is no coordinate axis (sponge_knife_cut_*):
  // the plot draws -f.d against (p - p0).d, for the reference (its band written around -f.d) and
  // the models alike, so the band holds the curve. Synthetic profiles; the expected values are the
  // dot products written out.
  const fs::path dir = fs::temp_directory_path() / ("kerf_inclined_plot_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const Eigen::Vector3d d(0.8, 0.0, -0.6);
  std::string reference = "t,tool,px,py,pz,fx,fy,fz,mode,crack_extent,cost_s,band_low,band_high\n";
  std::string model = "t,tool,px,py,pz,fx,fy,fz,mode,crack_extent,cost_s\n";
  std::vector<double> expected_x, expected_y, expected_model_y;
  for (int k = 0; k < 6; ++k) {
    const Eigen::Vector3d p = Eigen::Vector3d(0.4e-3, 0.0, 1.4e-3) + 1e-4 * k * Eigen::Vector3d(0.625, 0.0, -0.78);
    const Eigen::Vector3d f(0.01 * k, 0.0, 0.03 * k), g(-0.02 * k, 0.0, 0.01 * k);
    const double y = -f.dot(d);
    char line[256];
    std::snprintf(line, sizeof line, "%.17g,knife,%.17g,0,%.17g,%.17g,0,%.17g,cutting,0,0,%.17g,%.17g\n", 0.1 * k, p.x(), p.z(),
                  f.x(), f.z(), y - 0.001, y + 0.001);
    reference += line;
    std::snprintf(line, sizeof line, "%.17g,knife,%.17g,0,%.17g,%.17g,0,%.17g,cutting,0,0\n", 0.1 * k, p.x(), p.z(), g.x(), g.z());
    model += line;
    expected_x.push_back(1e3 * 1e-4 * k * Eigen::Vector3d(0.625, 0.0, -0.78).dot(d));
    expected_y.push_back(y);
    expected_model_y.push_back(-g.dot(d));
  }
  const fs::path ref_csv = write_file(dir / "reference.csv", reference), model_csv = write_file(dir / "model.csv", model);
  plot_profiles(dir / "knife_profiles", {{"voxel", model_csv}}, d, ProfilePlotReference{"reference L1", ref_csv, "test band"});
  std::size_t reference_rows = 0, model_rows = 0;
  for (const auto& row : read_csv(dir / "knife_profiles.csv")) {
    const double x = std::stod(row.at("x")), y = std::stod(row.at("y"));
    if (row.at("series") == "reference L1") {
      const std::size_t k = reference_rows++;
      EXPECT_NEAR(x, expected_x[k], 1e-12);
      EXPECT_NEAR(y, expected_y[k], 1e-12);
      EXPECT_LE(std::stod(row.at("band_low")), y);
      EXPECT_GE(std::stod(row.at("band_high")), y);
    } else if (row.at("series") == "voxel") {
      EXPECT_NEAR(y, expected_model_y[model_rows++], 1e-12);
    }
  }
  EXPECT_EQ(reference_rows, 6u);
  EXPECT_EQ(model_rows, 6u);
  fs::remove_all(dir);
}

TEST(StudyReport, TheLatexTablesAreAsciiWithOneCellPerColumn) {
  // No pdflatex on the build machine: the syntax is checked instead. Every row of study.tex and
  // verification.tex has as many cells as the tabular has columns (unescaped "&" = columns - 1),
  // braces balance, and the text is ASCII (µ, ×, φ, ≤ … written as LaTeX commands), so that
  // pdflatex's default set-up typesets it with booktabs.
  const ThreeLevelStudy& s = three_level_study();
  write_study_report(s.spec, s.result, s.out);
  for (const char* name : {"study.tex", "verification.tex"}) {
    std::ifstream in(s.out / name);
    std::stringstream text;
    text << in.rdbuf();
    const std::string tex = text.str();
    for (unsigned char c : tex) ASSERT_LT(c, 0x80) << name << " holds a non-ASCII byte:\n" << tex;
    const std::size_t spec_begin = tex.find("\\begin{tabular}{") + 16;
    const std::size_t columns = tex.find('}', spec_begin) - spec_begin;
    int depth = 0;
    std::istringstream lines(tex);
    std::string line;
    int rows = 0;
    while (std::getline(lines, line)) {
      for (std::size_t k = 0; k < line.size(); ++k) {
        if (line[k] == '\\') {
          ++k; // an escaped character or a command's first letter
          continue;
        }
        depth += line[k] == '{' ? 1 : line[k] == '}' ? -1 : 0;
        EXPECT_GE(depth, 0) << name << ": " << line;
      }
      if (line.size() < 2 || line.compare(line.size() - 2, 2, "\\\\") != 0 || line.find("\\multicolumn") == 0) continue;
      std::size_t cells = 1;
      for (std::size_t k = 0; k < line.size(); ++k) cells += line[k] == '&' && (k == 0 || line[k - 1] != '\\');
      EXPECT_EQ(cells, columns) << name << ": " << line;
      ++rows;
    }
    EXPECT_EQ(depth, 0) << name;
    EXPECT_GE(rows, 3) << name; // the header and at least two rows
  }
}

TEST(StudyReport, ACoarseLevelThatFailsIsLeftOutSayingWhy) {
  // A coarse mesh may not resolve the scene (clay_pull's grasp at 4h holds no node): the study goes
  // on with the levels that solved — two here, so no GCI — and the reference row names the failure.
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_study_report3_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const StudySpec spec = read_study(write_file(dir / "fail.toml", "[study]\nname = \"fail\"\nscenes = [\"potato_rect_cut\"]\n"
                                                                  "models = [\"fracture\"]\n[reference]\nrefinements = [-2, -1, 0]\nsamples = 6\n"
                                                                  "time_verification = false\n"));
  const ReferenceRunner inner = power_law_reference();
  const ReferenceRunner failing = [&](const StudyReferenceSolve& solve, const StudyReferenceSpec& settings) {
    if (solve.scene.geometry.element_size > 7e-3) throw std::runtime_error("no node within the grasp");
    return inner(solve, settings);
  };
  const StudyResult r = run_study(spec, dir / "out", failing);
  ASSERT_EQ(r.rows.size(), 3u); // reference L0, reference L-1, fracture
  EXPECT_NE(r.rows[0].note.find("L-2 failed (no node within the grasp)"), std::string::npos) << r.rows[0].note;
  EXPECT_NE(r.rows[0].note.find("no GCI available: 2 mesh level(s)"), std::string::npos) << r.rows[0].note;
  ASSERT_TRUE(r.rows[2].metrics.has_value());
  // The finest level failing leaves nothing to score against: an error.
  const ReferenceRunner finest_fails = [&](const StudyReferenceSolve& solve, const StudyReferenceSpec& settings) {
    if (solve.scene.geometry.element_size < 3e-3) throw std::runtime_error("diverged");
    return inner(solve, settings);
  };
  EXPECT_THROW(run_study(spec, dir / "out2", finest_fails), std::runtime_error);
  fs::remove_all(dir);
}

TEST(StudyReport, TheForceTimePanelIsForToolsThatHoldOrRetreat) {
  // potato_rect_cut: the blade advances along -z (its cutting direction), cuts, holds 0.5 s and
  // retreats; clay_pull: the stylus pulls up (+z) and holds. Without the hold and the retreat the
  // potato's travel never folds back: no time panel.
  Scene potato = read_scene(fs::path(KERF_SCENES_DIR) / "potato_rect_cut.toml");
  const Scene clay = read_scene(fs::path(KERF_SCENES_DIR) / "clay_pull.toml");
  EXPECT_LT((advance_direction(potato) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-15);
  EXPECT_LT((advance_direction(clay) - Eigen::Vector3d(0, 0, 1)).norm(), 1e-15);
  EXPECT_TRUE(holds_or_retreats(potato));
  EXPECT_TRUE(holds_or_retreats(clay));
  potato.tools.front().trajectory.segments.resize(2); // approach, cut
  EXPECT_FALSE(holds_or_retreats(potato));
}
