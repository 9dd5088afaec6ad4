#pragma once
// The study's plots, drawn by experiments/study/plot_study.py (matplotlib, Debian's python3) from
// kerf's own CSV files.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace kerf {

/// Force along the cutting axis against tool travel for each labelled profile, the first one's
/// modes shaded: STEM.png and STEM.pdf. `axis` is one of x y z -x -y -z (the direction of advance).
/// Throws std::runtime_error naming the command if the plotting program fails.
void plot_profiles(const std::filesystem::path& stem,
                   const std::vector<std::pair<std::string, std::filesystem::path>>& runs, const std::string& axis);

/// Error against cost per sample (log-log) with the 1 kHz and 10 kHz budgets: STEM.png, STEM.pdf.
void plot_pareto(const std::filesystem::path& stem, const std::filesystem::path& table_csv, const std::string& error_column,
                 const std::string& cost_column, const std::string& label_column);

/// The stability map (kerf stability): per swept axis, the value against the class of each run,
/// one row per (model, stability.csv) given: STEM.png and STEM.pdf.
void plot_stability(const std::filesystem::path& stem,
                    const std::vector<std::pair<std::string, std::filesystem::path>>& runs);

} // namespace kerf
