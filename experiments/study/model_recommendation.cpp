#include "experiments/study/model_recommendation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

namespace kerf {

namespace {

/// Splits one CSV record (RFC 4180: fields may be quoted, "" is a quote inside quotes). A quoted
/// field never spans lines in kerf's tables (study_table.cpp writes no line breaks in cells).
std::vector<std::string> csv_fields(const std::string& line, const std::filesystem::path& file, std::size_t number) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t k = 0; k < line.size(); ++k) {
    const char c = line[k];
    if (quoted) {
      if (c == '"' && k + 1 < line.size() && line[k + 1] == '"') {
        out.back() += '"';
        ++k;
      } else if (c == '"') {
        quoted = false;
      } else {
        out.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.emplace_back();
    } else if (c != '\r') {
      out.back() += c;
    }
  }
  if (quoted) throw std::runtime_error(file.string() + ":" + std::to_string(number) + ": unterminated quoted field");
  return out;
}

/// A measured error or cost: empty (not measured), or a finite number >= 0 ("nan" or "-inf" would
/// pass every budget comparison in recommend_model and be recommended).
std::optional<double> number(const std::string& field, const std::filesystem::path& file, std::size_t line) {
  if (field.empty()) return std::nullopt;
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(field, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != field.size() || !std::isfinite(v) || v < 0.0)
    throw std::runtime_error(file.string() + ":" + std::to_string(line) + ": \"" + field + "\" is not a finite number >= 0");
  return v;
}

std::string percent(double fraction) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g %%", 100.0 * fraction);
  return b;
}

std::string error_of(const MeasuredRow& r) {
  return r.below_reference_uncertainty ? std::string("below the reference's uncertainty") : percent(*r.rms_error);
}

std::string microseconds(double seconds) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g µs", 1e6 * seconds);
  return b;
}

} // namespace

std::vector<MeasuredRow> read_study_rows(const std::filesystem::path& csv) {
  std::ifstream in(csv);
  if (!in) throw std::runtime_error(csv.string() + ": cannot open the study table");
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(csv.string() + ":1: empty study table");
  const auto header = csv_fields(line, csv, 1);
  const auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) throw std::runtime_error(csv.string() + ":1: no column \"" + name + "\" (not a kerf study table?)");
    return static_cast<std::size_t>(it - header.begin());
  };
  const std::size_t scene = column("scene"), model = column("model"), error = column("RMS force error [%]"),
                    cost = column("p99 cost [µs]");
  std::vector<MeasuredRow> rows;
  for (std::size_t number_of_line = 2; std::getline(in, line); ++number_of_line) {
    if (line.empty()) continue;
    const auto f = csv_fields(line, csv, number_of_line);
    if (f.size() != header.size())
      throw std::runtime_error(csv.string() + ":" + std::to_string(number_of_line) + ": " + std::to_string(f.size()) +
                               " fields for " + std::to_string(header.size()) + " columns");
    MeasuredRow r;
    r.table = csv;
    r.line = number_of_line;
    r.scene = f[scene];
    r.model = f[model];
    if (f[error] == "below reference uncertainty") {
      r.rms_error = 0.0;
      r.below_reference_uncertainty = true;
    } else if (const auto e = number(f[error], csv, number_of_line)) {
      r.rms_error = *e / 100.0; // column in %
    }
    if (const auto c = number(f[cost], csv, number_of_line)) r.p99_cost = *c * 1e-6;    // column in µs
    r.text = line;
    rows.push_back(std::move(r));
  }
  return rows;
}

std::vector<std::filesystem::path> find_study_tables(const std::filesystem::path& directory) {
  namespace fs = std::filesystem;
  if (fs::is_regular_file(directory)) return {directory};
  if (!fs::is_directory(directory)) throw std::runtime_error(directory.string() + ": no such study table or directory");
  std::vector<fs::path> out;
  for (const auto& e : fs::recursive_directory_iterator(directory))
    if (e.is_regular_file() && e.path().filename() == "study.csv") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

Recommendation recommend_model(const std::vector<MeasuredRow>& rows, const std::string& scene, double max_error,
                               double rate) {
  if (!(rate > 0.0) || !(max_error >= 0.0)) throw std::invalid_argument("recommend: need a rate > 0 and a maximum error >= 0");
  // The servo period: a step must finish within 1 / rate (its p99 cost, study_runner.hpp).
  const double budget = 1.0 / rate;
  std::vector<const MeasuredRow*> scored;
  for (const MeasuredRow& r : rows)
    if (r.scene == scene && r.model.rfind("reference", 0) != 0 && r.rms_error && r.p99_cost) scored.push_back(&r);
  Recommendation out;
  if (scored.empty()) {
    out.reason = "no fast model of scene " + scene + " has a measured error and cost in the tables (run a study with the reference on it)";
    return out;
  }
  const MeasuredRow* best = nullptr;
  for (const MeasuredRow* r : scored) {
    if (*r->rms_error > max_error || *r->p99_cost > budget) continue;
    if (!best || *r->p99_cost < *best->p99_cost || (*r->p99_cost == *best->p99_cost && *r->rms_error < *best->rms_error))
      best = r;
  }
  if (best) {
    out.choice = *best;
    out.reason = best->model + ": RMS force error " + error_of(*best) + (best->below_reference_uncertainty ? "" : " <= " + percent(max_error)) +
                 ", p99 cost " + microseconds(*best->p99_cost) + " <= " + microseconds(budget) +
                 " (the cheapest of the rows that meet both)";
    return out;
  }
  // Why none: the most accurate row and the cheapest row, each with what it misses.
  const auto accurate = *std::min_element(scored.begin(), scored.end(), [](auto a, auto b) { return *a->rms_error < *b->rms_error; });
  const auto cheap = *std::min_element(scored.begin(), scored.end(), [](auto a, auto b) { return *a->p99_cost < *b->p99_cost; });
  out.reason = "none of the " + std::to_string(scored.size()) + " measured fast-model rows of " + scene +
               " meets both: the most accurate, " + accurate->model + ", errs " + error_of(*accurate) +
               " at p99 " + microseconds(*accurate->p99_cost) + "; the cheapest, " + cheap->model + ", costs " +
               microseconds(*cheap->p99_cost) + " at " + error_of(*cheap) + " (budget " + percent(max_error) +
               ", " + microseconds(budget) + ")";
  return out;
}

} // namespace kerf
