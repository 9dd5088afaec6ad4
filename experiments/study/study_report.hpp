#pragma once
// What a study writes once its runs are done (tables and plots an author can submit):
// the table (study.md/.tex/.csv), the errors per phase (study_phases.md/.tex/.csv), the
// reference's solution verification (verification.md/.csv),
// and per scene the profile plot with the reference and its band (SCENE_profiles.png/.pdf/.csv)
// and the speed/accuracy chart (SCENE_pareto.png/.pdf/.csv). Every figure has its data beside it.

#include "experiments/study/study_runner.hpp"
#include "experiments/study/study_spec.hpp"
#include "experiments/study/study_table.hpp"

#include <filesystem>

namespace kerf {

/// The solution verification of every scene's reference, one row per scene and quantity (RMS |F|,
/// peak |F|): levels, element sizes, the finest three values, r21, r32, observed order p,
/// oscillatory or not, extrapolated value, e_a, e_ext and GCI_fine (Celik et al. 2008), or a note
/// why there is none.
StudyTable verification_table(const StudyResult& result);

/// The reference uncertainty of a scene on the study table's RMS force error scale [–]: the
/// uncertainty of the finest force profile [N] (space and time, SceneReference::uncertainty) over
/// the finest level's peak |F| [N]; empty without either verification.
std::optional<double> rms_error_floor(const SceneReference& reference);

/// Per scene of `spec`, the force profiles of `result` into `out`: SCENE_reference.csv (the finest
/// reference with its band) and SCENE_profiles.* (the reference, every model on top). They need the
/// scored runs only, not their costs. Throws std::runtime_error if a plot cannot be drawn.
void write_profile_plots(const StudySpec& spec, const StudyResult& result, const std::filesystem::path& out);

/// The tables of `result` (study.*, study_phases.*, verification.*) and per scene of `spec` the
/// speed/accuracy chart SCENE_pareto.* into `out`. Throws std::runtime_error if a chart cannot be
/// drawn.
void write_tables_and_charts(const StudySpec& spec, const StudyResult& result, const std::filesystem::path& out);

/// Both: every table and plot of `result` into `out`.
void write_study_report(const StudySpec& spec, const StudyResult& result, const std::filesystem::path& out);

} // namespace kerf
