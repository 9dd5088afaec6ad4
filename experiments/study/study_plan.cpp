#include "experiments/study/study_plan.hpp"

#include "experiments/models/model_catalogue.hpp"
#include "experiments/models/run_model.hpp"
#include "formats/scene/scene_reader.hpp"
#include "experiments/study/model_resolution.hpp"

#include <algorithm>
#include <cmath>

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

std::vector<std::size_t> solved_samples(const Scene& scene, int count) {
  std::size_t n = 0;
  for (const auto& t : sample_scene_trajectories(scene)) n = std::max(n, t.samples.size());
  return reference_sample_indices(n, count);
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

namespace {

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

/// Plans the study's pieces one scene at a time (plan_study).
class Planner {
public:
  Planner(const StudySpec& spec, std::filesystem::path out, bool reference_wanted)
      : m_spec(spec), m_out(std::move(out)), m_with_reference(spec.has_reference && reference_wanted) {}

  StudyPlan plan() {
    for (const std::filesystem::path& scene_file : m_spec.scenes) plan_scene(scene_file);
    return std::move(m_plan);
  }

private:
  /// A reference solve of `scene` at `level` on `samples` samples, keyed into the cache.
  std::size_t plan_solve(const Scene& scene, int level, int samples, LoadIncrement increment = LoadIncrement::whole) {
    StudyReferenceSolve solve{study_reference_scene(scene, level), level, solved_samples(scene, samples), increment, {}, {}};
    const ReferenceCacheKey key =
        reference_cache_key(solve.scene, study_reference_settings(m_spec.reference, solve.scene, level, solve.indices, increment));
    solve.dir = m_out / "cache" / key.directory;
    solve.key_text = key.text;
    m_plan.solves.push_back(std::move(solve));
    return m_plan.solves.size() - 1;
  }

  void plan_scene(const std::filesystem::path& scene_file) {
    const std::string name = scene_file.stem().string();
    StudyPlannedScene planned{read_scene(scene_file), {}, std::nullopt};
    if (m_with_reference) {
      const int samples = m_spec.reference.samples_of(name);
      const std::vector<int>& levels = m_spec.reference.levels_of(name);
      for (int level : levels) planned.levels.push_back(plan_solve(planned.scene, level, samples));
      // Verification in time: the finest level again with half the increment, 2N − 1 samples
      // (the first solve's N among them: reference_sample_indices).
      if (m_spec.reference.time_verification)
        planned.time_check = plan_solve(planned.scene, levels.back(), 2 * samples - 1, LoadIncrement::half);
    }
    const std::size_t index = m_plan.scenes.size();
    for (const std::string& model : m_spec.models) plan_model(index, scene_file, planned.scene, model);
    m_plan.scenes.push_back(std::move(planned));
  }

  void plan_model(std::size_t index, const std::filesystem::path& scene_file, const Scene& scene, const std::string& model) {
    namespace fs = std::filesystem;
    std::vector<StudyModelRun>& runs = m_plan.model_runs;
    PhenomenonSet represented;
    try {
      represented = represented_phenomena(model, scene);
    } catch (const ModelMismatch& e) {
      // Not applicable: a row without numbers whose note says why.
      runs.push_back({index, model, model, scene, m_out / scene.name / model, {}, portable_note(std::string("not run: ") + e.what(), scene)});
      return;
    }
    const auto sweep = m_spec.resolutions.find(model);
    if (sweep == m_spec.resolutions.end()) {
      runs.push_back({index, model, model, scene, m_out / scene.name / model, represented, "", true});
    } else {
      // The model at each of its resolutions: the points of its speed/accuracy curve.
      for (int value : sweep->second) {
        try {
          ModelResolution r = at_resolution(model, scene, value);
          runs.push_back({index, model, r.label, std::move(r.scene), m_out / scene.name / r.directory, represented, "",
                          value == sweep->second.back()});
        } catch (const ModelMismatch& e) {
          runs.push_back({index, model, model, scene, m_out / scene.name / model, {}, portable_note(std::string("not run: ") + e.what(), scene),
                          value == sweep->second.back()});
          break;
        }
      }
    }
    const auto calibrated = m_spec.calibrations.find(scene_file.stem().string());
    if (calibrated != m_spec.calibrations.end())
      for (const fs::path& parameters : calibrated->second) {
        const auto models = calibrated_models(parameters);
        if (std::find(models.begin(), models.end(), model) == models.end()) continue;
        runs.push_back({index, model, model + " (calibrated)", read_scene(scene_file, {parameters}), m_out / scene.name / (model + "-calibrated"),
                        represented, ""});
      }
    for (const StudyCalibrationFit& fit : m_spec.fits)
      if (m_with_reference && fit.scene == scene_file.stem().string() && fit.model == model) plan_fit(index, scene_file, scene, fit);
  }

  void plan_fit(std::size_t index, const std::filesystem::path& scene_file, const Scene& scene, const StudyCalibrationFit& fit) {
    StudyFitRun run{index, fit, std::nullopt, fit_refusal(scene, m_spec.reference), fit.model + " (calibrated)",
                    m_out / scene.name / (fit.model + "-calibrated")};
    if (run.refusal.empty()) {
      try {
        const std::vector<int>& levels = m_spec.reference.levels_of(scene_file.stem().string());
        run.reference = plan_solve(calibration_scene(scene, fit.speed), *std::max_element(levels.begin(), levels.end()),
                                   fit.samples > 0 ? fit.samples : m_spec.reference.samples_of(scene_file.stem().string()));
      } catch (const std::invalid_argument& e) {
        run.refusal = std::string("not calibrated: ") + e.what();
      }
    }
    m_plan.fit_runs.push_back(std::move(run));
  }

  const StudySpec& m_spec;
  const std::filesystem::path m_out;
  const bool m_with_reference;
  StudyPlan m_plan;
};

} // namespace

StudyPlan plan_study(const StudySpec& spec, const std::filesystem::path& out, bool reference_wanted) {
  return Planner(spec, out, reference_wanted).plan();
}

} // namespace kerf
