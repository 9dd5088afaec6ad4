// kerf recommend SCENE --max-error 10% --rate 1000 [--tables DIR]: the cheapest model that the
// measured study tables say meets the error budget at the servo rate, with the evidence row; "none"
// and why when nothing does (docs/studies.md, `kerf recommend`).

#include "apps/kerf/commands.hpp"
#include "experiments/study/model_recommendation.hpp"

#include <cstdio>
#include <memory>

namespace kerf::cli {

namespace {

struct RecommendOptions {
  std::string scene;
  std::string max_error = "10%";
  double rate = 1000.0;
  std::string tables = "runs/studies";
};

/// "10%" or "0.1": a fraction.
double parse_error_budget(const std::string& text) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  const std::string rest = text.substr(used);
  if (used == 0 || (rest != "" && rest != "%") || !(v >= 0.0))
    throw CLI::ValidationError("--max-error", "expected a fraction (0.1) or a percentage (10%), got \"" + text + "\"");
  return rest == "%" ? v / 100.0 : v;
}

void run_recommend(const RecommendOptions& o) {
  // A scene file path names its scene by its stem; a name is the scene's name.
  const std::string scene = std::filesystem::path(o.scene).stem().string();
  const double max_error = parse_error_budget(o.max_error);
  std::vector<MeasuredRow> rows;
  const auto tables = find_study_tables(o.tables);
  for (const auto& t : tables)
    for (MeasuredRow& r : read_study_rows(t)) rows.push_back(std::move(r));
  const Recommendation rec = recommend_model(rows, scene, max_error, o.rate);
  if (!rec.choice) {
    std::printf("none\n%s\n(%zu table(s) read under %s)\n", rec.reason.c_str(), tables.size(), o.tables.c_str());
    return;
  }
  std::printf("%s\n%s\nevidence: %s:%zu\n  %s\n", rec.choice->model.c_str(), rec.reason.c_str(), rec.choice->table.c_str(),
              rec.choice->line, rec.choice->text.c_str());
}

} // namespace

void add_recommend_command(CLI::App& app) {
  auto options = std::make_shared<RecommendOptions>();
  auto* cmd = app.add_subcommand("recommend", "the cheapest model the measured study tables say meets an error budget at a servo rate");
  cmd->add_option("scene", options->scene, "scene name (or file) as it appears in the study tables")->required();
  cmd->add_option("--max-error", options->max_error, "largest normalised RMS force error: 10% or 0.1 (default 10%)");
  cmd->add_option("--rate", options->rate, "servo rate [Hz] the p99 step cost must allow (default 1000)")->check(CLI::PositiveNumber);
  cmd->add_option("--tables", options->tables, "a study.csv, or a directory searched for study.csv files (default runs/studies)");
  cmd->callback([options] { run_recommend(*options); });
}

} // namespace kerf::cli
