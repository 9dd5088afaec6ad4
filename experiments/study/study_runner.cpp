#include "experiments/study/study_runner.hpp"
#include "experiments/records/run_record.hpp"

#include "experiments/calibration/calibration.hpp"
#include "experiments/models/model_catalogue.hpp"
#include "experiments/reference_run/reference_run.hpp"
#include "experiments/scene/scene_mesh.hpp"
#include "experiments/scene/scene_reader.hpp"
#include "experiments/study/machine_label.hpp"
#include "experiments/study/model_resolution.hpp"
#include "experiments/study/reference_cache.hpp"
#include "meshes/atomic_file.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <mutex>
#include <sstream>
#include <thread>
#include <tuple>

namespace kerf {

std::vector<std::size_t> reference_sample_indices(std::size_t n, int count) {
  std::vector<std::size_t> out;
  if (n == 0) return out;
  const auto m = static_cast<std::size_t>(std::max(2, count));
  for (std::size_t i = 0; i < m; ++i) {
    const std::size_t k = (n - 1) * i / (m - 1);
    if (out.empty() || out.back() != k) out.push_back(k);
  }
  return out;
}

ForceProfile subsample(const ForceProfile& profile, const std::vector<std::size_t>& indices) {
  ForceProfile out;
  std::map<std::string, std::size_t> seen;
  for (const ProfileRow& r : profile.rows) {
    const std::size_t k = seen[r.tool]++;
    if (std::binary_search(indices.begin(), indices.end(), k)) out.rows.push_back(r);
  }
  return out;
}

ReferenceRunner finite_element_reference() {
  return [](const Scene& scene, const StudyReferenceSpec& spec, int level, const std::vector<std::size_t>& indices,
            const std::filesystem::path& dir) {
    return run_reference(scene, scene_mesh(scene, MeshPurpose::reference), study_reference_settings(spec, scene, level, indices), dir);
  };
}

Scene calibration_scene(const Scene& scene, double speed) {
  if (!(speed > 0.0) || !std::isfinite(speed))
    throw std::invalid_argument("calibration trajectory of scene " + scene.name + ": speed factor must be > 0");
  Scene s = scene;
  for (Tool& t : s.tools) {
    if (!t.trajectory.recorded_file.empty())
      throw std::invalid_argument("scene " + scene.name + ": tool " + t.name + " replays a recorded trajectory (" +
                                  t.trajectory.recorded_file.string() + "), which has no speed to change");
    for (TrajectorySegment& segment : t.trajectory.segments) {
      if (segment.kind == TrajectorySegment::Kind::move) segment.speed *= speed;
      else segment.duration /= speed;
    }
  }
  return s;
}

ForceProfile at_common_times(const ForceProfile& a, const ForceProfile& b) {
  std::map<std::string, std::vector<double>> times;
  for (const ProfileRow& r : b.rows) times[r.tool].push_back(r.t);
  for (auto& [tool, t] : times) std::sort(t.begin(), t.end());
  ForceProfile out;
  for (const ProfileRow& r : a.rows) {
    const auto it = times.find(r.tool);
    if (it == times.end()) continue;
    const auto lo = std::lower_bound(it->second.begin(), it->second.end(), r.t - 1e-9);
    if (lo != it->second.end() && *lo <= r.t + 1e-9) out.rows.push_back(r);
  }
  return out;
}

ScoredSamples represented_samples(const ForceProfile& reference, PhenomenonSet scene_phenomena, PhenomenonSet represented) {
  ScoredSamples out{reference, ""};
  bool separates = false;
  for (const Phenomenon p : {Phenomenon::cutting, Phenomenon::tearing})
    separates = separates || (scene_phenomena.contains(p) && !represented.contains(p));
  if (!separates) return out;
  // The first time the reference's body is cut or torn (paper 001 Fig. 11: rupture starts the cut,
  // deformation-2 presses a cut body).
  double separated = std::numeric_limits<double>::infinity();
  for (const ProfileRow& r : reference.rows)
    if (r.mode == InteractionMode::rupture || r.mode == InteractionMode::cutting || r.mode == InteractionMode::deformation_2 ||
        r.crack_extent > 0.0)
      separated = std::min(separated, r.t);
  out.reference.rows.clear();
  std::set<double> all_times, kept_times;
  for (const ProfileRow& r : reference.rows) {
    all_times.insert(r.t);
    if (r.t < separated - 1e-9) {
      out.reference.rows.push_back(r);
      kept_times.insert(r.t);
    }
  }
  char note[256];
  if (kept_times.empty())
    std::snprintf(note, sizeof note, "not scored: it represents %s of this scene, and the reference separates from its first sample",
                  represented.to_string().c_str());
  else
    std::snprintf(note, sizeof note, "scored on the %zu of %zu reference samples before the body separates (t ≤ %.3g s): it represents %s of this scene",
                  kept_times.size(), all_times.size(), *kept_times.rbegin(), represented.to_string().c_str());
  out.note = note;
  return out;
}

namespace {

/// The steady cutting force J_c l (paper 001 Eq. 10) of a homogeneous box cut across its width by
/// a blade: l = the box's width. Other shapes have no single steady value (l varies with depth).
std::optional<SteadyCuttingExpectation> expected_cutting(const Scene& scene) {
  if (scene.tools.size() != 1 || scene.tools.front().kind != Tool::Kind::blade || scene.phenomena.contains(Phenomenon::layers))
    return std::nullopt;
  const auto& p = scene.geometry.parameters;
  const std::string geo = scene.geometry.source.filename().string();
  if (geo != "rect_prism.geo" || !p.count("width") || (p.count("cut_normal") && p.at("cut_normal") != 0.0))
    return std::nullopt;
  return SteadyCuttingExpectation{scene.material.fracture_toughness * p.at("width"),
                                  scene.tools.front().blade.cutting_direction};
}

} // namespace

namespace {

/// One fast-model run of a study: the model on a scene (with calibrated parameters for a
/// "MODEL (calibrated)" row from a [calibration] file), its profile under `dir`.
struct ModelRun {
  std::size_t scene = 0;  ///< index into the planned scenes
  std::string model;      ///< catalogue name
  std::string label;      ///< the table's model column
  Scene scene_with_parameters;
  std::filesystem::path dir;
  PhenomenonSet represented;   ///< what the model reproduces of the scene (represented_phenomena)
  std::string not_applicable;  ///< why the model cannot run on the scene (then it is not run)
  bool anchors_fits = false;   ///< the model's fitted calibration row comes right after this one
};

using ReferenceSolve = StudyReferenceSolve;

struct PlannedScene {
  Scene scene;
  std::vector<std::size_t> levels; ///< indices into the planned reference solves, coarsest first
};

/// A calibration the study fits ([[calibrate]]): the fit on the calibration trajectory against
/// `reference` (an index into the planned solves), then the fitted model on the scene's own
/// trajectory, written under `dir` like any model run, with `parameters.toml` and
/// `calibration.txt` (the row's note) beside.
struct FitRun {
  std::size_t scene = 0;
  StudyCalibrationFit fit;
  std::optional<std::size_t> reference; ///< none when the fit is refused (`refusal`)
  std::string refusal;                  ///< why this reference cannot be fitted to
  std::string label;
  std::filesystem::path dir;
};

/// Why the study's reference of `scene` is no target for a calibration, or "" when it is one: a
/// cutting or tearing scene whose reference runs without fracture describes an uncut body, and a
/// model fitted to it would fit that, not the cut.
std::string fit_refusal(const Scene& scene, const StudyReferenceSpec& reference) {
  const bool separates = scene.phenomena.contains(Phenomenon::cutting) || scene.phenomena.contains(Phenomenon::tearing);
  if (separates && reference.fracture == ReferenceFracture::off)
    return "not calibrated: scene " + scene.name +
           " cuts or tears, and its reference runs without fracture ([reference] fracture = \"off\"): a fit to an uncut "
           "body would not be a calibration of the cut";
  return "";
}

/// The trajectory samples a reference solves on `scene`: `count` evenly spaced ones.
std::vector<std::size_t> solved_samples(const Scene& scene, int count) {
  std::size_t n = 0;
  for (const auto& t : sample_scene_trajectories(scene)) n = std::max(n, t.samples.size());
  return reference_sample_indices(n, count);
}

void write_text(const std::filesystem::path& file, const std::string& text) {
  std::filesystem::create_directories(file.parent_path());
  write_atomically(file, [&](const std::filesystem::path& tmp) {
    std::ofstream f(tmp);
    f << text;
    if (!f.flush()) throw std::runtime_error(file.string() + ": write failed");
  });
}

/// A `not run:` note goes into tables that are published (docs/results.md), so the scene file's
/// path in the model's message is written relative to the directory the study runs in (the
/// repository root for `kerf study default`), or as the file's name when the scene lies outside
/// it: the table then reads the same on every checkout.
std::string portable_note(std::string note, const Scene& scene) {
  namespace fs = std::filesystem;
  if (!scene.file.is_absolute()) return note;
  std::error_code error;
  fs::path shown = fs::relative(scene.file, fs::current_path(error), error);
  if (error || shown.empty() || *shown.begin() == "..") shown = scene.file.filename();
  const std::string absolute = scene.file.string();
  for (std::size_t at = note.find(absolute); at != std::string::npos; at = note.find(absolute, at + 1))
    note.replace(at, absolute.size(), shown.string());
  return note;
}

std::string read_text(const std::filesystem::path& file) {
  std::ifstream f(file);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

/// Runs `tasks` on `jobs` threads; each task catches its own failures.
void run_tasks(const std::vector<std::function<void()>>& tasks, int jobs) {
  std::atomic<std::size_t> next{0};
  std::mutex failure_mutex;
  std::exception_ptr failure;
  const auto worker = [&] {
    for (std::size_t k = next++; k < tasks.size(); k = next++) {
      try {
        tasks[k]();
      } catch (...) {
        const std::lock_guard lock(failure_mutex);
        if (!failure) failure = std::current_exception();
      }
    }
  };
  const auto threads = static_cast<std::size_t>(std::max(1, jobs));
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < std::min(threads, tasks.size()); ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}

/// "stiffness_scale 1 → 0.62": each free parameter from its start to its fitted value, in the
/// units of its parameter file, and the fracture exponents.
std::string describe_fit(const CalibrationResult& r) {
  std::string out;
  const auto free = free_parameters(r.fitted.model);
  for (std::size_t k = 0; k < free.size(); ++k) {
    char item[160];
    std::snprintf(item, sizeof item, "%s%s %.4g → %.4g%s%s", out.empty() ? "" : ", ", std::string(free[k].symbol).c_str(),
                  r.initial.values[k] / free[k].unit_value, r.fitted.values[k] / free[k].unit_value,
                  free[k].unit.empty() ? "" : " ", std::string(free[k].unit).c_str());
    out += item;
  }
  if (r.fitted.deformation_1_exponent) out += ", i = " + std::to_string(*r.fitted.deformation_1_exponent);
  if (r.fitted.deformation_2_exponent) out += ", j = " + std::to_string(*r.fitted.deformation_2_exponent);
  return out;
}

/// Runs `model` on `scene` and writes its profile and manifest under `dir`.
void run_and_write(const std::string& model, const Scene& scene, const TetMesh& mesh, const std::filesystem::path& dir) {
  BuiltModel built = make_model(model, scene, mesh);
  std::vector<std::string> names;
  for (const Tool& t : scene.tools) names.push_back(t.name);
  const auto begin = std::chrono::steady_clock::now();
  const ForceProfile profile = run_model(*built.model, names, sample_scene_trajectories(scene));
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  write_run(dir, profile, run_manifest(scene, built, mesh, profile, wall));
}

/// Everything a study runs, planned from its file: the same on every rank and for
/// study_reference_solves.
struct StudyPlan {
  std::vector<PlannedScene> scenes;
  std::vector<ReferenceSolve> solves;
  std::vector<ModelRun> model_runs;
  std::vector<FitRun> fit_runs;
};

StudyPlan plan_study(const StudySpec& spec, const std::filesystem::path& out, bool reference_wanted = true) {
  namespace fs = std::filesystem;
  StudyPlan plan;
  std::vector<PlannedScene>& scenes = plan.scenes;
  std::vector<ReferenceSolve>& solves = plan.solves;
  std::vector<ModelRun>& model_runs = plan.model_runs;
  std::vector<FitRun>& fit_runs = plan.fit_runs;
  const bool with_reference = spec.has_reference && reference_wanted;
  const auto plan_solve = [&](const Scene& scene, int level, int samples) {
    ReferenceSolve solve{study_reference_scene(scene, level), level, solved_samples(scene, samples), {}, {}};
    const ReferenceCacheKey key = reference_cache_key(solve.scene, study_reference_settings(spec.reference, solve.scene, level, solve.indices));
    solve.dir = out / "cache" / key.directory;
    solve.key_text = key.text;
    solves.push_back(std::move(solve));
    return solves.size() - 1;
  };
  for (const fs::path& scene_file : spec.scenes) {
    PlannedScene planned{read_scene(scene_file), {}};
    const Scene& scene = planned.scene;
    if (with_reference)
      for (int level : spec.reference.levels_of(scene_file.stem().string()))
        planned.levels.push_back(plan_solve(scene, level, spec.reference.samples_of(scene_file.stem().string())));
    const std::size_t index = scenes.size();
    for (const std::string& model : spec.models) {
      PhenomenonSet represented;
      try {
        represented = represented_phenomena(model, scene);
      } catch (const ModelMismatch& e) {
        // Not applicable: a row without numbers whose note says why.
        model_runs.push_back({index, model, model, scene, out / scene.name / model, {}, portable_note(std::string("not run: ") + e.what(), scene)});
        continue;
      }
      const auto sweep = spec.resolutions.find(model);
      if (sweep == spec.resolutions.end()) {
        model_runs.push_back({index, model, model, scene, out / scene.name / model, represented, "", true});
      } else {
        // The model at each of its resolutions: the points of its speed/accuracy curve.
        for (int value : sweep->second) {
          try {
            ModelResolution r = at_resolution(model, scene, value);
            model_runs.push_back({index, model, r.label, std::move(r.scene), out / scene.name / r.directory, represented, "",
                                  value == sweep->second.back()});
          } catch (const ModelMismatch& e) {
            model_runs.push_back({index, model, model, scene, out / scene.name / model, {},
                                  portable_note(std::string("not run: ") + e.what(), scene), value == sweep->second.back()});
            break;
          }
        }
      }
      const auto calibrated = spec.calibrations.find(scene_file.stem().string());
      if (calibrated != spec.calibrations.end())
        for (const fs::path& parameters : calibrated->second) {
          const auto models = calibrated_models(parameters);
          if (std::find(models.begin(), models.end(), model) == models.end()) continue;
          model_runs.push_back({index, model, model + " (calibrated)", read_scene(scene_file, {parameters}),
                                out / scene.name / (model + "-calibrated"), represented, ""});
        }
      for (const StudyCalibrationFit& fit : spec.fits) {
        if (!with_reference || fit.scene != scene_file.stem().string() || fit.model != model) continue;
        FitRun run{index, fit, std::nullopt, fit_refusal(scene, spec.reference), model + " (calibrated)",
                   out / scene.name / (model + "-calibrated")};
        if (run.refusal.empty()) {
          try {
            const std::vector<int>& levels = spec.reference.levels_of(scene_file.stem().string());
            run.reference = plan_solve(calibration_scene(scene, fit.speed), *std::max_element(levels.begin(), levels.end()),
                                       fit.samples > 0 ? fit.samples : spec.reference.samples_of(scene_file.stem().string()));
          } catch (const std::invalid_argument& e) {
            run.refusal = std::string("not calibrated: ") + e.what();
          }
        }
        fit_runs.push_back(std::move(run));
      }
    }
    scenes.push_back(std::move(planned));
  }
  return plan;
}

/// Copies a reference solve's files from one entry folder (cache or library) to another, each
/// written atomically, the profile last: its presence marks the entry as complete.
void copy_reference_entry(const std::filesystem::path& from, const std::filesystem::path& to) {
  for (const char* f : {"manifest.json", "key.txt", "profile.csv"})
    if (std::filesystem::exists(from / f)) write_text(to / f, read_text(from / f));
}

/// Copies a solve's library entry into the study's cache when the library
/// holds one under the solve's key: the same key text, so the same scene, mesh, samples and solver.
void take_from_library(const std::filesystem::path& library, const ReferenceSolve& solve) {
  namespace fs = std::filesystem;
  if (library.empty()) return;
  const fs::path entry = library / solve.dir.filename();
  if (!fs::exists(entry / "profile.csv") || !fs::exists(entry / "key.txt") || read_text(entry / "key.txt") != solve.key_text) return;
  copy_reference_entry(entry, solve.dir);
}

} // namespace

StudyResult run_study(const StudySpec& spec, const std::filesystem::path& out, const ReferenceRunner& reference,
                      const StudyExecution& execution) {
  namespace fs = std::filesystem;
  if (execution.ranks > 1 && !execution.synchronise)
    throw std::invalid_argument("run_study: " + std::to_string(execution.ranks) + " ranks need a synchronise function");
  const auto synchronise = [&](int value) { return execution.ranks > 1 ? execution.synchronise(value) : value; };

  // Plan (every rank the same): scenes, reference solves, model runs, fitted calibrations.
  StudyPlan plan = plan_study(spec, out, static_cast<bool>(reference));
  std::vector<PlannedScene>& scenes = plan.scenes;
  std::vector<ReferenceSolve>& solves = plan.solves;
  std::vector<ModelRun>& model_runs = plan.model_runs;
  std::vector<FitRun>& fit_runs = plan.fit_runs;
  // A solve the cache lacks and the study's reference library holds, with the same key, is taken
  // from the library into the cache.
  if (execution.rank == 0)
    for (const ReferenceSolve& solve : solves)
      if (!fs::exists(solve.dir / "profile.csv")) take_from_library(spec.reference.library, solve);
  std::vector<std::size_t> reference_runs; // solves not cached
  for (std::size_t k = 0; k < solves.size(); ++k)
    if (!fs::exists(solves[k].dir / "profile.csv")) reference_runs.push_back(k);
  synchronise(0); // every rank has looked at the cache before any rank writes to it

  // This rank's share: run k (references first, then models, then fits) belongs to rank k mod ranks.
  const auto mine = [&](std::size_t k) { return static_cast<int>(k % static_cast<std::size_t>(execution.ranks)) == execution.rank; };
  std::vector<std::size_t> my_references;
  for (std::size_t k = 0; k < reference_runs.size(); ++k)
    if (mine(k)) my_references.push_back(reference_runs[k]);
  std::vector<const ModelRun*> my_models;
  for (std::size_t k = 0; k < model_runs.size(); ++k)
    if (mine(reference_runs.size() + k) && model_runs[k].not_applicable.empty()) my_models.push_back(&model_runs[k]);
  std::vector<const FitRun*> my_fits;
  for (std::size_t k = 0; k < fit_runs.size(); ++k)
    if (mine(reference_runs.size() + model_runs.size() + k)) my_fits.push_back(&fit_runs[k]);

  // Meshes of the scenes this rank runs models on, made before the threads start.
  std::map<std::size_t, TetMesh> meshes;
  for (const ModelRun* run : my_models)
    if (!meshes.count(run->scene)) meshes.emplace(run->scene, scene_mesh(scenes[run->scene].scene));
  for (const FitRun* run : my_fits)
    if (!meshes.count(run->scene)) meshes.emplace(run->scene, scene_mesh(scenes[run->scene].scene));

  // Phase 1: the reference solves and the model runs.
  std::vector<std::function<void()>> tasks;
  int solved = 0;
  if (!my_references.empty())
    tasks.emplace_back([&] { // one at a time: PETSc is not thread-safe
      for (std::size_t k : my_references) {
        const ReferenceSolve& solve = solves[k];
        fs::remove(solve.dir / "error.txt");
        try {
          const ForceProfile p = reference(solve.scene, spec.reference, solve.level, solve.indices, solve.dir);
          if (!fs::exists(solve.dir / "profile.csv")) write_profile_csv(p, solve.dir / "profile.csv");
          write_text(solve.dir / "key.txt", solve.key_text);
          ++solved;
        } catch (const std::exception& e) {
          write_text(solve.dir / "error.txt", e.what());
        }
      }
    });
  for (const ModelRun* run : my_models)
    tasks.emplace_back([&, run] {
      fs::remove(run->dir / "profile.csv");
      fs::remove(run->dir / "note.txt");
      try {
        run_and_write(run->model, run->scene_with_parameters, meshes.at(run->scene), run->dir);
      } catch (const std::exception& e) {
        write_text(run->dir / "note.txt", e.what());
      }
    });
  const auto started = std::chrono::steady_clock::now();
  const auto seconds_since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  };
  run_tasks(tasks, execution.jobs);

  StudyResult result;
  result.machine = machine_label();
  result.jobs = execution.jobs;
  result.ranks = execution.ranks;
  result.reference_runs = synchronise(solved); // every reference is on disk: the fits may read theirs
  result.run_seconds = seconds_since(started);

  // Phase 2: the fitted calibrations, each against its reference on the calibration trajectory,
  // then scored on the scene's own trajectory.
  tasks.clear();
  for (const FitRun* run : my_fits)
    tasks.emplace_back([&, run] {
      for (const char* f : {"profile.csv", "note.txt", "calibration.txt", "parameters.toml"}) fs::remove(run->dir / f);
      try {
        if (!run->reference) throw std::runtime_error(run->refusal);
        const ReferenceSolve& target_solve = solves[*run->reference];
        if (!fs::exists(target_solve.dir / "profile.csv"))
          throw std::runtime_error("not calibrated: its reference failed: " +
                                   (fs::exists(target_solve.dir / "error.txt") ? read_text(target_solve.dir / "error.txt") : "no profile written"));
        char speed[32];
        std::snprintf(speed, sizeof speed, "%g", run->fit.speed);
        const std::string label = "reference L" + std::to_string(target_solve.level) + " at speed ×" + speed;
        const CalibrationTarget target{label, target_solve.scene, read_profile_csv(target_solve.dir / "profile.csv")};
        CalibrationSettings settings;
        settings.simplex.max_evaluations = run->fit.max_evaluations;
        // 1e-3 in ln p: 0.1 % of each value, far below the reference's own discretisation error
        // (the reference L<k> rows), which bounds what a fit to it can mean.
        settings.simplex.step_tolerance = 1e-3;
        const TetMesh& mesh = meshes.at(run->scene);
        CalibrationResult fitted;
        try {
          fitted = calibrate(run->fit.model, target, mesh, settings);
        } catch (const std::exception& e) {
          throw std::runtime_error(std::string("not calibrated: ") + e.what());
        }
        const Scene& scene = scenes[run->scene].scene;
        char errors[160];
        std::snprintf(errors, sizeof errors, "RMS error there %.3g %% → %.3g %%, %d runs%s", 100.0 * fitted.initial_error,
                      100.0 * fitted.fitted_error, fitted.evaluations, fitted.converged ? "" : ", evaluation limit reached");
        const std::string note = "fitted at speed ×" + std::string(speed) + " to " + target_solve.scene.name + "'s " + label.substr(0, label.find(" at")) +
                                 ": " + describe_fit(fitted) + " (" + errors + ")";
        run_and_write(run->fit.model, with_parameters(scene, fitted.fitted), mesh, run->dir);
        write_text(run->dir / "parameters.toml",
                   parameter_file_text(fitted.fitted, "Fitted by kerf study " + spec.name + " ([[calibrate]] " + run->fit.model + " on " +
                                                          scene.name + "): " + note + "\n"));
        write_text(run->dir / "calibration.txt", note);
      } catch (const std::exception& e) {
        write_text(run->dir / "note.txt", e.what());
      }
    });
  const auto fits_started = std::chrono::steady_clock::now();
  run_tasks(tasks, execution.jobs);
  synchronise(0);
  result.fit_seconds = seconds_since(fits_started);
  if (execution.rank != 0) return result;

  // Rank 0: the table, from what every rank wrote.
  for (std::size_t s = 0; s < scenes.size(); ++s) {
    const Scene& scene = scenes[s].scene;
    std::map<int, ForceProfile> references;
    SceneReference verified{scene.name, scene.tools.front().name, {}, {}, {}, std::nullopt, ""};
    std::vector<ReferenceLevel> levels;
    std::string failed_levels; // coarser levels that failed: the table goes on without them, saying so
    for (std::size_t k : scenes[s].levels) {
      const ReferenceSolve& solve = solves[k];
      if (!fs::exists(solve.dir / "profile.csv")) {
        const std::string why = "reference of scene " + scene.name + " at level " + std::to_string(solve.level) + " failed: " +
                                (fs::exists(solve.dir / "error.txt") ? read_text(solve.dir / "error.txt") : "no profile written");
        if (k == scenes[s].levels.back()) throw std::runtime_error(why); // the finest: nothing to score against
        failed_levels += "L" + std::to_string(solve.level) + " failed (" + why.substr(why.find("failed: ") + 8) + "); ";
        continue;
      }
      references[solve.level] = read_profile_csv(solve.dir / "profile.csv");
      verified.levels.push_back(solve.level);
      verified.element_sizes.push_back(study_reference_element_size(scene, solve.level));
      verified.profiles.push_back(solve.dir / "profile.csv");
      levels.push_back({solve.level, verified.element_sizes.back(), references[solve.level]});
    }
    const ForceProfile* finest = references.empty() ? nullptr : &references.rbegin()->second;
    const std::string tool = scene.tools.front().name;

    // The finest reference first, with its uncertainty: the solution verification of its three
    // finest levels (reference_verification.hpp), or why there is none.
    if (finest) {
      const int finest_level = references.rbegin()->first;
      try {
        verified.verification = verify_reference(levels, tool, spec.reference.degree_of(scene.file.stem().string(), scene.geometry.element_degree) + 1.0);
        verified.note = verified.verification ? verified.verification->summary()
                                              : "no GCI available: " + std::to_string(levels.size()) +
                                                    " mesh level(s), solution verification needs 3 ([reference] refinements)";
      } catch (const std::exception& e) {
        verified.note = std::string("no GCI available: ") + e.what();
      }
      verified.note = failed_levels + verified.note;
      // From each level's manifest, read once: the finest reference's own resolution check (the
      // cohesive zone's elements, reference_fracture.hpp), which a reference that fails says on its
      // row; and a load path that stopped short of the trajectory's end (`stopped`), so that the
      // level is verified and scored on the samples it reached only, which its row says first.
      std::string resolution, stopped;
      for (std::size_t k : scenes[s].levels) {
        if (!fs::exists(solves[k].dir / "manifest.json")) continue;
        std::ifstream in(solves[k].dir / "manifest.json");
        const nlohmann::json manifest = nlohmann::json::parse(in, nullptr, false);
        if (manifest.is_discarded()) continue;
        if (solves[k].level == finest_level && manifest.contains("fracture") && manifest.at("fracture").contains("warning") &&
            manifest.at("fracture").at("warning").is_string() && !manifest.at("fracture").at("warning").get<std::string>().empty())
          resolution = "fails its resolution check: " + manifest.at("fracture").at("warning").get<std::string>() + "; ";
        if (manifest.contains("stopped") && manifest.at("stopped").is_string())
          stopped = "L" + std::to_string(solves[k].level) + " stopped before the trajectory's end (" +
                    manifest.at("stopped").get<std::string>().substr(0, 160) + "…); " + stopped;
      }
      verified.note = stopped + resolution + verified.note;
      char size[64];
      std::snprintf(size, sizeof size, "mesh h = %.3g mm; ", study_reference_element_size(scene, finest_level) * 1e3);
      StudyRow row{scene.name, "reference L" + std::to_string(finest_level), std::nullopt, cost_statistics(*finest), size + verified.note, {}};
      for (std::size_t k = 0; k < verified.levels.size(); ++k)
        if (verified.levels[k] == finest_level) row.profile = verified.profiles[k];
      result.rows.push_back(std::move(row));
    }
    // A model's RMS force error is a norm of its difference to the reference profile: it is set
    // beside the profile's uncertainty in the same norm.
    const std::optional<double> rms_uncertainty = verified.verification ? verified.verification->profile_uncertainty() : std::nullopt;
    const std::optional<double> peak_uncertainty = verified.verification ? verified.verification->peak_uncertainty() : std::nullopt;

    // The reference's own discretisation error: each coarser level against the finest.
    for (const auto& [level, profile] : references) {
      if (&profile == finest) continue;
      char note[160];
      std::snprintf(note, sizeof note, "mesh h = %.3g mm against the finest, L%d with h = %.3g mm", study_reference_element_size(scene, level) * 1e3,
                    references.rbegin()->first, study_reference_element_size(scene, references.rbegin()->first) * 1e3);
      StudyRow row{scene.name, "reference L" + std::to_string(level), std::nullopt, cost_statistics(profile), note, {}};
      for (std::size_t k = 0; k < verified.levels.size(); ++k)
        if (verified.levels[k] == level) row.profile = verified.profiles[k];
      try {
        row.metrics = compare_profiles(at_common_times(profile, *finest), at_common_times(*finest, profile), tool);
      } catch (const std::exception& e) {
        row.note += std::string("; ") + e.what();
      }
      result.rows.push_back(std::move(row));
    }
    if (finest) result.references.push_back(std::move(verified));

    // The model rows, each fitted calibration right after its model's plain row; a model that
    // cannot run on the scene has its row too, saying why.
    std::vector<std::tuple<std::string, fs::path, bool, const ModelRun*>> rows; // label, dir, fitted, run
    for (const ModelRun& run : model_runs) {
      if (run.scene != s) continue;
      rows.emplace_back(run.label, run.dir, false, &run);
      for (const FitRun& fit : fit_runs)
        if (fit.scene == s && fit.fit.model == run.model && run.anchors_fits) rows.emplace_back(fit.label, fit.dir, true, &run);
    }
    const auto join = [](const std::string& a, const std::string& b) { return a.empty() ? b : b.empty() ? a : a + "; " + b; };
    for (const auto& [label, dir, fitted, run] : rows) {
      StudyRow row{scene.name, label, std::nullopt, {}, "", {}};
      if (!run->not_applicable.empty()) {
        row.note = run->not_applicable;
        result.rows.push_back(std::move(row));
        continue;
      }
      if (!fs::exists(dir / "profile.csv")) {
        row.note = fs::exists(dir / "note.txt") ? read_text(dir / "note.txt") : "no profile written";
        result.rows.push_back(std::move(row));
        continue;
      }
      if (fitted) row.note = read_text(dir / "calibration.txt");
      try {
        const ForceProfile profile = read_profile_csv(dir / "profile.csv");
        row.profile = dir / "profile.csv";
        row.cost = cost_statistics(profile);
        if (finest) {
          // Scored only over the phases the model represents (springs on a blade: before the cut).
          const ScoredSamples scored = represented_samples(*finest, scene.phenomena, run->represented);
          row.note = join(row.note, scored.note);
          if (!scored.reference.rows.empty())
            row.metrics = compare_profiles(at_common_times(profile, scored.reference), at_common_times(scored.reference, profile),
                                           tool, expected_cutting(scene));
          // An error the reference cannot resolve is not shown as a number: compared in
          // newtons with the uncertainty of the finest reference's RMS |F| and peak |F|.
          if (row.metrics && rms_uncertainty)
            row.rms_below_reference_uncertainty =
                row.metrics->normalised_rms_force_error * row.metrics->reference_peak_force < *rms_uncertainty;
          if (row.metrics && peak_uncertainty)
            row.peak_below_reference_uncertainty =
                std::abs(row.metrics->peak_force_error) * row.metrics->reference_peak_force < *peak_uncertainty;
        }
      } catch (const std::exception& e) {
        row.note = join(row.note, e.what());
      }
      result.rows.push_back(std::move(row));
    }
  }
  return result;
}

StudyTable StudyResult::table() const {
  StudyTable t({{"scene", "", 3, 1.0},
                {"model", "", 3, 1.0},
                {"RMS force error", "%", 3, 100.0},
                {"peak force error", "%", 3, 100.0},
                {"rupture travel error", "mm", 3, 1e3},
                {"steady cutting error", "%", 3, 100.0},
                {"work error", "%", 3, 100.0},
                {"mode agreement", "%", 3, 100.0},
                {"median cost", "µs", 3, 1e6},
                {"p99 cost", "µs", 3, 1e6},
                {"max cost", "µs", 3, 1e6},
                {"rate allowed", "kHz", 3, 1e-3},
                {"note", "", 3, 1.0}});
  t.group_by_first_column(true);
  if (!machine.empty())
    t.set_caption("Costs: wall time per servo step on " + machine + ", " + std::to_string(jobs) + " job(s)" +
                   (ranks > 1 ? " × " + std::to_string(ranks) + " ranks" : std::string()) +
                   (jobs * ranks > 1 ? " at once (a run beside others is slower; --jobs 1 for undisturbed costs)" : "") + ".");
  using O = std::optional<double>;
  for (const StudyRow& r : rows) {
    const bool m = r.metrics.has_value();
    const bool c = r.cost.steps > 0;
    using Cell = StudyTable::Cell;
    const Cell rms = r.rms_below_reference_uncertainty ? Cell{std::string(below_reference_uncertainty)}
                                                       : Cell{m ? O(r.metrics->normalised_rms_force_error) : O()};
    const Cell peak = r.peak_below_reference_uncertainty ? Cell{std::string(below_reference_uncertainty)}
                                                         : Cell{m ? O(r.metrics->peak_force_error) : O()};
    t.add_row({r.scene, r.model, rms, peak, m ? r.metrics->rupture_displacement_error : O(),
               m ? r.metrics->steady_cutting_force_error : O(), m ? O(r.metrics->work_error) : O(),
               m ? O(r.metrics->mode_agreement) : O(), c ? O(r.cost.median) : O(), c ? O(r.cost.p99) : O(),
               c ? O(r.cost.max) : O(), c ? O(r.cost.rate_allowed()) : O(), r.note});
  }
  return t;
}

std::vector<StudyReferenceSolve> study_reference_solves(const StudySpec& spec, const std::filesystem::path& out) {
  return plan_study(spec, out).solves;
}

int publish_references(const std::vector<StudyReferenceSolve>& solves, const std::filesystem::path& library,
                       const std::string& command) {
  namespace fs = std::filesystem;
  int published = 0;
  for (const StudyReferenceSolve& solve : solves) {
    if (!fs::exists(solve.dir / "profile.csv")) continue;
    const fs::path entry = library / solve.dir.filename();
    copy_reference_entry(solve.dir, entry);
    write_text(entry / "command.txt", command + "\n");
    ++published;
  }
  std::set<std::string> planned;
  for (const StudyReferenceSolve& solve : solves) planned.insert(solve.dir.filename().string());
  std::vector<fs::path> stale;
  for (const fs::directory_entry& e : fs::directory_iterator(library))
    if (e.is_directory() && fs::exists(e.path() / "key.txt") && planned.count(e.path().filename().string()) == 0)
      stale.push_back(e.path());
  for (const fs::path& p : stale) fs::remove_all(p);
  return published;
}

} // namespace kerf
