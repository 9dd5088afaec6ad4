#include "fuzz/fuzz_targets.hpp"

#include "fuzz/fuzz_input_file.hpp"
#include "realtime/haptics/session_file.hpp"

#include <cmath>

namespace kerf::fuzz {

void fuzz_session_csv(std::span<const std::byte> data) {
  const std::filesystem::path file = write_input_file(data, "session.csv");
  try {
    const Session s = read_session(file);
    const std::size_t tools = s.header.tools.size();
    if (tools < 1 || tools > static_cast<std::size_t>(max_session_tools) || !(s.header.rate > 0.0))
      throw FuzzFinding("a session header was accepted with a bad rate or tool count");
    for (std::size_t k = 0; k < s.ticks.size(); ++k) {
      const TickRecord& r = s.ticks[k];
      if (r.tools != static_cast<int>(tools)) throw FuzzFinding("a tick is missing a tool");
      if (k > 0 && r.tick < s.ticks[k - 1].tick) throw FuzzFinding("ticks out of order");
      for (std::size_t i = 0; i < tools; ++i)
        if (!r.tool[i].position.allFinite() || !r.tool[i].force.allFinite()) // model_f may be NaN (session_file.hpp)
          throw FuzzFinding("a session row is not finite");
    }
    const auto states = session_tool_states(s);
    if (states.size() != tools) throw FuzzFinding("one state list per tool");
  } catch (const std::runtime_error&) {
    // The documented rejection, naming file:line.
  }
}

} // namespace kerf::fuzz
