#pragma once
// Running a study: every model on every scene it can represent, the reference at each mesh level
// (cached by the hash of the scene and the solver settings), metrics against the finest
// reference, the reference's own discretisation error beside them, tables and plots (issue 7).

#include "experiments/profile/force_profile.hpp"
#include "experiments/run/run_model.hpp"
#include "experiments/study/profile_metrics.hpp"
#include "experiments/study/study_spec.hpp"
#include "experiments/study/study_table.hpp"

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace kerf {

/// The reference as a study sees it: the profile of `scene` at mesh level `refinement`, solved at
/// the trajectory samples `sample_indices` (one row per tool per index), with its run files
/// written under `dir`. Throws on failure.
using ReferenceRunner = std::function<ForceProfile(const Scene& scene, const StudyReferenceSpec& settings,
                                                   int refinement, const std::vector<std::size_t>& sample_indices,
                                                   const std::filesystem::path& dir)>;

/// The finite-element reference (reference/, through experiments/run/reference_run.hpp) as a
/// study calls it: the chosen samples at the given mesh level, no field files (`kerf reference`
/// writes those).
ReferenceRunner finite_element_reference();

/// One row of the study table.
struct StudyRow {
  std::string scene;
  std::string model;                      ///< a fast model, or "reference L<k>" for a coarser level
  std::optional<ProfileMetrics> metrics;  ///< against the finest reference (when there is one)
  CostStatistics cost;                    ///< per step [s]
  std::string note;                       ///< why a model did not run, or what was guarded
};

struct StudyResult {
  std::vector<StudyRow> rows;
  StudyTable table() const;   ///< the publishable table
  int reference_runs = 0;     ///< reference solves actually run (0 on a fully cached re-run)
};

/// `reference` may be empty (no reference built): then only costs are reported. Every output
/// goes under `out`; the reference cache lives in `out/cache`.
StudyResult run_study(const StudySpec& spec, const std::filesystem::path& out, const ReferenceRunner& reference);

/// The trajectory samples the reference solves: `count` indices evenly spaced over [0, n-1],
/// first and last included.
std::vector<std::size_t> reference_sample_indices(std::size_t n, int count);

/// The rows of `profile` whose sample index (row order per tool) is in `indices`.
ForceProfile subsample(const ForceProfile& profile, const std::vector<std::size_t>& indices);

/// The rows of `a` whose tool and time (to 1e-9 s) also appear in `b`: the samples two runs have
/// in common — a reference that stopped early (a blade pressed further than an uncut body can
/// take) is compared on the samples it solved.
ForceProfile at_common_times(const ForceProfile& a, const ForceProfile& b);

} // namespace kerf
