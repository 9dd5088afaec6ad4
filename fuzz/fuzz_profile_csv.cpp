#include "fuzz/fuzz_targets.hpp"

#include "formats/profile/force_profile.hpp"
#include "fuzz/fuzz_input_file.hpp"

#include <cmath>

namespace kerf::fuzz {

void fuzz_profile_csv(std::span<const std::byte> data) {
  const std::filesystem::path file = write_input_file(data, "profile.csv");
  try {
    const ForceProfile p = read_profile_csv(file);
    for (const ProfileRow& r : p.rows) {
      if (r.tool.empty() || !std::isfinite(r.t) || !r.position.allFinite() || !r.force.allFinite() ||
          !std::isfinite(r.crack_extent) || !std::isfinite(r.cost_s))
        throw FuzzFinding("a profile row was accepted with an empty tool or a non-finite value");
    }
    // What the study computes from a profile read back (profile_metrics): the work per tool.
    if (!p.rows.empty()) {
      const double w = tool_work(p, p.rows.front().tool, 0, p.rows.size());
      (void)w; // finite or not, any double is a valid sum of finite products; the call must be safe
    }
  } catch (const std::runtime_error&) {
    // The documented rejection, naming file:line and the column.
  }
}

} // namespace kerf::fuzz
