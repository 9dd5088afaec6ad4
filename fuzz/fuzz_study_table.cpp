#include "fuzz/fuzz_targets.hpp"

#include "experiments/study/model_recommendation.hpp"
#include "fuzz/fuzz_input_file.hpp"

#include <set>

namespace kerf::fuzz {

void fuzz_study_table(std::span<const std::byte> data) {
  const std::filesystem::path file = write_input_file(data, "study.csv");
  std::vector<MeasuredRow> rows;
  try {
    rows = read_study_rows(file);
  } catch (const std::runtime_error&) {
    return; // the documented rejection, naming file:line
  }
  // What `kerf recommend` does with the rows: a choice per scene, within 10 % at 1 kHz.
  constexpr double max_error = 0.10, rate = 1000.0;
  std::set<std::string> scenes;
  for (const MeasuredRow& r : rows) scenes.insert(r.scene);
  for (const std::string& scene : scenes) {
    const Recommendation rec = recommend_model(rows, scene, max_error, rate);
    if (rec.reason.empty()) throw FuzzFinding("a recommendation without a reason");
    if (!rec.choice) continue;
    const MeasuredRow& c = *rec.choice;
    if (c.scene != scene || c.model.rfind("reference", 0) == 0)
      throw FuzzFinding("a recommended row of another scene, or a reference row");
    // model_recommendation.hpp: "a measured error <= max_error and a p99 cost <= 1 / rate".
    if (!c.rms_error || !c.p99_cost || !(*c.rms_error >= 0.0 && *c.rms_error <= max_error) ||
        !(*c.p99_cost >= 0.0 && *c.p99_cost <= 1.0 / rate))
      throw FuzzFinding("a recommended row outside the error or cost budget");
  }
}

} // namespace kerf::fuzz
