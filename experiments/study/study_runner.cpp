#include "experiments/study/study_runner.hpp"

#include "experiments/run/model_catalogue.hpp"
#include "experiments/run/reference_run.hpp"
#include "experiments/run/scene_mesh.hpp"
#include "experiments/scene/scene_reader.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

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

StudyResult run_study(const StudySpec& spec, const std::filesystem::path& out, const ReferenceRunner& reference) {
  namespace fs = std::filesystem;
  StudyResult result;
  for (const fs::path& scene_file : spec.scenes) {
    const Scene scene = read_scene(scene_file);
    const TetMesh mesh = scene_mesh(scene);
    const auto trajectories = sample_scene_trajectories(scene);
    std::size_t n = 0;
    for (const auto& t : trajectories) n = std::max(n, t.samples.size());

    // The reference at every level, cached by scene hash and settings.
    std::map<int, ForceProfile> references;
    const auto indices = reference_sample_indices(n, spec.reference.samples);
    if (spec.has_reference && reference) {
      for (int level : spec.reference.refinements) {
        const fs::path cached = out / "cache" / cache_key(scene, spec.reference, level);
        if (fs::exists(cached / "profile.csv")) {
          references[level] = read_profile_csv(cached / "profile.csv");
        } else {
          references[level] = reference(scene, spec.reference, level, indices, cached);
          ++result.reference_runs;
          if (!fs::exists(cached / "profile.csv")) write_profile_csv(references[level], cached / "profile.csv");
        }
      }
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

    for (const std::string& model : spec.models) {
      StudyRow row{scene.name, model, std::nullopt, {}, ""};
      try {
        require_model_for_scene(model, scene);
      } catch (const std::exception& e) {
        continue; // not applicable: not in the table
      }
      try {
        BuiltModel built = make_model(model, scene, mesh);
        std::vector<std::string> names;
        for (const Tool& t : scene.tools) names.push_back(t.name);
        const auto begin = std::chrono::steady_clock::now();
        const ForceProfile profile = run_model(*built.model, names, trajectories);
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
        write_run(out / scene.name / model, profile, run_manifest(scene, built, mesh, profile, wall));
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
