#pragma once
// What a study runs, planned from its file before anything runs (docs/studies.md): the reference
// solves (each scene at its mesh levels, the finest a second time at half the load increment, the
// calibration trajectories), the fast-model runs (each model on each scene, at each resolution, with
// each calibration file) and the fitted calibrations. Every rank of an MPI study plans the same, and
// study_reference_solves (publishing the library) plans the same again.

#include "formats/scene/scene.hpp"
#include "experiments/study/reference_cache.hpp"
#include "experiments/study/study_spec.hpp"
#include "realtime/phenomena.hpp"

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace kerf {

/// One reference solve a study plans: a scene (possibly with another trajectory than its file's:
/// a calibration trajectory) at a mesh level on chosen samples and load increment, cached in `dir`
/// (`out/cache/<key directory>`, reference_cache.hpp) with its key's text.
struct StudyReferenceSolve {
  Scene scene;
  int level = 0;
  std::vector<std::size_t> indices;
  LoadIncrement increment = LoadIncrement::whole;
  std::filesystem::path dir;
  std::string key_text;
};

/// One fast-model run of a study: the model on a scene (with calibrated parameters for a
/// "MODEL (calibrated)" row from a [calibration] file), its records under `dir`.
struct StudyModelRun {
  std::size_t scene = 0;       ///< index into the planned scenes
  std::string model;           ///< catalogue name
  std::string label;           ///< the table's model column
  Scene scene_with_parameters;
  std::filesystem::path dir;
  PhenomenonSet represented;   ///< what the model reproduces of the scene (represented_phenomena)
  std::string not_applicable;  ///< why the model cannot run on the scene (then it is not run)
  bool anchors_fits = false;   ///< the model's fitted calibration row comes right after this one
};

/// A calibration the study fits ([[calibrate]]): the fit on the calibration trajectory against
/// `reference` (an index into the planned solves), then the fitted model on the scene's own
/// trajectory, its records under `dir` like any model run, with `parameters.toml` beside.
struct StudyFitRun {
  std::size_t scene = 0;
  StudyCalibrationFit fit;
  std::optional<std::size_t> reference; ///< none when the fit is refused (`refusal`)
  std::string refusal;                  ///< why this reference cannot be fitted to
  std::string label;
  std::filesystem::path dir;
};

/// A scene of the study and its reference solves (indices into StudyPlan::solves).
struct StudyPlannedScene {
  Scene scene;
  std::vector<std::size_t> levels;        ///< coarsest first; the last is the finest
  std::optional<std::size_t> time_check;  ///< the finest level at half the load increment
};

struct StudyPlan {
  std::vector<StudyPlannedScene> scenes;
  std::vector<StudyReferenceSolve> solves;
  std::vector<StudyModelRun> model_runs;
  std::vector<StudyFitRun> fit_runs;
};

/// Plans `spec` with its outputs under `out`; `reference_wanted` false plans no reference solve
/// (and no fit): a study run without a reference reports costs only.
StudyPlan plan_study(const StudySpec& spec, const std::filesystem::path& out, bool reference_wanted = true);

/// The trajectory samples a reference solves on `scene`: `count` evenly spaced in time, first and
/// last included (the solve adds every vertex of the motion, reference_run.hpp).
std::vector<std::size_t> solved_samples(const Scene& scene, int count);

/// The trajectory samples the reference solves: `count` indices evenly spaced over [0, n-1],
/// first and last included. reference_sample_indices(n, 2 m − 1) holds reference_sample_indices(n, m).
std::vector<std::size_t> reference_sample_indices(std::size_t n, int count);

/// The calibration trajectory of a fitted calibration ([[calibrate]], study_spec.hpp): `scene`
/// with its scripted trajectory played `speed` times as fast — every move at `speed` times its
/// speed, every hold 1/`speed` as long — the same path in 1/`speed` of the time. Throws
/// std::invalid_argument for a tool replaying a recorded trajectory, or a speed factor <= 0.
Scene calibration_scene(const Scene& scene, double speed);

/// A `not run:` note goes into tables that are published (docs/results.md), so the scene file's
/// path in the model's message is written relative to the directory the study runs in (the
/// repository root for `kerf study default`), or as the file's name when the scene lies outside
/// it: the table then reads the same on every checkout.
std::string portable_note(std::string note, const Scene& scene);

} // namespace kerf
