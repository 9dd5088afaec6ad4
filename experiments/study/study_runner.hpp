#pragma once
// Running a study: every model on every scene it can represent, the reference at each mesh level
// (cached by the hash of the scene and the solver settings), metrics against the finest
// reference, the reference's own discretisation error beside them, tables and plots (docs/studies.md).

#include "experiments/profile/force_profile.hpp"
#include "experiments/models/run_model.hpp"
#include "experiments/study/profile_metrics.hpp"
#include "experiments/study/reference_verification.hpp"
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

/// The finite-element reference (reference/, through experiments/reference_run/reference_run.hpp) as a
/// study calls it: the chosen samples at the given mesh level with the study's solver settings
/// (study_reference_settings, reference_cache.hpp), no field files (`kerf reference` writes those).
ReferenceRunner finite_element_reference();

/// One row of the study table. Each scene's rows: first its finest reference ("reference L<k>",
/// no metrics, its note the solution verification or why there is none), then each coarser level
/// against the finest ("reference L<k>"), then the fast models.
struct StudyRow {
  std::string scene;
  std::string model;                      ///< a fast model, or "reference L<k>"
  std::optional<ProfileMetrics> metrics;  ///< against the finest reference (when there is one)
  CostStatistics cost;                    ///< per step [s]
  std::string note;                       ///< why a model did not run, or what was guarded
  std::filesystem::path profile;          ///< the row's profile.csv (empty when it has none)
  /// The model's RMS force difference [N] (normalised RMS error × the compared reference's peak
  /// |F|) is below the reference's uncertainty in RMS |F| (GCI × RMS |F|, reference_verification.hpp):
  /// the table shows "below reference uncertainty", not the number.
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
  std::optional<ReferenceVerification> verification; ///< with three levels or more
  std::string note;                       ///< the reference row's note
};

struct StudyResult {
  std::vector<StudyRow> rows;
  std::vector<SceneReference> references; ///< one per scene with a reference, in study order
  std::string machine;        ///< the machine the costs were measured on (machine_label.hpp)
  int jobs = 1, ranks = 1;    ///< how the runs were spread (StudyExecution)
  /// The publishable table, rows grouped by scene, with a caption naming the machine and the
  /// jobs the costs were measured with.
  StudyTable table() const;
  int reference_runs = 0;     ///< reference solves actually run (0 on a fully cached re-run)
  double run_seconds = 0.0;   ///< wall time of the reference solves and model runs (until every rank has them) [s]
  double fit_seconds = 0.0;   ///< wall time of the fitted calibrations ([[calibrate]]) [s]
};

/// How the independent runs of a study are spread: over `jobs` threads of this process and over
/// `ranks` processes (MPI, study_ranks.hpp). A run is a reference solve (a scene at a mesh level,
/// or a scene on a calibration trajectory), a fast model on a scene, or a fitted calibration
/// ([[calibrate]]); run k (references first, then models, then fits, in study order) belongs to
/// rank k mod ranks. Each rank runs its share, writing every result to disk (the reference cache,
/// the model's profile.csv, or a note.txt saying why it failed); the fits start once every
/// reference is on disk (they read theirs from the cache); after the last `synchronise`, rank 0
/// reads every result back and builds the table — so the tables do not depend on jobs or ranks,
/// apart from the cost columns (a step timed beside another run is slower). Reference solves of
/// one process run one at a time (PETSc is not thread-safe), beside the fast models; each solve
/// runs on its one process (the mesh is not distributed).
struct StudyExecution {
  int jobs = 1;   ///< threads for this process's runs, >= 1
  int rank = 0;   ///< this process, in [0, ranks)
  int ranks = 1;  ///< processes sharing the study
  /// With ranks > 1: waits for every rank and returns the sum of `value` over the ranks
  /// (MPI_Allreduce). Called three times: before any run (so every rank plans from the same
  /// cache), after the reference solves and model runs (summing the solves), after the fits.
  std::function<int(int value)> synchronise;
};

/// `reference` may be empty (no reference built): then only costs are reported (and nothing is
/// fitted). Every output goes under `out`; the reference cache lives in `out/cache`, one directory
/// per solve named by reference_cache_key (reference_cache.hpp) with its `key.txt`. A fitted
/// calibration's row "MODEL (calibrated)" comes right after MODEL's row, its note saying what was
/// fitted on which trajectory; its parameter file is `out/SCENE/MODEL-calibrated/parameters.toml`. Rank 0 returns the rows; other
/// ranks return no rows (and the total reference runs). Throws if a scene's finest reference solve
/// failed; a coarser level that failed is left out, the reference row's note saying why (the
/// solution verification then has the levels that remain).
StudyResult run_study(const StudySpec& spec, const std::filesystem::path& out, const ReferenceRunner& reference,
                      const StudyExecution& execution = {});

/// One reference solve a study plans: a scene (possibly with another trajectory than its file's:
/// a calibration trajectory) at a mesh level on chosen samples, cached in `dir`
/// (`out/cache/<key directory>`, reference_cache.hpp) with its key's text.
struct StudyReferenceSolve {
  Scene scene;
  int level = 0;
  std::vector<std::size_t> indices;
  std::filesystem::path dir;
  std::string key_text;
};

/// Every reference solve `spec` plans (each scene's levels, then the calibration trajectories'),
/// their cache directories under `out`, as run_study plans them.
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

/// The trajectory samples the reference solves: `count` indices evenly spaced over [0, n-1],
/// first and last included.
std::vector<std::size_t> reference_sample_indices(std::size_t n, int count);

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

/// The calibration trajectory of a fitted calibration ([[calibrate]], study_spec.hpp): `scene`
/// with its scripted trajectory played `speed` times as fast — every move at `speed` times its
/// speed, every hold 1/`speed` as long — the same path in 1/`speed` of the time. Throws
/// std::invalid_argument for a tool replaying a recorded trajectory, or a speed factor <= 0.
Scene calibration_scene(const Scene& scene, double speed);

/// The rows of `a` whose tool and time (to 1e-9 s) also appear in `b`: the samples two runs have
/// in common — a reference that stopped early (a blade pressed further than an uncut body can
/// take) is compared on the samples it solved.
ForceProfile at_common_times(const ForceProfile& a, const ForceProfile& b);

} // namespace kerf
