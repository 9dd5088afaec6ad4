#include "realtime/haptics/session_file.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace kerf {

namespace {

std::vector<std::string> split(const std::string& s, char separator) {
  std::vector<std::string> out;
  std::string field;
  std::stringstream in(s);
  while (std::getline(in, field, separator)) out.push_back(field);
  if (!s.empty() && s.back() == separator) out.emplace_back();
  return out;
}

/// The file's complete lines: an append-only file cut by a crash may end in a partial row.
std::string complete_lines(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot open the session file");
  std::stringstream whole;
  whole << in.rdbuf();
  std::string text = whole.str();
  if (const auto last = text.find_last_of('\n'); last == std::string::npos) text.clear();
  else text.resize(last + 1);
  return text;
}

/// Reads the fields of one line of the file; every error names file:line and the column.
struct FieldReader {
  const std::filesystem::path& file;
  int line = 0;

  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error(file.string() + ":" + std::to_string(line) + ": " + what);
  }
  double number(const std::string& field, const char* column) const {
    char* end = nullptr;
    const double v = std::strtod(field.c_str(), &end);
    // The whole field: a NUL byte inside it ends strtod's string, not the field.
    if (field.empty() || end != field.c_str() + field.size() || !std::isfinite(v))
      fail(std::string("column ") + column + ": expected a finite number, found \"" + field + "\"");
    return v;
  }
  // The model's own force may be NaN or Inf (the safety layer replaced it, status safety_non_finite):
  // the file records what the model returned, so these columns take any number strtod reads.
  double model_number(const std::string& field) const {
    char* end = nullptr;
    const double v = std::strtod(field.c_str(), &end);
    if (field.empty() || end != field.c_str() + field.size())
      fail("column model_f: expected a number, found \"" + field + "\"");
    return v;
  }
  // Counts and bit sets (tick, buttons, status): a whole number in [0, limit), checked before the
  // conversion (a negative or too large double converted to an unsigned integer is undefined).
  double whole(const std::string& field, const char* column, double limit) const {
    const double v = number(field, column);
    if (!(v >= 0.0 && v < limit) || v != std::floor(v))
      fail(std::string("column ") + column + ": expected a whole number from 0, found \"" + field + "\"");
    return v;
  }
};

/// The second line: "# rate_hz=… model=… scene=… tools=a;b" (other words are ignored).
SessionHeader read_header(const FieldReader& reader, const std::string& line) {
  SessionHeader header;
  std::stringstream words(line.substr(line.rfind('#', 0) == 0 ? 1 : 0));
  std::string word;
  while (words >> word) {
    const auto eq = word.find('=');
    if (eq == std::string::npos) continue;
    const std::string key = word.substr(0, eq), value = word.substr(eq + 1);
    if (key == "rate_hz") header.rate = reader.number(value, "rate_hz");
    else if (key == "model") header.model = value;
    else if (key == "scene") header.scene = value;
    else if (key == "tools") header.tools = split(value, ';');
  }
  if (!(header.rate > 0.0)) reader.fail("header: rate_hz missing or not positive");
  if (header.tools.empty() || header.tools.size() > static_cast<std::size_t>(max_session_tools))
    reader.fail("header: tools must name 1 to " + std::to_string(max_session_tools) + " tools");
  return header;
}

/// A new tick from its first row `f`: its time and the servo's compute and late seconds.
TickRecord start_tick(const FieldReader& reader, const std::vector<std::string>& f, std::uint64_t tick) {
  TickRecord record{};
  record.tick = tick;
  record.t = reader.number(f[1], "t");
  record.compute = reader.number(f[22], "compute_s");
  record.late = reader.number(f[23], "late_s");
  return record;
}

/// One tool's columns of a row `f`.
void read_tool_columns(const FieldReader& reader, const std::vector<std::string>& f, ToolTick& k) {
  for (int c = 0; c < 3; ++c) {
    k.position[c] = reader.number(f[3 + static_cast<std::size_t>(c)], "p");
    k.velocity[c] = reader.number(f[6 + static_cast<std::size_t>(c)], "v");
    k.model_force[c] = reader.model_number(f[14 + static_cast<std::size_t>(c)]);
    k.force[c] = reader.number(f[17 + static_cast<std::size_t>(c)], "f");
  }
  for (int c = 0; c < 4; ++c) k.orientation[c] = reader.number(f[9 + static_cast<std::size_t>(c)], "q");
  k.buttons = static_cast<std::uint32_t>(reader.whole(f[13], "buttons", 0x1p32));
  const auto mode = interaction_mode_from_string(f[20]);
  if (!mode) reader.fail("unknown mode \"" + f[20] + "\"");
  k.mode = *mode;
  k.crack_extent = reader.number(f[21], "crack_extent");
  k.link_age = reader.number(f[24], "link_age_s");
  k.status = static_cast<std::uint32_t>(reader.whole(f[25], "status", 0x1p32));
  k.injected = reader.number(f[26], "injected_j");
}

} // namespace

Session read_session(const std::filesystem::path& file) {
  std::stringstream lines(complete_lines(file));
  Session session;
  FieldReader reader{file};
  const std::vector<std::string> columns = split(session_csv_header, ',');
  TickRecord current;
  bool open = false;
  std::string line;
  while (std::getline(lines, line)) {
    const int number = ++reader.line;
    if (number == 1) {
      if (line != "# kerf haptic session v1") reader.fail("not a kerf haptic session (expected \"# kerf haptic session v1\")");
      continue;
    }
    if (number == 2) {
      session.header = read_header(reader, line);
      continue;
    }
    if (number == 3) {
      if (line != session_csv_header) reader.fail(std::string("expected the header \"") + session_csv_header + "\"");
      continue;
    }
    // A row: one tool of one tick; a tick's rows come together, in the header's tool order.
    const std::vector<std::string> f = split(line, ',');
    if (f.size() != columns.size())
      reader.fail("expected " + std::to_string(columns.size()) + " columns, found " + std::to_string(f.size()));
    const auto tick = static_cast<std::uint64_t>(reader.whole(f[0], "tick", 0x1p64));
    int tool = -1;
    for (std::size_t k = 0; k < session.header.tools.size(); ++k)
      if (session.header.tools[k] == f[2]) tool = static_cast<int>(k);
    if (tool < 0) reader.fail("unknown tool \"" + f[2] + "\"");
    if (open && tick != current.tick) {
      if (current.tools != static_cast<int>(session.header.tools.size())) reader.fail("a tick is missing a tool's row");
      if (tick < current.tick) reader.fail("ticks out of order");
      session.ticks.push_back(current);
      open = false;
    }
    if (!open) {
      current = start_tick(reader, f, tick);
      open = true;
    }
    if (tool != current.tools) reader.fail("tool rows of a tick out of order");
    read_tool_columns(reader, f, current.tool[static_cast<std::size_t>(tool)]);
    ++current.tools;
  }
  if (reader.line < 3) throw std::runtime_error(file.string() + ": the session file has no header");
  // A last tick cut by a crash (some tool rows missing) is dropped like a partial line.
  if (open && current.tools == static_cast<int>(session.header.tools.size())) session.ticks.push_back(current);
  return session;
}

std::vector<std::vector<ToolState>> session_tool_states(const Session& session) {
  std::vector<std::vector<ToolState>> out(session.header.tools.size());
  for (auto& tool : out) tool.reserve(session.ticks.size());
  for (const TickRecord& r : session.ticks)
    for (std::size_t i = 0; i < out.size(); ++i) {
      ToolState s;
      s.position = r.tool[i].position;
      s.velocity = r.tool[i].velocity;
      s.time = r.t;
      out[i].push_back(s);
    }
  return out;
}

} // namespace kerf
