#include "experiments/study/study_runner.hpp"

#include "experiments/run/model_catalogue.hpp"
#include "experiments/run/reference_run.hpp"
#include "experiments/run/scene_mesh.hpp"
#include "experiments/scene/scene_reader.hpp"

#include <nlohmann/json.hpp>

#include "meshes/atomic_file.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

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
    ReferenceRunSettings settings;
    settings.degree = spec.degree;
    settings.refinements = level;
    settings.sample_indices = indices;
    settings.write_fields = false;
    return run_reference(scene, scene_mesh(scene), settings, dir);
  };
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

std::string cache_key(const Scene& scene, const StudyReferenceSpec& r, int level) {
  return file_sha256(scene.file).substr(0, 16) + "-p" + std::to_string(r.degree) + "-L" + std::to_string(level) + "-n" +
         std::to_string(r.samples);
}

} // namespace

namespace {

/// One fast-model run of a study: the model on a scene (with calibrated parameters for a
/// "MODEL (calibrated)" row), its profile under `dir`.
struct ModelRun {
  std::size_t scene = 0;  ///< index into the planned scenes
  std::string model;      ///< catalogue name
  std::string label;      ///< the table's model column
  Scene scene_with_parameters;
  std::filesystem::path dir;
};

struct PlannedScene {
  Scene scene;
  std::vector<std::size_t> indices; ///< trajectory samples the reference solves
  std::vector<std::pair<int, std::filesystem::path>> levels; ///< (mesh level, cache directory)
};

void write_text(const std::filesystem::path& file, const std::string& text) {
  std::filesystem::create_directories(file.parent_path());
  write_atomically(file, [&](const std::filesystem::path& tmp) {
    std::ofstream f(tmp);
    f << text;
    if (!f.flush()) throw std::runtime_error(file.string() + ": write failed");
  });
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

} // namespace

StudyResult run_study(const StudySpec& spec, const std::filesystem::path& out, const ReferenceRunner& reference,
                      const StudyExecution& execution) {
  namespace fs = std::filesystem;
  if (execution.ranks > 1 && !execution.synchronise)
    throw std::invalid_argument("run_study: " + std::to_string(execution.ranks) + " ranks need a synchronise function");
  const auto synchronise = [&](int value) { return execution.ranks > 1 ? execution.synchronise(value) : value; };

  // Plan (every rank the same): scenes, reference levels not yet cached, model runs.
  std::vector<PlannedScene> scenes;
  std::vector<ModelRun> model_runs;
  for (const fs::path& scene_file : spec.scenes) {
    PlannedScene planned{read_scene(scene_file), {}, {}};
    const Scene& scene = planned.scene;
    std::size_t n = 0;
    for (const auto& t : sample_scene_trajectories(scene)) n = std::max(n, t.samples.size());
    planned.indices = reference_sample_indices(n, spec.reference.samples);
    if (spec.has_reference && reference)
      for (int level : spec.reference.refinements)
        planned.levels.emplace_back(level, out / "cache" / cache_key(scene, spec.reference, level));
    const std::size_t index = scenes.size();
    for (const std::string& model : spec.models) {
      try {
        require_model_for_scene(model, scene);
      } catch (const std::exception&) {
        continue; // not applicable: not in the table
      }
      model_runs.push_back({index, model, model, scene, out / scene.name / model});
      const auto calibrated = spec.calibrations.find(scene_file.stem().string());
      if (calibrated == spec.calibrations.end()) continue;
      for (const fs::path& parameters : calibrated->second) {
        const auto models = calibrated_models(parameters);
        if (std::find(models.begin(), models.end(), model) == models.end()) continue;
        model_runs.push_back({index, model, model + " (calibrated)", read_scene(scene_file, {parameters}),
                              out / scene.name / (model + "-calibrated")});
      }
    }
    scenes.push_back(std::move(planned));
  }
  std::vector<std::pair<std::size_t, std::size_t>> reference_runs; // (scene, level index) not cached
  for (std::size_t s = 0; s < scenes.size(); ++s)
    for (std::size_t l = 0; l < scenes[s].levels.size(); ++l)
      if (!fs::exists(scenes[s].levels[l].second / "profile.csv")) reference_runs.emplace_back(s, l);
  synchronise(0); // every rank has looked at the cache before any rank writes to it

  // This rank's share: run k (references first, then models) belongs to rank k mod ranks.
  const auto mine = [&](std::size_t k) { return static_cast<int>(k % static_cast<std::size_t>(execution.ranks)) == execution.rank; };
  std::vector<std::pair<std::size_t, std::size_t>> my_references;
  for (std::size_t k = 0; k < reference_runs.size(); ++k)
    if (mine(k)) my_references.push_back(reference_runs[k]);
  std::vector<const ModelRun*> my_models;
  for (std::size_t k = 0; k < model_runs.size(); ++k)
    if (mine(reference_runs.size() + k)) my_models.push_back(&model_runs[k]);

  // Meshes of the scenes this rank runs models on, made before the threads start.
  std::map<std::size_t, TetMesh> meshes;
  for (const ModelRun* run : my_models)
    if (!meshes.count(run->scene)) meshes.emplace(run->scene, scene_mesh(scenes[run->scene].scene));

  std::vector<std::function<void()>> tasks;
  int solved = 0;
  if (!my_references.empty())
    tasks.emplace_back([&] { // one at a time: PETSc is not thread-safe
      for (const auto& [s, l] : my_references) {
        const auto& [level, cached] = scenes[s].levels[l];
        fs::remove(cached / "error.txt");
        try {
          const ForceProfile p = reference(scenes[s].scene, spec.reference, level, scenes[s].indices, cached);
          if (!fs::exists(cached / "profile.csv")) write_profile_csv(p, cached / "profile.csv");
          ++solved;
        } catch (const std::exception& e) {
          write_text(cached / "error.txt", e.what());
        }
      }
    });
  for (const ModelRun* run : my_models)
    tasks.emplace_back([&, run] {
      fs::remove(run->dir / "profile.csv");
      fs::remove(run->dir / "note.txt");
      try {
        const TetMesh& mesh = meshes.at(run->scene);
        BuiltModel built = make_model(run->model, run->scene_with_parameters, mesh);
        std::vector<std::string> names;
        for (const Tool& t : run->scene_with_parameters.tools) names.push_back(t.name);
        const auto begin = std::chrono::steady_clock::now();
        const ForceProfile profile = run_model(*built.model, names, sample_scene_trajectories(run->scene_with_parameters));
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
        write_run(run->dir, profile, run_manifest(run->scene_with_parameters, built, mesh, profile, wall));
      } catch (const std::exception& e) {
        write_text(run->dir / "note.txt", e.what());
      }
    });
  run_tasks(tasks, execution.jobs);

  StudyResult result;
  result.reference_runs = synchronise(solved);
  if (execution.rank != 0) return result;

  // Rank 0: the table, from what every rank wrote.
  for (std::size_t s = 0; s < scenes.size(); ++s) {
    const Scene& scene = scenes[s].scene;
    std::map<int, ForceProfile> references;
    for (const auto& [level, cached] : scenes[s].levels) {
      if (!fs::exists(cached / "profile.csv"))
        throw std::runtime_error("reference of scene " + scene.name + " at level " + std::to_string(level) + " failed: " +
                                 (fs::exists(cached / "error.txt") ? read_text(cached / "error.txt") : "no profile written"));
      references[level] = read_profile_csv(cached / "profile.csv");
    }
    const ForceProfile* finest = references.empty() ? nullptr : &references.rbegin()->second;
    const std::string tool = scene.tools.front().name;

    // The reference's own discretisation error: each coarser level against the finest.
    for (const auto& [level, profile] : references) {
      if (&profile == finest) continue;
      StudyRow row{scene.name, "reference L" + std::to_string(level), std::nullopt, cost_statistics(profile), ""};
      try {
        row.metrics = compare_profiles(at_common_times(profile, *finest), at_common_times(*finest, profile), tool);
      } catch (const std::exception& e) {
        row.note = e.what();
      }
      result.rows.push_back(std::move(row));
    }

    for (const ModelRun& run : model_runs) {
      if (run.scene != s) continue;
      StudyRow row{scene.name, run.label, std::nullopt, {}, ""};
      if (!fs::exists(run.dir / "profile.csv")) {
        row.note = fs::exists(run.dir / "note.txt") ? read_text(run.dir / "note.txt") : "no profile written";
        result.rows.push_back(std::move(row));
        continue;
      }
      try {
        const ForceProfile profile = read_profile_csv(run.dir / "profile.csv");
        row.cost = cost_statistics(profile);
        if (finest)
          row.metrics = compare_profiles(at_common_times(profile, *finest), at_common_times(*finest, profile), tool,
                                         expected_cutting(scene));
      } catch (const std::exception& e) {
        row.note = e.what();
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
  using O = std::optional<double>;
  for (const StudyRow& r : rows) {
    const bool m = r.metrics.has_value();
    const bool c = r.cost.steps > 0;
    t.add_row({r.scene, r.model, m ? O(r.metrics->normalised_rms_force_error) : O(),
               m ? O(r.metrics->peak_force_error) : O(), m ? r.metrics->rupture_displacement_error : O(),
               m ? r.metrics->steady_cutting_force_error : O(), m ? O(r.metrics->work_error) : O(),
               m ? O(r.metrics->mode_agreement) : O(), c ? O(r.cost.median) : O(), c ? O(r.cost.p99) : O(),
               c ? O(r.cost.max) : O(), c ? O(r.cost.rate_allowed()) : O(), r.note});
  }
  return t;
}

} // namespace kerf
