#include "experiments/study/study_report.hpp"

#include "formats/scene/scene_reader.hpp"
#include "experiments/study/study_plots.hpp"

#include "meshes/atomic_file.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>

namespace kerf {

std::optional<double> rms_error_floor(const SceneReference& reference) {
  const auto u = reference.uncertainty();
  double peak = 0.0;
  if (!reference.level_profiles.empty())
    for (const ProfileRow& r : reference.level_profiles.back().rows)
      if (r.tool == reference.tool) peak = std::max(peak, r.force.norm());
  if (!u || !(peak > 0.0)) return std::nullopt;
  return *u / peak;
}

StudyTable verification_table(const StudyResult& result) {
  StudyTable t({{"scene", "", 3, 1.0},           {"quantity", "", 3, 1.0},        {"levels", "", 3, 1.0},
                {"h1", "mm", 3, 1e3},             {"h2", "mm", 3, 1e3},            {"h3", "mm", 3, 1e3},
                {"φ1", "N", 5, 1.0},              {"φ2", "N", 5, 1.0},             {"φ3", "N", 5, 1.0},
                {"r21", "", 3, 1.0},              {"r32", "", 3, 1.0},             {"observed order p", "", 3, 1.0},
                {"convergence", "", 3, 1.0},      {"extrapolated", "N", 5, 1.0},   {"e_a", "%", 3, 100.0},
                {"e_ext", "%", 3, 100.0},         {"GCI_fine", "%", 3, 100.0},     {"note", "", 3, 1.0}});
  using O = std::optional<double>;
  // The verification in time: the RMS difference of the finest level at the study's load
  // increment and at half of it (φ1), its share of the peak in the GCI column.
  const auto add_sampling_row = [&](const SceneReference& r) {
    if (!r.sampling) return;
    const SamplingVerification& v = *r.sampling;
    char runs[96];
    std::snprintf(runs, sizeof runs, "L%d: %zu and %zu samples", r.levels.back(), v.loads_whole, v.loads_half);
    t.add_row({r.scene, std::string("force profile in time (half the load increment)"), std::string(runs),
               O(r.element_sizes.back()), O(), O(), O(v.rms_difference), O(), O(), O(2.0), O(), O(), std::string(), O(), O(), O(),
               v.peak_force > 0.0 ? O(v.uncertainty() / v.peak_force) : O(), v.summary()});
  };
  for (const SceneReference& r : result.references) {
    if (!r.verification) {
      t.add_row({r.scene, std::string("RMS |F|, peak |F|"), std::string(), O(), O(), O(), O(), O(), O(), O(), O(), O(), std::string(), O(),
                 O(), O(), O(), r.note});
      add_sampling_row(r);
      continue;
    }
    const ReferenceVerification& v = *r.verification;
    const std::string levels =
        "L" + std::to_string(v.levels[0]) + ", L" + std::to_string(v.levels[1]) + ", L" + std::to_string(v.levels[2]);
    for (const auto& [name, c, value] : {std::tuple{"RMS |F|", &v.rms, v.rms_force}, std::tuple{"peak |F|", &v.peak, v.peak_force}}) {
      t.add_row({r.scene, std::string(name), levels, O(v.element_sizes[0]), O(v.element_sizes[1]), O(v.element_sizes[2]), O(value),
                 O(c->grids.phi2), O(c->grids.phi3), O(c->r21), O(c->r32), c->observed_order,
                 std::string(!c->observed_order ? "none" : c->oscillatory ? "oscillatory" : "monotonic"), c->extrapolated,
                 O(c->approximate_relative_error), c->extrapolated_relative_error, c->gci_fine, c->unusable});
    }
    // The force profile: its uncertainty in the RMS norm from the level differences (φ2, φ3: the
    // RMS of f2 − f1 and f3 − f2), relative to the finest level's peak |F| in the GCI column.
    const DifferenceConvergence& d = v.profile;
    const std::string order_note = d.usable() && *d.order_used < *d.observed_order ? "order capped at the formal " + std::to_string(static_cast<int>(d.formal_order)) : d.unusable;
    t.add_row({r.scene, std::string("force profile (RMS of level differences)"), levels, O(v.element_sizes[0]), O(v.element_sizes[1]),
               O(v.element_sizes[2]), O(v.rms_force), O(d.e21), O(d.e32), O(d.r21), O(d.r32), d.observed_order,
               std::string(d.usable() ? "monotonic" : "none"), O(), O(), O(),
               d.usable() && v.peak_force > 0.0 ? O(*d.uncertainty / v.peak_force) : O(), order_note});
    add_sampling_row(r);
  }
  return t;
}

namespace {

/// The finest reference of `reference` as plot_profiles draws it: its profile CSV with band_low and
/// band_high columns, written to `csv`.
ProfilePlotReference write_reference_series(const SceneReference& reference, const Eigen::Vector3d& direction, const std::filesystem::path& csv) {
  std::vector<ReferenceLevel> levels;
  for (std::size_t k = 0; k < reference.levels.size(); ++k)
    levels.push_back({reference.levels[k], reference.element_sizes[k], reference.level_profiles[k]});
  std::size_t finest = 0;
  for (std::size_t k = 1; k < levels.size(); ++k)
    if (levels[k].element_size < levels[finest].element_size) finest = k;
  const ReferenceBand band = reference_band(levels, reference.verification, reference.tool, direction);
  std::string text = std::string(profile_csv_header) + ",band_low,band_high\n";
  std::size_t k = 0;
  char line[512];
  for (const ProfileRow& r : levels[finest].profile.rows) {
    if (r.tool != reference.tool) continue;
    std::snprintf(line, sizeof line, "%.17g,%s,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%s,%.17g,%.17g,%.17g,%.17g\n", r.t, r.tool.c_str(),
                  r.position.x(), r.position.y(), r.position.z(), r.force.x(), r.force.y(), r.force.z(), std::string(to_string(r.mode)).c_str(),
                  r.crack_extent, r.cost_s, band.low[k], band.high[k]);
    text += line;
    ++k;
  }
  write_atomically(csv, [&](const std::filesystem::path& tmp) {
    std::ofstream f(tmp, std::ios::binary);
    f << text;
    if (!f.flush()) throw std::runtime_error(csv.string() + ": write failed");
  });
  std::string source;
  if (band.from_gci) {
    char text_source[96];
    std::snprintf(text_source, sizeof text_source, "GCI band (p = %.2g)", *reference.verification->profile.order_used);
    source = text_source;
  } else if (levels.size() > 1) {
    source = "spread of L" + std::to_string(reference.levels.front()) + "..L" + std::to_string(reference.levels.back());
  } else {
    source = "one level: no band";
  }
  return {"reference L" + std::to_string(levels[finest].level), csv, source};
}

} // namespace

namespace {

/// The reference of `scene` in `result`, or nullptr.
const SceneReference* reference_of(const StudyResult& result, const std::string& scene) {
  const SceneReference* reference = nullptr;
  for (const SceneReference& r : result.references)
    if (r.scene == scene) reference = &r;
  return reference;
}

} // namespace

void write_profile_plots(const StudySpec& spec, const StudyResult& result, const std::filesystem::path& out) {
  namespace fs = std::filesystem;
  for (const fs::path& scene_file : spec.scenes) {
    const Scene scene = read_scene(scene_file);
    std::vector<std::pair<std::string, fs::path>> runs;
    for (const StudyRow& r : result.rows)
      if (r.scene == scene.name && !r.profile.empty() && r.model.rfind("reference", 0) != 0) runs.emplace_back(r.model, r.profile);
    const SceneReference* reference = reference_of(result, scene.name);
    if (runs.empty() && !reference) continue;
    const Eigen::Vector3d direction = advance_direction(scene);
    std::optional<ProfilePlotReference> drawn;
    if (reference) drawn = write_reference_series(*reference, direction, out / (scene.name + "_reference.csv"));
    plot_profiles(out / (scene.name + "_profiles"), runs, direction, drawn, holds_or_retreats(scene),
                  scene.name + ": resisting force of the " + scene.tools.front().name);
  }
}

void write_tables_and_charts(const StudySpec& spec, const StudyResult& result, const std::filesystem::path& out) {
  namespace fs = std::filesystem;
  result.table().write(out, "study");
  result.phase_table().write(out, "study_phases");
  if (!result.references.empty()) verification_table(result).write(out, "verification");
  for (const fs::path& scene_file : spec.scenes) {
    const std::string scene = read_scene(scene_file).name;
    const bool any_error = std::any_of(result.rows.begin(), result.rows.end(),
                                       [&](const StudyRow& r) { return r.scene == scene && r.metrics.has_value(); });
    if (!any_error) continue;
    const SceneReference* reference = reference_of(result, scene);
    plot_pareto(out / (scene + "_pareto"), out / "study.csv", "RMS force error [%]", "p99 cost [µs]", "model", scene,
                reference && rms_error_floor(*reference) ? std::optional<double>(100.0 * *rms_error_floor(*reference)) : std::nullopt,
                scene + ": RMS force error against cost");
  }
}

void write_study_report(const StudySpec& spec, const StudyResult& result, const std::filesystem::path& out) {
  write_tables_and_charts(spec, result, out);
  write_profile_plots(spec, result, out);
}

} // namespace kerf
