#pragma once
// The study's plots, drawn by experiments/study/plot_study.py (matplotlib, Debian's python3) from
// kerf's own CSV files.

#include "formats/scene/scene.hpp"

#include <Eigen/Core>

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace kerf {

/// The reference a profile plot draws under the models: a profile CSV with two more columns,
/// band_low and band_high [N] (the band of the resisting force, reference_verification.hpp).
struct ProfilePlotReference {
  std::string label;               ///< the series name, as the study table's reference row
  std::filesystem::path csv;
  std::string band_source;         ///< what the band is, for the legend ("GCI band", "spread of L-1..L1")
};

/// The resisting force along the direction of advance d (unit; advance_direction), −f·d, against
/// tool travel along it, (p − p0)·d: the reference with its band (when given, the band of −f·d),
/// each labelled profile on top, the reference's modes (else the first run's) shaded where they
/// occur; with `time_panel`, force against time beside. STEM.png, STEM.pdf, and STEM.csv (panel,
/// series, x, y, band_low, band_high: the data drawn). Throws std::runtime_error naming the command
/// if the plotting program fails.
void plot_profiles(const std::filesystem::path& stem, const std::vector<std::pair<std::string, std::filesystem::path>>& runs,
                   const Eigen::Vector3d& direction, const std::optional<ProfilePlotReference>& reference = std::nullopt,
                   bool time_panel = false, const std::string& title = "");

/// Error against p99 cost per step (log-log) for the rows of `scene` (all rows when empty) of a
/// study table, a line per model through its resolutions, every point labelled, the 1 kHz and
/// 10 kHz budgets marked and `floor` (the reference uncertainty, in the error column's unit) as a
/// floor: STEM.png, STEM.pdf and STEM.csv (series, x, y, label).
void plot_pareto(const std::filesystem::path& stem, const std::filesystem::path& table_csv, const std::string& error_column,
                 const std::string& cost_column, const std::string& label_column, const std::string& scene = "",
                 std::optional<double> floor = std::nullopt, const std::string& title = "");

/// The unit direction a scene's first tool advances along: a blade's cutting direction, else the
/// direction of its first move.
Eigen::Vector3d advance_direction(const Scene& scene);

/// Whether a scene's first tool holds still or moves back against its advance at some point: then
/// its force against travel folds onto itself and a force-time view is drawn beside.
bool holds_or_retreats(const Scene& scene);

/// The stability map (kerf stability): per swept axis, the value against the class of each run,
/// one row per (model, stability.csv) given: STEM.png and STEM.pdf.
void plot_stability(const std::filesystem::path& stem,
                    const std::vector<std::pair<std::string, std::filesystem::path>>& runs);

} // namespace kerf
