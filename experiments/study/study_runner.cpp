#include "experiments/study/study_runner.hpp"

#include "experiments/calibration/calibration.hpp"
#include "experiments/models/model_catalogue.hpp"
#include "experiments/records/content_hash.hpp"
#include "experiments/records/run_record.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"
#include "experiments/study/machine_label.hpp"
#include "experiments/study/reference_cache.hpp"
#include "experiments/study/study_progress.hpp"
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
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

namespace kerf {

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
  return [](const StudyReferenceSolve& solve, const StudyReferenceSpec& spec) {
    return run_reference(solve.scene, scene_mesh(solve.scene, MeshPurpose::reference),
                         study_reference_settings(spec, solve.scene, solve.level, solve.indices, solve.increment), solve.dir);
  };
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

namespace fs = std::filesystem;

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

void write_text(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  write_atomically(file, [&](const fs::path& tmp) {
    std::ofstream f(tmp);
    f << text;
    if (!f.flush()) throw std::runtime_error(file.string() + ": write failed");
  });
}

std::string read_text(const fs::path& file) {
  std::ifstream f(file);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
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

/// A run's result is its profile in memory; its record on disk (profile.csv and manifest, for the
/// plots and for the reader) may fail to be written — a full disk, a folder that cannot be made —
/// without losing the result: the returned note then says so.
struct RecordedRun {
  ForceProfile profile;
  std::string record_note; ///< empty when the record was written
};

/// Runs `model` on `scene`, writes its profile and manifest under `dir` (the run's record) and
/// returns the profile.
RecordedRun run_and_record(const std::string& model, const Scene& scene, const TetMesh& mesh, const fs::path& dir) {
  BuiltModel built = make_model(model, scene, mesh);
  std::vector<std::string> names;
  for (const Tool& t : scene.tools) names.push_back(t.name);
  const auto begin = std::chrono::steady_clock::now();
  RecordedRun out{run_model(*built.model, names, sample_scene_trajectories(scene)), ""};
  try {
    write_run(dir, out.profile, run_manifest(scene, built, mesh, out.profile, seconds_since(begin)));
  } catch (const std::exception& e) {
    out.record_note = std::string("its record was not written (") + e.what() + "): the table holds it, the plots do not";
  }
  return out;
}

/// Removes `names` from `dir` where they exist; a folder that cannot be read is left to the write
/// that follows to report.
void remove_records(const fs::path& dir, std::initializer_list<const char*> names) {
  std::error_code ignored;
  for (const char* name : names) fs::remove(dir / name, ignored);
}

/// Copies a reference solve's files from one entry folder (cache or library) to another, each
/// written atomically, the profile last: its presence marks the entry as complete.
void copy_reference_entry(const fs::path& from, const fs::path& to) {
  for (const char* f : {"manifest.json", "key.txt", "profile.csv"})
    if (fs::exists(from / f)) write_text(to / f, read_text(from / f));
}

/// Copies a solve's library entry into the study's cache when the library holds one under the
/// solve's key: the same key text, so the same scene, mesh, samples and solver.
void take_from_library(const fs::path& library, const StudyReferenceSolve& solve) {
  if (library.empty()) return;
  const fs::path entry = library / solve.dir.filename();
  if (!fs::exists(entry / "profile.csv") || !fs::exists(entry / "key.txt") || read_text(entry / "key.txt") != solve.key_text) return;
  copy_reference_entry(entry, solve.dir);
}

/// What one reference solve of the study gave.
struct SolveOutcome {
  std::optional<ForceProfile> profile;
  std::string error;      ///< why there is no profile
  std::string stopped;    ///< its load path stopped before the trajectory's end (the profile is partial)
  std::string resolution; ///< its cohesive zone's resolution warning
};

/// A solve's outcome from its record in the cache (a solve cached before this run, or another
/// rank's): profile.csv, error.txt and the manifest's `stopped` and fracture warning.
SolveOutcome read_solve(const StudyReferenceSolve& solve) {
  SolveOutcome out;
  if (fs::exists(solve.dir / "profile.csv")) out.profile = read_profile_csv(solve.dir / "profile.csv");
  else out.error = fs::exists(solve.dir / "error.txt") ? read_text(solve.dir / "error.txt") : "no profile written";
  if (fs::exists(solve.dir / "manifest.json")) {
    std::ifstream in(solve.dir / "manifest.json");
    const nlohmann::json m = nlohmann::json::parse(in, nullptr, false);
    if (!m.is_discarded()) {
      if (m.contains("stopped") && m.at("stopped").is_string()) out.stopped = m.at("stopped").get<std::string>();
      if (m.contains("fracture") && m.at("fracture").is_object() && m.at("fracture").contains("warning") &&
          m.at("fracture").at("warning").is_string())
        out.resolution = m.at("fracture").at("warning").get<std::string>();
    }
  }
  return out;
}

/// What one model run (or fitted calibration) of the study gave.
struct RunOutcome {
  std::optional<ForceProfile> profile;
  std::string note;                  ///< why there is no profile
  std::string calibration;           ///< a fit: what was fitted, on which trajectory
  std::optional<Scene> fitted_scene; ///< a fit: the scene with its fitted parameters
  std::optional<TimedCost> timed;    ///< from the timing pass
};

/// A model run's outcome from its record (another rank's run).
RunOutcome read_run(const fs::path& dir, const fs::path& scene_file, bool fitted) {
  RunOutcome out;
  if (fs::exists(dir / "profile.csv")) {
    out.profile = read_profile_csv(dir / "profile.csv");
    if (fitted) {
      out.calibration = read_text(dir / "calibration.txt");
      out.fitted_scene = read_scene(scene_file, {dir / "parameters.toml"});
    }
  } else {
    out.note = fs::exists(dir / "note.txt") ? read_text(dir / "note.txt") : "no profile written";
  }
  return out;
}

/// What of the reference's verification misses the study's target (each uncertainty ≤ 2 % of the
/// peak, docs/studies.md), and why, for its row's note; empty when both meet it.
std::string target_note(const SceneReference& r) {
  constexpr double target = 0.02;
  std::string out;
  char text[320];
  if (r.verification && r.verification->profile_uncertainty() && r.verification->peak_force > 0.0) {
    const double u = *r.verification->profile_uncertainty() / r.verification->peak_force;
    if (u > target) {
      std::snprintf(text, sizeof text, "; in space %.2g %% of the peak, above the 2 %% target: the mesh levels' profiles still differ by %.3g and "
                    "%.3g N RMS (a finer mesh would lower it)", 100.0 * u, r.verification->profile.e21, r.verification->profile.e32);
      out += text;
    }
  } else if (r.verification) {
    out += "; in space no uncertainty, so no check against the 2 % target (" + r.verification->profile.unusable + ")";
  }
  if (r.sampling && r.sampling->peak_force > 0.0) {
    const double u = r.sampling->uncertainty() / r.sampling->peak_force;
    if (u > target) {
      std::snprintf(text, sizeof text, "; in time %.2g %% of the peak, above the 2 %% target: the two load increments leave the body in "
                    "different states, most at t = %.4g s (%s), where the crack or the contact advanced by other steps",
                    100.0 * u, r.sampling->largest_difference_time, std::string(to_string(r.sampling->largest_difference_mode)).c_str());
      out += text;
    }
  }
  return out;
}

/// The calibration a study fits with ([[calibrate]]): the fit's run budget, a step tolerance of
/// 1e-3 in ln p — 0.1 % of each value, far below the reference's own discretisation error (the
/// reference L<k> rows), which bounds what a fit to it can mean.
CalibrationSettings study_calibration_settings(const StudyCalibrationFit& fit) {
  CalibrationSettings settings;
  settings.simplex.max_evaluations = fit.max_evaluations;
  settings.simplex.step_tolerance = 1e-3;
  return settings;
}

/// A fitted calibration's identity in the study's library (docs/studies.md, "Reference library"):
/// every input that changes the fitted parameters — the scene file, the model and its free
/// parameters, the calibration trajectory's speed, the fit's settings, and the target (the
/// reference solve's own key) — and the version of the fast models and the calibration
/// (study_fit_version), so a fit taken from the library is the fit this build would make.
struct FitKey {
  std::string text;
  std::string directory; ///< `fits/<scene>-<model>-<sha256 of text, 16 hex>`
};

FitKey fit_key(const StudyFitRun& run, const Scene& scene, const StudyReferenceSolve& target) {
  const CalibrationSettings settings = study_calibration_settings(run.fit);
  char numbers[256];
  std::snprintf(numbers, sizeof numbers,
                "speed = %.17g\nmax_evaluations = %d\nstep_tolerance = %.17g\nscreening_evaluations = %d\nrefined_pairs = %d\n",
                run.fit.speed, settings.simplex.max_evaluations, settings.simplex.step_tolerance, settings.screening_evaluations,
                settings.refined_pairs);
  std::string parameters;
  for (const FreeParameter& p : free_parameters(run.fit.model)) parameters += " " + std::string(p.symbol);
  FitKey key;
  key.text = "fit_version = " + std::to_string(study_fit_version) + "\nscene_file_sha256 = " + file_sha256(scene.file) +
             "\nmodel = " + run.fit.model + "\nfree_parameters =" + parameters + "\n" + numbers +
             "target_key_sha256 = " + text_sha256(target.key_text) + "\n";
  key.directory = "fits/" + scene.name + "-" + run.fit.model + "-" + text_sha256(key.text).substr(0, 16);
  return key;
}

std::string level_name(const StudyReferenceSolve& solve) {
  return "reference L" + std::to_string(solve.level) + (solve.increment == LoadIncrement::half ? " (half increment)" : "");
}

/// A study's run: its plan, every run's outcome, and the steps from the plan to the table (see
/// run_study in study_runner.hpp). run() is the driver.
class StudyRun {
public:
  StudyRun(const StudySpec& spec, fs::path out, const ReferenceRunner& reference, const StudyExecution& execution)
      : m_spec(spec), m_out(std::move(out)), m_reference(reference), m_execution(execution),
        m_plan(plan_study(spec, m_out, static_cast<bool>(reference))), m_solves(m_plan.solves.size()),
        m_models(m_plan.model_runs.size()), m_fits(m_plan.fit_runs.size()) {}

  StudyResult run();

private:
  int synchronise(int value) const { return m_execution.ranks > 1 ? m_execution.synchronise(value) : value; }
  bool mine(std::size_t k) const { return static_cast<int>(k % static_cast<std::size_t>(m_execution.ranks)) == m_execution.rank; }
  void share_work();
  void make_meshes(const std::set<std::size_t>& scenes);
  void solve_references();
  void run_model(std::size_t k);
  void fit(std::size_t k);
  void collect_references();
  void collect_runs();
  void time_models();
  void scene_rows(std::size_t s, StudyResult& result) const;
  std::optional<SceneReference> verify(std::size_t s, StudyResult& result) const;
  std::string verify_in_time(const StudyPlannedScene& planned, SceneReference& verified, std::optional<ForceProfile>& half,
                             StudyResult& result) const;
  void coarser_reference_rows(const StudyPlannedScene& planned, const SceneReference& verified, const std::vector<ReferenceLevel>& levels,
                              const std::optional<ForceProfile>& half, StudyResult& result) const;
  void model_rows(std::size_t s, const SceneReference* reference, StudyResult& result) const;
  StudyRow model_row(const StudyPlannedScene& scene, const std::string& label, const StudyModelRun& run, const RunOutcome& outcome,
                     const fs::path& dir, const SceneReference* reference) const;

  const StudySpec& m_spec;
  const fs::path m_out;
  const ReferenceRunner& m_reference;
  const StudyExecution& m_execution;
  StudyPlan m_plan;
  std::vector<SolveOutcome> m_solves;
  std::vector<RunOutcome> m_models, m_fits;
  std::vector<std::size_t> m_reference_runs;           ///< solves not in the cache
  std::vector<std::size_t> m_my_references, m_my_models, m_my_fits;
  std::map<std::size_t, TetMesh> m_meshes;
  std::unique_ptr<StudyProgress> m_progress;
  int m_solved = 0;
  std::atomic<int> m_fitted{0};
};

/// The cache first (the library's entries copied in), then this rank's share: run k (references
/// first, then models, then fits) belongs to rank k mod ranks.
void StudyRun::share_work() {
  if (m_execution.rank == 0)
    for (const StudyReferenceSolve& solve : m_plan.solves)
      if (!fs::exists(solve.dir / "profile.csv")) take_from_library(m_spec.reference.library, solve);
  for (std::size_t k = 0; k < m_plan.solves.size(); ++k)
    if (!fs::exists(m_plan.solves[k].dir / "profile.csv")) m_reference_runs.push_back(k);
  synchronise(0); // every rank has looked at the cache before any rank writes to it
  for (std::size_t k = 0; k < m_reference_runs.size(); ++k)
    if (mine(k)) m_my_references.push_back(m_reference_runs[k]);
  for (std::size_t k = 0; k < m_plan.model_runs.size(); ++k)
    if (mine(m_reference_runs.size() + k) && m_plan.model_runs[k].not_applicable.empty()) m_my_models.push_back(k);
  for (std::size_t k = 0; k < m_plan.fit_runs.size(); ++k)
    if (mine(m_reference_runs.size() + m_plan.model_runs.size() + k)) m_my_fits.push_back(k);
  m_progress = std::make_unique<StudyProgress>(m_spec.name, m_execution.progress);
  m_progress->expect(StudyProgress::Kind::reference_solve, m_my_references.size());
  m_progress->expect(StudyProgress::Kind::model_run, m_my_models.size());
  m_progress->expect(StudyProgress::Kind::fit, m_my_fits.size());
}

/// The fast models' meshes of `scenes`, made before any thread starts.
void StudyRun::make_meshes(const std::set<std::size_t>& scenes) {
  for (std::size_t s : scenes)
    if (!m_meshes.count(s)) m_meshes.emplace(s, scene_mesh(m_plan.scenes[s].scene));
}

/// This rank's reference solves, one at a time (PETSc is not thread-safe), each recorded in its
/// cache entry: profile.csv, manifest.json and key.txt, or error.txt.
void StudyRun::solve_references() {
  for (std::size_t k : m_my_references) {
    const StudyReferenceSolve& solve = m_plan.solves[k];
    const auto begin = std::chrono::steady_clock::now();
    fs::remove(solve.dir / "error.txt");
    SolveOutcome& outcome = m_solves[k];
    try {
      ReferenceResult r = m_reference(solve, m_spec.reference);
      if (!fs::exists(solve.dir / "profile.csv")) write_profile_csv(r.profile, solve.dir / "profile.csv");
      write_text(solve.dir / "key.txt", solve.key_text);
      outcome = read_solve(solve); // the manifest's notes beside the profile
      outcome.profile = std::move(r.profile);
      if (!r.complete()) outcome.stopped = r.stopped;
      ++m_solved;
    } catch (const std::exception& e) {
      write_text(solve.dir / "error.txt", e.what());
      outcome.error = e.what();
    }
    m_progress->finished(StudyProgress::Kind::reference_solve, solve.scene.name + " · " + level_name(solve) + (outcome.profile ? ": solved" : ": failed"), seconds_since(begin));
  }
}

void StudyRun::run_model(std::size_t k) {
  const StudyModelRun& run = m_plan.model_runs[k];
  const auto begin = std::chrono::steady_clock::now();
  remove_records(run.dir, {"profile.csv", "note.txt"});
  RunOutcome& outcome = m_models[k];
  try {
    RecordedRun r = run_and_record(run.model, run.scene_with_parameters, m_meshes.at(run.scene), run.dir);
    outcome.profile = std::move(r.profile);
    outcome.note = r.record_note;
  } catch (const std::exception& e) {
    outcome.note = e.what();
    try {
      write_text(run.dir / "note.txt", e.what());
    } catch (const std::exception&) {
    } // the note is in the table all the same
  }
  m_progress->finished(StudyProgress::Kind::model_run, m_plan.scenes[run.scene].scene.name + " · " + run.label + (outcome.profile ? ": ran" : ": failed"),
                       seconds_since(begin));
}

/// A fitted calibration: the fit against its reference on the calibration trajectory, then the
/// fitted model on the scene's own trajectory (recorded like any model run, with parameters.toml
/// and calibration.txt beside).
void StudyRun::fit(std::size_t k) {
  const StudyFitRun& run = m_plan.fit_runs[k];
  const auto begin = std::chrono::steady_clock::now();
  remove_records(run.dir, {"profile.csv", "note.txt", "calibration.txt", "parameters.toml", "fit.json", "key.txt", "library_entry.txt"});
  RunOutcome& outcome = m_fits[k];
  bool from_library = false;
  try {
    if (!run.reference) throw std::runtime_error(run.refusal);
    const StudyReferenceSolve& target_solve = m_plan.solves[*run.reference];
    const SolveOutcome& target_outcome = m_solves[*run.reference];
    if (!target_outcome.profile) throw std::runtime_error("not calibrated: its reference failed: " + target_outcome.error);
    char speed[32];
    std::snprintf(speed, sizeof speed, "%g", run.fit.speed);
    const std::string label = "reference L" + std::to_string(target_solve.level) + " at speed ×" + speed;
    const Scene& scene = m_plan.scenes[run.scene].scene;
    const TetMesh& mesh = m_meshes.at(run.scene);
    const FitKey key = fit_key(run, scene, target_solve);
    const fs::path entry = m_spec.reference.library.empty() ? fs::path() : m_spec.reference.library / key.directory;
    from_library = !entry.empty() && fs::exists(entry / "parameters.toml") && fs::exists(entry / "fit.json") &&
                   read_text(entry / "key.txt") == key.text;
    if (from_library) {
      // The library holds this fit (the same key: the same scene, model, settings and target):
      // its parameters, run once on the scene's own trajectory.
      std::ifstream in(entry / "fit.json");
      outcome.calibration = nlohmann::json::parse(in).at("note").get<std::string>() + " (from the library)";
      outcome.fitted_scene = read_scene(scene.file, {entry / "parameters.toml"});
      write_text(run.dir / "parameters.toml", read_text(entry / "parameters.toml"));
      write_text(run.dir / "fit.json", read_text(entry / "fit.json"));
    } else {
      const CalibrationTarget target{label, target_solve.scene, *target_outcome.profile};
      CalibrationResult fitted;
      try {
        fitted = calibrate(run.fit.model, target, mesh, study_calibration_settings(run.fit));
      } catch (const std::exception& e) {
        throw std::runtime_error(std::string("not calibrated: ") + e.what());
      }
      char errors[160];
      std::snprintf(errors, sizeof errors, "RMS error there %.3g %% → %.3g %%, %d runs%s", 100.0 * fitted.initial_error,
                    100.0 * fitted.fitted_error, fitted.evaluations, fitted.converged ? "" : ", evaluation limit reached");
      outcome.calibration = "fitted at speed ×" + std::string(speed) + " to " + target_solve.scene.name + "'s " +
                            label.substr(0, label.find(" at")) + ": " + describe_fit(fitted) + " (" + errors + ")";
      outcome.fitted_scene = with_parameters(scene, fitted.fitted);
      ++m_fitted;
      write_text(run.dir / "parameters.toml",
                 parameter_file_text(fitted.fitted, "Fitted by kerf study " + m_spec.name + " ([[calibrate]] " + run.fit.model + " on " +
                                                        scene.name + "): " + outcome.calibration + "\n"));
      // The fit's record: what the library keeps (publish_references) and its check recomputes
      // (tests/experiments/study/test_reference_library.cpp: the fitted error on the target).
      const nlohmann::json record = {{"note", outcome.calibration},
                                     {"fitted_error", fitted.fitted_error},
                                     {"initial_error", fitted.initial_error},
                                     {"evaluations", fitted.evaluations},
                                     {"converged", fitted.converged},
                                     {"target", target_solve.dir.filename().string()}};
      write_text(run.dir / "fit.json", record.dump(2) + "\n");
    }
    write_text(run.dir / "key.txt", key.text);
    write_text(run.dir / "library_entry.txt", key.directory + "\n");
    RecordedRun r = run_and_record(run.fit.model, *outcome.fitted_scene, mesh, run.dir);
    outcome.profile = std::move(r.profile);
    write_text(run.dir / "calibration.txt", outcome.calibration);
  } catch (const std::exception& e) {
    outcome = RunOutcome{};
    outcome.note = e.what();
    try {
      write_text(run.dir / "note.txt", e.what());
    } catch (const std::exception&) {
    } // the note is in the table all the same
  }
  m_progress->finished(StudyProgress::Kind::fit, m_plan.scenes[run.scene].scene.name + " · " + run.label + (!outcome.profile ? ": not fitted" : from_library ? ": fit taken from the library" : ": fitted"),
                       seconds_since(begin));
}

/// Every solve this process did not run itself, from the cache (cached before this run, or
/// solved by another rank).
void StudyRun::collect_references() {
  std::set<std::size_t> here(m_my_references.begin(), m_my_references.end());
  for (std::size_t k = 0; k < m_plan.solves.size(); ++k)
    if (!here.count(k)) m_solves[k] = read_solve(m_plan.solves[k]);
}

/// Rank 0, with several ranks: the other ranks' model runs and fits, from their records.
void StudyRun::collect_runs() {
  if (m_execution.ranks == 1) return;
  const std::set<std::size_t> models(m_my_models.begin(), m_my_models.end()), fits(m_my_fits.begin(), m_my_fits.end());
  for (std::size_t k = 0; k < m_plan.model_runs.size(); ++k)
    if (!models.count(k) && m_plan.model_runs[k].not_applicable.empty())
      m_models[k] = read_run(m_plan.model_runs[k].dir, m_plan.scenes[m_plan.model_runs[k].scene].scene.file, false);
  for (std::size_t k = 0; k < m_plan.fit_runs.size(); ++k)
    if (!fits.count(k)) m_fits[k] = read_run(m_plan.fit_runs[k].dir, m_plan.scenes[m_plan.fit_runs[k].scene].scene.file, true);
}

/// The timing pass (cost_timing.hpp): every model that ran, built again and run `timing_runs`
/// times on this thread alone, after every other run of the study is over, the models in turn
/// (round r runs each once), each run followed by a reset that waits for the model's own worker
/// threads (the springs' factor refresh), so that nothing of one run overlaps the next.
void StudyRun::time_models() {
  if (m_execution.timing_runs < 1) return;
  struct Timed {
    std::string model, label;
    std::size_t scene;
    const Scene* with_parameters;
    RunOutcome* outcome;
  };
  std::vector<Timed> timed;
  for (std::size_t k = 0; k < m_plan.model_runs.size(); ++k) {
    const StudyModelRun& run = m_plan.model_runs[k];
    if (m_models[k].profile) timed.push_back({run.model, run.label, run.scene, &run.scene_with_parameters, &m_models[k]});
  }
  for (std::size_t k = 0; k < m_plan.fit_runs.size(); ++k) {
    const StudyFitRun& run = m_plan.fit_runs[k];
    if (m_fits[k].profile && m_fits[k].fitted_scene) timed.push_back({run.fit.model, run.label, run.scene, &*m_fits[k].fitted_scene, &m_fits[k]});
  }
  if (timed.empty()) return;
  std::set<std::size_t> scenes;
  for (const Timed& t : timed) scenes.insert(t.scene);
  make_meshes(scenes);

  struct Ready {
    BuiltModel built;
    std::vector<std::string> names;
    std::vector<SampledTrajectory> trajectories;
  };
  std::vector<Ready> ready;
  ready.reserve(timed.size());
  for (const Timed& t : timed) {
    Ready r{make_model(t.model, *t.with_parameters, m_meshes.at(t.scene)), {}, sample_scene_trajectories(*t.with_parameters)};
    for (const Tool& tool : t.with_parameters->tools) r.names.push_back(tool.name);
    ready.push_back(std::move(r));
  }
  std::vector<TimedModel> models;
  for (std::size_t k = 0; k < timed.size(); ++k) {
    Ready* r = &ready[k];
    models.push_back({[r] {
                        ForceProfile profile = kerf::run_model(*r->built.model, r->names, r->trajectories);
                        r->built.model->reset();
                        return profile;
                      },
                      &*timed[k].outcome->profile, passes_per_timed_run(step_costs(*timed[k].outcome->profile).size())});
  }
  const int rounds = m_execution.timing_runs;
  m_progress->expect(StudyProgress::Kind::timing, static_cast<std::size_t>(rounds));
  const std::vector<TimedCost> costs = time_models_in_turn(models, rounds, [&](int round, double seconds) {
    m_progress->finished(StudyProgress::Kind::timing,
                         "timing round " + std::to_string(round) + "/" + std::to_string(rounds) + ": " + std::to_string(timed.size()) + " models, each once",
                         seconds);
  });
  for (std::size_t k = 0; k < timed.size(); ++k) timed[k].outcome->timed = costs[k];
}

StudyResult StudyRun::run() {
  if (m_execution.ranks > 1 && !m_execution.synchronise)
    throw std::invalid_argument("run_study: " + std::to_string(m_execution.ranks) + " ranks need a synchronise function");
  share_work();
  std::set<std::size_t> model_scenes;
  for (std::size_t k : m_my_models) model_scenes.insert(m_plan.model_runs[k].scene);
  for (std::size_t k : m_my_fits) model_scenes.insert(m_plan.fit_runs[k].scene);
  make_meshes(model_scenes);

  // Phase 1: the reference solves (one task, in turn) beside the model runs.
  std::vector<std::function<void()>> tasks;
  if (!m_my_references.empty()) tasks.emplace_back([this] { solve_references(); });
  for (std::size_t k : m_my_models) tasks.emplace_back([this, k] { run_model(k); });
  const auto started = std::chrono::steady_clock::now();
  run_tasks(tasks, m_execution.jobs);
  StudyResult result;
  result.machine = machine_label();
  result.jobs = m_execution.jobs;
  result.ranks = m_execution.ranks;
  result.reference_runs = synchronise(m_solved); // every reference is on disk: the fits may read theirs
  result.run_seconds = seconds_since(started);
  collect_references();

  // Phase 2: the fitted calibrations.
  tasks.clear();
  for (std::size_t k : m_my_fits) tasks.emplace_back([this, k] { fit(k); });
  const auto fits_started = std::chrono::steady_clock::now();
  run_tasks(tasks, m_execution.jobs);
  result.fits_run = synchronise(m_fitted);
  result.fit_seconds = seconds_since(fits_started);
  if (m_execution.rank != 0) return result;

  // Rank 0 alone: the accuracy (known now), the timing pass, then the tables.
  collect_runs();
  if (m_execution.scored) {
    StudyResult scored = result; // the costs as the scored runs measured them
    for (std::size_t s = 0; s < m_plan.scenes.size(); ++s) scene_rows(s, scored);
    m_execution.scored(scored);
  }
  const auto timing_started = std::chrono::steady_clock::now();
  time_models();
  result.timing_seconds = seconds_since(timing_started);
  result.timing_runs = m_execution.timing_runs;
  for (std::size_t s = 0; s < m_plan.scenes.size(); ++s) scene_rows(s, result);
  return result;
}

/// The scene's reference rows (the finest with its verification, the coarser levels and the
/// half-increment run against it), then its model rows.
void StudyRun::scene_rows(std::size_t s, StudyResult& result) const {
  const std::optional<SceneReference> reference = verify(s, result);
  if (reference) result.references.push_back(*reference);
  model_rows(s, reference ? &result.references.back() : nullptr, result);
}

std::optional<SceneReference> StudyRun::verify(std::size_t s, StudyResult& result) const {
  const StudyPlannedScene& planned = m_plan.scenes[s];
  const Scene& scene = planned.scene;
  if (planned.levels.empty()) return std::nullopt;
  SceneReference verified{scene.name, scene.tools.front().name, {}, {}, {}, {}, std::nullopt, std::nullopt, ""};
  std::vector<ReferenceLevel> levels;
  std::string failed; // coarser levels that failed: the table goes on without them, saying so
  std::string stopped, resolution;
  const StudyReferenceSolve& finest_solve = m_plan.solves[planned.levels.back()];
  for (std::size_t k : planned.levels) {
    const StudyReferenceSolve& solve = m_plan.solves[k];
    const SolveOutcome& outcome = m_solves[k];
    if (!outcome.stopped.empty()) {
      stopped += "L" + std::to_string(solve.level) + " stopped before the trajectory's end (" + outcome.stopped.substr(0, 160) + "…); ";
      result.stopped_references.push_back(scene.name + " L" + std::to_string(solve.level) + ": " + outcome.stopped);
    }
    if (!outcome.profile) {
      if (k == planned.levels.back()) // the finest: nothing to score against
        throw std::runtime_error("reference of scene " + scene.name + " at level " + std::to_string(solve.level) + " failed: " + outcome.error);
      failed += "L" + std::to_string(solve.level) + " failed (" + outcome.error + "); ";
      continue;
    }
    verified.levels.push_back(solve.level);
    verified.element_sizes.push_back(study_reference_element_size(scene, solve.level));
    verified.profiles.push_back(solve.dir / "profile.csv");
    verified.level_profiles.push_back(*outcome.profile);
    levels.push_back({solve.level, verified.element_sizes.back(), *outcome.profile});
  }
  if (!m_solves[planned.levels.back()].resolution.empty())
    resolution = "fails its resolution check: " + m_solves[planned.levels.back()].resolution + "; ";
  const ForceProfile& finest = verified.level_profiles.back();
  const std::string tool = verified.tool;

  // In space: the three finest levels (reference_verification.hpp).
  std::string space;
  try {
    verified.verification =
        verify_reference(levels, tool, m_spec.reference.degree_of(scene.file.stem().string(), scene.geometry.element_degree) + 1.0);
    space = verified.verification ? verified.verification->summary()
                                  : "no GCI available: " + std::to_string(levels.size()) +
                                        " mesh level(s), solution verification needs 3 ([reference] refinements)";
  } catch (const std::exception& e) {
    space = std::string("no GCI available: ") + e.what();
  }
  // In time: the finest level at half the load increment.
  std::optional<ForceProfile> half;
  const std::string time = verify_in_time(planned, verified, half, result);
  char head[96];
  std::snprintf(head, sizeof head, "mesh h = %.3g mm; ", study_reference_element_size(scene, finest_solve.level) * 1e3);
  verified.note = stopped + resolution + failed + space + (time.empty() ? "" : "; " + time);
  if (const auto u = verified.uncertainty(); u && verified.verification && verified.sampling && verified.verification->peak_force > 0.0) {
    char combined[160];
    std::snprintf(combined, sizeof combined, "; combined uncertainty %.2g %% of the peak (root sum square of space and time)",
                  100.0 * *u / verified.verification->peak_force);
    verified.note += combined;
  }
  verified.note += target_note(verified);
  StudyRow finest_row{scene.name, "reference L" + std::to_string(finest_solve.level), std::nullopt, cost_statistics(finest), std::nullopt,
                      head + verified.note, finest_solve.dir / "profile.csv"};
  result.rows.push_back(std::move(finest_row));
  coarser_reference_rows(planned, verified, levels, half, result);
  return verified;
}

/// The sampling uncertainty of the scene's finest level (its run at half the load increment,
/// `half`, against it) in `verified.sampling`, and the note that says it or why there is none.
std::string StudyRun::verify_in_time(const StudyPlannedScene& planned, SceneReference& verified, std::optional<ForceProfile>& half,
                                     StudyResult& result) const {
  if (!planned.time_check) return "";
  const SolveOutcome& outcome = m_solves[*planned.time_check];
  if (!outcome.stopped.empty())
    result.stopped_references.push_back(planned.scene.name + " " + level_name(m_plan.solves[*planned.time_check]) + ": " + outcome.stopped);
  if (!outcome.profile) return "no sampling uncertainty: the run at half the load increment failed (" + outcome.error + ")";
  half = outcome.profile;
  try {
    verified.sampling = verify_sampling(verified.level_profiles.back(), *half, verified.tool);
    return verified.sampling->summary();
  } catch (const std::exception& e) {
    return std::string("no sampling uncertainty: ") + e.what();
  }
}

/// The reference's own discretisation error: a row for each coarser level, and one for the half
/// increment, against the finest level.
void StudyRun::coarser_reference_rows(const StudyPlannedScene& planned, const SceneReference& verified,
                                      const std::vector<ReferenceLevel>& levels, const std::optional<ForceProfile>& half,
                                      StudyResult& result) const {
  const Scene& scene = planned.scene;
  const ForceProfile& finest = verified.level_profiles.back();
  const StudyReferenceSolve& finest_solve = m_plan.solves[planned.levels.back()];
  const auto against_finest = [&](const std::string& label, const ForceProfile& profile, const fs::path& file, const std::string& note) {
    StudyRow row{scene.name, label, std::nullopt, cost_statistics(profile), std::nullopt, note, file};
    try {
      row.metrics = compare_profiles(at_common_times(profile, finest), at_common_times(finest, profile), verified.tool);
    } catch (const std::exception& e) {
      row.note += std::string("; ") + e.what();
    }
    result.rows.push_back(std::move(row));
  };
  for (std::size_t k = 0; k + 1 < levels.size(); ++k) {
    char note[160];
    std::snprintf(note, sizeof note, "mesh h = %.3g mm against the finest, L%d with h = %.3g mm", levels[k].element_size * 1e3,
                  finest_solve.level, study_reference_element_size(scene, finest_solve.level) * 1e3);
    against_finest("reference L" + std::to_string(levels[k].level), levels[k].profile, verified.profiles[k], note);
  }
  if (half)
    against_finest(level_name(m_plan.solves[*planned.time_check]), *half, m_plan.solves[*planned.time_check].dir / "profile.csv",
                   "the finest level at half the load increment against the finest at the study's (the common output times)");
}

StudyRow StudyRun::model_row(const StudyPlannedScene& planned, const std::string& label, const StudyModelRun& run,
                             const RunOutcome& outcome, const fs::path& dir, const SceneReference* reference) const {
  const Scene& scene = planned.scene;
  StudyRow row{scene.name, label, std::nullopt, {}, outcome.timed, "", {}};
  const auto join = [](const std::string& a, const std::string& b) { return a.empty() ? b : b.empty() ? a : a + "; " + b; };
  if (!run.not_applicable.empty()) {
    row.note = run.not_applicable;
    return row;
  }
  if (!outcome.profile) {
    row.note = outcome.note;
    return row;
  }
  row.note = join(outcome.calibration, outcome.note);
  if (outcome.note.empty()) row.profile = dir / "profile.csv";
  row.cost = cost_statistics(*outcome.profile);
  if (outcome.timed && !outcome.timed->reproduces_scored_run)
    row.note = join(row.note, "the timed runs' forces differ from the scored run's (a model that depends on the clock)");
  if (!reference) return row;
  try {
    // Scored only over the phases the model represents (springs on a blade: before the cut).
    const ScoredSamples scored = represented_samples(reference->level_profiles.back(), scene.phenomena, run.represented);
    row.note = join(row.note, scored.note);
    if (!scored.reference.rows.empty())
      row.metrics = compare_profiles(at_common_times(*outcome.profile, scored.reference), at_common_times(scored.reference, *outcome.profile),
                                     reference->tool, expected_cutting(scene));
    // An error the reference cannot resolve is not shown as a number: compared in newtons with the
    // uncertainty of the finest reference (space and time) and of its peak |F|.
    const std::optional<double> u = reference->uncertainty();
    const std::optional<double> u_peak = reference->verification ? reference->verification->peak_uncertainty() : std::nullopt;
    if (row.metrics && u) row.rms_below_reference_uncertainty = row.metrics->normalised_rms_force_error * row.metrics->reference_peak_force < *u;
    if (row.metrics && u_peak)
      row.peak_below_reference_uncertainty = std::abs(row.metrics->peak_force_error) * row.metrics->reference_peak_force < *u_peak;
  } catch (const std::exception& e) {
    row.note = join(row.note, e.what());
  }
  return row;
}

/// The model rows, each fitted calibration right after its model's plain row; a model that cannot
/// run on the scene has its row too, saying why.
void StudyRun::model_rows(std::size_t s, const SceneReference* reference, StudyResult& result) const {
  const StudyPlannedScene& planned = m_plan.scenes[s];
  for (std::size_t k = 0; k < m_plan.model_runs.size(); ++k) {
    const StudyModelRun& run = m_plan.model_runs[k];
    if (run.scene != s) continue;
    result.rows.push_back(model_row(planned, run.label, run, m_models[k], run.dir, reference));
    if (!run.anchors_fits) continue;
    for (std::size_t f = 0; f < m_plan.fit_runs.size(); ++f) {
      const StudyFitRun& fit = m_plan.fit_runs[f];
      if (fit.scene == s && fit.fit.model == run.model) result.rows.push_back(model_row(planned, fit.label, run, m_fits[f], fit.dir, reference));
    }
  }
}

} // namespace

StudyResult run_study(const StudySpec& spec, const std::filesystem::path& out, const ReferenceRunner& reference,
                      const StudyExecution& execution) {
  return StudyRun(spec, out, reference, execution).run();
}

namespace {

/// The study table, with its cost columns or without them.
StudyTable study_table(const StudyResult& result, bool costs);

} // namespace

StudyTable StudyResult::table() const { return study_table(*this, true); }

StudyTable StudyResult::accuracy_table() const { return study_table(*this, false); }

namespace {

StudyTable study_table(const StudyResult& result, bool costs) {
  std::vector<StudyTable::Column> columns{{"scene", "", 3, 1.0},
                {"model", "", 3, 1.0},
                {"RMS force error", "%", 3, 100.0},
                {"peak force error", "%", 3, 100.0},
                {"rupture travel error", "mm", 3, 1e3},
                {"steady cutting error", "%", 3, 100.0},
                {"work error", "%", 3, 100.0},
                {"mode agreement", "%", 3, 100.0}};
  if (costs)
    columns.insert(columns.end(), {{"median cost", "µs", 3, 1e6},
                                   {"p99 cost", "µs", 3, 1e6},
                                   {"p99 cost spread", "%", 2, 100.0},
                                   {"max cost", "µs", 3, 1e6},
                                   {"rate allowed", "kHz", 3, 1e-3}});
  columns.push_back({"note", "", 3, 1.0});
  StudyTable t(std::move(columns));
  t.group_by_first_column(true);
  const std::string& machine = result.machine;
  const int timing_runs = result.timing_runs, jobs = result.jobs, ranks = result.ranks;
  if (!costs)
    t.set_caption("Accuracy against the reference; the costs follow from the timing pass.");
  else if (!machine.empty()) {
    if (timing_runs > 0)
      t.set_caption("Costs: wall time per servo step on " + machine + ", each model timed alone after every other run of the study, the models in turn (" +
                    std::to_string(timing_runs) + " runs each, a run at least " + std::to_string(timing_min_steps) +
                    " steps, a short trajectory passed again: the median of the runs' median, p99 and max, and the spread of the " +
                    "runs' p99, (largest − smallest) / median); a reference's cost is its solve time per sample.");
    else
      t.set_caption("Costs: wall time per servo step on " + machine + ", measured in the scored runs, " + std::to_string(jobs) +
                    " job(s)" + (ranks > 1 ? " × " + std::to_string(ranks) + " ranks" : std::string()) +
                    (jobs * ranks > 1 ? " at once (a run beside others is slower)" : "") + ".");
  }
  using O = std::optional<double>;
  for (const StudyRow& r : result.rows) {
    const bool m = r.metrics.has_value();
    using Cell = StudyTable::Cell;
    const Cell rms = r.rms_below_reference_uncertainty ? Cell{std::string(below_reference_uncertainty)}
                                                       : Cell{m ? O(r.metrics->normalised_rms_force_error) : O()};
    const Cell peak = r.peak_below_reference_uncertainty ? Cell{std::string(below_reference_uncertainty)}
                                                         : Cell{m ? O(r.metrics->peak_force_error) : O()};
    O median, p99, spread, max, rate;
    if (r.timed) {
      median = r.timed->median, p99 = r.timed->p99, spread = r.timed->p99_spread(), max = r.timed->max, rate = r.timed->rate_allowed();
    } else if (r.cost.steps > 0) {
      median = r.cost.median, p99 = r.cost.p99, max = r.cost.max, rate = r.cost.rate_allowed();
    }
    std::vector<Cell> row{r.scene, r.model, rms, peak, m ? r.metrics->rupture_displacement_error : O(), m ? r.metrics->steady_cutting_force_error : O(),
                          m ? O(r.metrics->work_error) : O(), m ? O(r.metrics->mode_agreement) : O()};
    if (costs) row.insert(row.end(), {median, p99, spread, max, rate});
    row.emplace_back(r.note);
    t.add_row(std::move(row));
  }
  return t;
}

} // namespace

StudyTable StudyResult::phase_table() const {
  const InteractionMode modes[] = {InteractionMode::no_contact, InteractionMode::deformation_1, InteractionMode::rupture,
                                   InteractionMode::cutting, InteractionMode::deformation_2};
  std::vector<StudyTable::Column> columns{{"scene", "", 3, 1.0}, {"model", "", 3, 1.0}};
  for (InteractionMode mode : modes) columns.push_back({std::string(to_string(mode)) + " RMS error", "%", 3, 100.0});
  columns.push_back({"dominant phase", "", 3, 1.0});
  StudyTable t(columns);
  t.group_by_first_column(true);
  t.set_caption("RMS force error within each phase of the finest reference (its interaction mode at the compared times), on the "
                "scale of the whole profile's peak; the dominant phase holds the largest share of the squared error over the trajectory.");
  for (const StudyRow& r : rows) {
    if (!r.metrics || r.model.rfind("reference", 0) == 0) continue;
    std::vector<StudyTable::Cell> row{r.scene, r.model};
    for (InteractionMode mode : modes) {
      std::optional<double> value;
      for (const PhaseError& p : r.metrics->phases)
        if (p.mode == mode) value = p.normalised_rms_force_error;
      row.emplace_back(value);
    }
    std::string dominant;
    if (const PhaseError* p = r.metrics->dominant_phase()) {
      char text[96];
      std::snprintf(text, sizeof text, "%s (%.0f %% of the squared error, %.0f %% of the time)", std::string(to_string(p->mode)).c_str(),
                    100.0 * p->error_share, 100.0 * p->time_fraction);
      dominant = text;
    }
    row.emplace_back(dominant);
    t.add_row(std::move(row));
  }
  return t;
}

std::vector<StudyReferenceSolve> study_reference_solves(const StudySpec& spec, const std::filesystem::path& out) {
  return plan_study(spec, out).solves;
}

int publish_fits(const StudySpec& spec, const std::filesystem::path& out, const std::filesystem::path& library) {
  int published = 0;
  std::set<std::string> planned;
  for (const StudyFitRun& run : plan_study(spec, out).fit_runs) {
    if (!fs::exists(run.dir / "library_entry.txt") || !fs::exists(run.dir / "fit.json")) continue;
    std::string directory = read_text(run.dir / "library_entry.txt");
    while (!directory.empty() && directory.back() == '\n') directory.pop_back();
    const fs::path entry = library / directory;
    for (const char* f : {"key.txt", "parameters.toml", "fit.json"}) write_text(entry / f, read_text(run.dir / f));
    planned.insert(fs::path(directory).filename().string());
    ++published;
  }
  if (fs::exists(library / "fits")) {
    std::vector<fs::path> stale;
    for (const fs::directory_entry& e : fs::directory_iterator(library / "fits"))
      if (e.is_directory() && fs::exists(e.path() / "key.txt") && planned.count(e.path().filename().string()) == 0) stale.push_back(e.path());
    for (const fs::path& p : stale) fs::remove_all(p);
  }
  return published;
}

int publish_references(const std::vector<StudyReferenceSolve>& solves, const std::filesystem::path& library,
                       const std::string& command) {
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
