#pragma once
// Model selection (docs/studies.md, `kerf recommend`): from the measured study tables, the cheapest
// model that keeps a scene's force error within a budget at a servo rate — with the table row
// that shows it — or "none" and why.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace kerf {

/// One scored row of a study table (study.csv, study_runner.hpp's columns).
struct MeasuredRow {
  std::filesystem::path table;        ///< the CSV it came from
  std::size_t line = 0;               ///< its line in that file (header = 1)
  std::string scene, model;           ///< model with its variant ("springs (calibrated)")
  std::optional<double> rms_error;    ///< normalised RMS force error [–]; 0 when below the reference's uncertainty
  /// The table says "below reference uncertainty": the error is smaller than the reference can
  /// resolve; such a row meets every error budget the table can answer for.
  bool below_reference_uncertainty = false;
  std::optional<double> p99_cost;     ///< p99 cost per servo step [s]
  std::string text;                   ///< the row as written, the evidence
};

/// Reads the scored rows of a study.csv (columns "scene", "model", "RMS force error [%]",
/// "p99 cost [µs]"; RFC 4180 quoting). An error cell "below reference uncertainty" reads as 0 with
/// below_reference_uncertainty set. Throws std::runtime_error naming file:line on a malformed
/// file, missing columns, or an error or cost that is neither empty, that text, nor a finite number >= 0.
std::vector<MeasuredRow> read_study_rows(const std::filesystem::path& csv);

/// Every study.csv under `directory` (recursively), or `directory` itself if it is a file; sorted.
std::vector<std::filesystem::path> find_study_tables(const std::filesystem::path& directory);

struct Recommendation {
  std::optional<MeasuredRow> choice; ///< empty: none meets the budget
  std::string reason;                ///< why this row, or why none
};

/// Among the fast-model rows of `scene` (reference rows excluded) with a measured error ≤
/// `max_error` and a p99 cost ≤ 1 / `rate` (the servo period), the one with the smallest p99
/// cost (ties: the smaller error, then the earlier row). `rate` in Hz > 0, `max_error` ≥ 0.
Recommendation recommend_model(const std::vector<MeasuredRow>& rows, const std::string& scene, double max_error,
                               double rate);

} // namespace kerf
