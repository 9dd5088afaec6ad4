#include "experiments/records/run_record.hpp"

#include "experiments/models/run_model.hpp"
#include "experiments/records/content_hash.hpp"
#include "meshes/vtu_writer.hpp"

#include <map>
#include <string>

namespace kerf {

nlohmann::json run_manifest(const Scene& scene, const BuiltModel& model, const TetMesh& mesh,
                            const ForceProfile& profile, double wall_seconds) {
  nlohmann::json m;
  m["kerf_version"] = KERF_VERSION;
  m["git_commit"] = KERF_GIT_COMMIT;
  m["scene"] = {{"name", scene.name},
                {"file", std::filesystem::absolute(scene.file).string()},
                {"sha256", file_sha256(scene.file)},
                {"phenomena", scene.phenomena.to_string()}};
  m["model"] = {{"name", std::string(model.model->name())}, {"parameters", model.parameters}};
  m["mesh"] = {{"nodes", mesh.nodes.rows()},
               {"tetrahedra", mesh.tets.rows()},
               {"element_size_m", scene.geometry.element_size},
               {"source", scene.geometry.source.string()}};
  const CostStatistics cost = cost_statistics(profile);
  m["timings"] = {{"steps", cost.steps},          {"step_total_s", cost.total}, {"step_median_s", cost.median},
                  {"step_p99_s", cost.p99},       {"step_max_s", cost.max},     {"rate_allowed_hz", cost.rate_allowed()},
                  {"steps_over_budget", profile.steps_over_budget}, {"wall_s", wall_seconds}};
  std::map<std::string, std::size_t> modes;
  std::map<std::string, std::size_t> rows_per_tool;
  std::map<std::string, double> crack;
  for (const ProfileRow& r : profile.rows) {
    ++modes[std::string(to_string(r.mode))];
    ++rows_per_tool[r.tool];
    crack[r.tool] = r.crack_extent;
  }
  nlohmann::json tools = nlohmann::json::object();
  for (const auto& [tool, count] : rows_per_tool)
    tools[tool] = {{"samples", count},
                   {"work_J", tool_work(profile, tool, 0, count - 1)},
                   {"final_crack_extent_m", crack[tool]}};
  m["totals"] = {{"rows", profile.rows.size()}, {"modes", modes}, {"tools", tools}};
  return m;
}

void write_run(const std::filesystem::path& dir, const ForceProfile& profile, const nlohmann::json& manifest,
               const BuiltModel* model) {
  write_profile_csv(profile, dir / "profile.csv");
  if (model && model->write_outputs) {
    nlohmann::json with_outputs = manifest;
    with_outputs.update(model->write_outputs(dir, &write_vtu));
    write_manifest(with_outputs, dir / "manifest.json");
    return;
  }
  write_manifest(manifest, dir / "manifest.json");
}

} // namespace kerf
