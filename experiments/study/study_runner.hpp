#pragma once
// Running a study: every model on every scene it can represent, the reference at each mesh level
// (cached by the hash of the scene and the solver settings) and once more at half the load
// increment, metrics against the finest reference (over the whole trajectory and per phase), the
// reference's own discretisation error in space and in time beside them, the costs of every model
// timed undisturbed in a pass of their own, tables and plots (docs/studies.md).

#include "formats/profile/force_profile.hpp"
#include "experiments/models/run_model.hpp"
#include "experiments/reference_run/reference_run.hpp"
#include "experiments/study/cost_timing.hpp"
#include "formats/profile/profile_metrics.hpp"
#include "experiments/study/reference_verification.hpp"
#include "experiments/study/study_plan.hpp"
#include "experiments/study/study_spec.hpp"
#include "experiments/study/study_table.hpp"

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace kerf {

/// The reference as a study sees it: `solve` (a scene at a mesh level, on chosen samples, at a
/// load increment), solved with the study's settings `spec`, its run files written under
/// `solve.dir`. Returns the profile (one row per tool per solved sample) and why its load path
/// stopped, if it did; throws on failure.
using ReferenceRunner = std::function<ReferenceResult(const StudyReferenceSolve& solve, const StudyReferenceSpec& spec)>;

/// The finite-element reference (reference/, through experiments/reference_run/reference_run.hpp) as a
/// study calls it: the chosen samples at the given mesh level and increment with the study's
/// solver settings (study_reference_settings, reference_cache.hpp), no field files.
ReferenceRunner finite_element_reference();

/// One row of the study table. Each scene's rows: first its finest reference ("reference L<k>",
/// no metrics, its note the solution verification in space and in time, or why there is none),
/// then each coarser level and the finest at half the increment against the finest
/// ("reference L<k>", "reference L<k> (half increment)"), then the fast models.
struct StudyRow {
  std::string scene;
  std::string model;                      ///< a fast model, or "reference L<k>"
  std::optional<ProfileMetrics> metrics;  ///< against the finest reference (when there is one)
  CostStatistics cost;                    ///< per step [s], of the scored run (a reference: per solved sample)
  std::optional<TimedCost> timed;         ///< a fast model's cost per step from the timing pass
  std::string note;                       ///< why a model did not run, or what was guarded
  std::filesystem::path profile;          ///< the row's profile.csv (empty when it has none)
  /// The model's RMS force difference [N] (normalised RMS error × the compared reference's peak
  /// |F|) is below the reference's uncertainty in RMS |F| (space and time combined,
  /// combined_uncertainty): the table shows "below reference uncertainty", not the number.
  bool rms_below_reference_uncertainty = false;
  /// |peak |F|_model - peak |F|_reference| [N] below the reference's uncertainty in peak |F|.
  bool peak_below_reference_uncertainty = false;
};

/// The text a table shows instead of an error smaller than the reference's own uncertainty.
inline constexpr const char* below_reference_uncertainty = "below reference uncertainty";

/// A scene's reference as the study solved and verified it.
struct SceneReference {
  std::string scene;
  std::string tool;                       ///< the scene's first tool: the one scored
  std::vector<int> levels;                ///< mesh levels, coarsest first
  std::vector<double> element_sizes;      ///< [m], per level
  std::vector<std::filesystem::path> profiles; ///< profile.csv per level (in the cache)
  std::vector<ForceProfile> level_profiles;    ///< the profile of each level
  std::optional<ReferenceVerification> verification; ///< in space, with three levels or more
  std::optional<SamplingVerification> sampling;      ///< in time: the finest level at half the increment
  std::string note;                       ///< the reference row's note
  /// The finest profile's uncertainty in the RMS norm [N], space and time together.
  [[nodiscard]] std::optional<double> uncertainty() const { return combined_uncertainty(verification, sampling); }
};

struct StudyResult {
  std::vector<StudyRow> rows;
  std::vector<SceneReference> references; ///< one per scene with a reference, in study order
  std::string machine;        ///< the machine the costs were measured on (machine_label.hpp)
  int jobs = 1, ranks = 1;    ///< how the accuracy runs were spread (StudyExecution)
  int timing_runs = 0;        ///< runs per model in the timing pass (0: no timing pass)
  /// The publishable table, rows grouped by scene, with a caption saying how the costs were
  /// measured and on which machine.
  StudyTable table() const;
  /// The table's accuracy columns alone (scene, model, the errors, mode agreement, note): what
  /// the study knows before its timing pass (StudyExecution::scored).
  StudyTable accuracy_table() const;
  /// The force error per phase of the reference (profile_metrics.hpp) of every scored model row,
  /// and the phase with the largest share of the squared error.
  StudyTable phase_table() const;
  int reference_runs = 0;     ///< reference solves actually run (0 on a fully cached re-run)
  /// References whose load path stopped before the trajectory's end ("scene level L<k>: why"): the
  /// study scores what they solved and its command ends with status 4 (apps/command_line.hpp).
  std::vector<std::string> stopped_references;
  int fits_run = 0;           ///< calibrations fitted anew (the others taken from the library)
  double run_seconds = 0.0;   ///< wall time of the reference solves and model runs (until every rank has them) [s]
  double fit_seconds = 0.0;   ///< wall time of the fitted calibrations ([[calibrate]]) [s]
  double timing_seconds = 0.0; ///< wall time of the timing pass [s]
};

/// How the independent runs of a study are spread: over `jobs` threads of this process and over
/// `ranks` processes (MPI, study_ranks.hpp). A run is a reference solve (a scene at a mesh level
/// and increment, or a scene on a calibration trajectory), a fast model on a scene, or a fitted
/// calibration ([[calibrate]]); run k (references first, then models, then fits, in study order)
/// belongs to rank k mod ranks. Each rank keeps its results in memory and writes them to disk as
/// records (the reference cache, each model's profile.csv and manifest, a note.txt saying why a run
/// failed); the fits start once every reference is on disk (they read theirs from the cache);
/// after the last `synchronise`, rank 0 builds the table from its own results and — with several
/// ranks — the other ranks' records, so the tables do not depend on jobs or ranks. Then rank 0
/// alone times every model (the timing pass, cost_timing.hpp) while the other ranks are done. Reference
/// solves of one process run one at a time (PETSc is not thread-safe), beside the fast models;
/// each solve runs on its one process (the mesh is not distributed).
struct StudyExecution {
  int jobs = 1;   ///< threads for this process's accuracy runs, >= 1
  int rank = 0;   ///< this process, in [0, ranks)
  int ranks = 1;  ///< processes sharing the study
  /// Whole runs per model in the timing pass (>= 1; 0: no timing pass, the cost columns from the
  /// scored runs as they ran beside others).
  int timing_runs = 5;
  /// With ranks > 1: waits for every rank and returns the sum of `value` over the ranks
  /// (MPI_Allreduce). Called three times: before any run (so every rank plans from the same
  /// cache), after the reference solves and model runs (summing the solves), after the fits.
  std::function<int(int value)> synchronise;
  /// Progress lines (study_progress.hpp) go here; nullptr: silent.
  std::FILE* progress = stderr;
  /// Called on rank 0 once every run is scored and before the timing pass, with the rows as they
  /// stand then: every error column final, the cost columns those of the scored runs (as they ran
  /// beside others). The accuracy is known minutes before the costs: `kerf study` prints it and
  /// draws the profile plots here. Empty: not called.
  std::function<void(const StudyResult& scored)> scored;
};

/// `reference` may be empty (no reference built): then only costs are reported (and nothing is
/// fitted). Every output goes under `out`; the reference cache lives in `out/cache`, one directory
/// per solve named by reference_cache_key (reference_cache.hpp) with its `key.txt`. A fitted
/// calibration's row "MODEL (calibrated)" comes right after MODEL's row, its note saying what was
/// fitted on which trajectory; its parameter file is `out/SCENE/MODEL-calibrated/parameters.toml`. Rank 0 returns the rows; other
/// ranks return no rows (and the total reference runs). Throws if a scene's finest reference solve
/// failed; a coarser level (or the half-increment run) that failed is left out, the reference
/// row's note saying why (the verification then has the levels that remain).
StudyResult run_study(const StudySpec& spec, const std::filesystem::path& out, const ReferenceRunner& reference,
                      const StudyExecution& execution = {});

/// Every reference solve `spec` plans (each scene's levels and its half-increment run, then the
/// calibration trajectories'), their cache directories under `out`, as run_study plans them.
std::vector<StudyReferenceSolve> study_reference_solves(const StudySpec& spec, const std::filesystem::path& out);

/// Copies each of `solves` that is in its cache (profile.csv, key.txt, manifest.json — which holds
/// kerf's version, its git commit and the solve's settings) into `library/<key directory>/`, with
/// `command.txt` holding `command` (what made it), replacing an entry of the same key, and removes
/// every other entry of the library (a folder holding a key.txt that is not one of `solves`: an entry
/// under a stale key, which no study run could take any more); returns how many were published. A
/// library belongs to one study. The library
/// is what a study file's `[reference] library` names: a study takes from it every solve whose key
/// it holds instead of solving it (docs/studies.md, "Reference library").
int publish_references(const std::vector<StudyReferenceSolve>& solves, const std::filesystem::path& library,
                       const std::string& command);

/// The version of what a study's fitted calibration computes: the fast models, their free
/// parameters and the calibration. A fit in a study's library is keyed by it (with the scene, the
/// model, the fit's settings and its target's key) and taken instead of fitting anew when the key
/// matches. Bump it when a model's or the calibration's numbers change for unchanged inputs;
/// ReferenceLibrary.EveryFitGivesItsRecordedErrorOnItsTarget fails until it is bumped and the
/// library re-published (its fitted error no longer reproduces).
inline constexpr int study_fit_version = 2;

/// Copies each fitted calibration of `spec` whose run under `out` recorded one (parameters.toml,
/// fit.json, key.txt) into `library/fits/<scene>-<model>-<key, 16 hex>/`, replacing an entry of
/// the same key, and removes every other entry of `library/fits`; returns how many were published.
/// A study with a library takes a fit from it when the key matches (docs/studies.md, "Reference
/// library").
int publish_fits(const StudySpec& spec, const std::filesystem::path& out, const std::filesystem::path& library);

/// The rows of `profile` whose sample index (row order per tool) is in `indices`.
ForceProfile subsample(const ForceProfile& profile, const std::vector<std::size_t>& indices);

/// The reference samples a model is scored on: those of the phases it represents.
struct ScoredSamples {
  ForceProfile reference; ///< the rows of the reference the model is compared with
  std::string note;       ///< empty when every sample is scored; else which ones were, and why
};

/// The phases of `reference` a model represents, given the scene's phenomena and those the model
/// reproduces on it (represented_phenomena, experiments/models/model_catalogue.hpp). A model that
/// represents every way the scene's body comes apart (cutting, tearing) — or a scene that declares
/// none — is scored on every sample. Otherwise it is scored on the phase before the body separates:
/// the samples before the reference's first sample in `rupture`, `cutting` or `deformation-2` mode
/// or with a crack (paper 001 Fig. 11: no-contact and deformation-1; after that the reference's body
/// is cut, one the model does not have) — all rows at those times, every tool.
ScoredSamples represented_samples(const ForceProfile& reference, PhenomenonSet scene_phenomena, PhenomenonSet represented);

} // namespace kerf
