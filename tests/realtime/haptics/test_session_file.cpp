// Session files: what the recorder writes, read_session reads back bit for bit (%.17g round
// trips binary64); a row cut by a crash is dropped, a wrong file is refused with its line.

#include "realtime/haptics/device_protocol.hpp"
#include "realtime/haptics/session_recorder.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <unistd.h>
#include <fstream>

using namespace kerf;

namespace {

std::filesystem::path temp_file(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("kerf_test_session_" + std::to_string(getpid())); // per process: parallel ctest runs
  std::filesystem::create_directories(dir);
  return dir / name;
}

TickRecord record(std::uint64_t k) {
  TickRecord r;
  r.tick = k;
  r.t = static_cast<double>(k) / 1000.0;
  r.compute = 1e-6 * static_cast<double>(k);
  r.late = 3e-6;
  r.tools = 2;
  for (int i = 0; i < 2; ++i) {
    ToolTick& t = r.tool[static_cast<std::size_t>(i)];
    t.position = {0.1 / 3.0 + static_cast<double>(k), -1.0 / 7.0, 1e-9 * i};
    t.velocity = {1.0 / 3.0, 0.0, -2.0};
    t.model_force = {std::sqrt(2.0), 0.0, -1e-17};
    t.force = {1.0, 0.0, -0.5};
    t.mode = i == 0 ? InteractionMode::cutting : InteractionMode::deformation_1;
    t.crack_extent = 0.001 * static_cast<double>(k);
    t.link_age = 1e-3;
    t.status = safety_clamped | safety_ramping;
    t.injected = -0.125;
    t.buttons = 3;
  }
  return r;
}

} // namespace

TEST(SessionFile, RecorderWritesWhatTheReaderReadsBack) {
  const auto file = temp_file("round_trip.csv");
  SessionHeader header{1000.0, "fracture", "potato_rect_cut", {"left", "right"}};
  {
    SessionRecorder recorder(file, header, 64);
    for (std::uint64_t k = 0; k < 50; ++k) ASSERT_TRUE(recorder.push(record(k)));
    recorder.close();
    EXPECT_EQ(recorder.written(), 50u);
    EXPECT_EQ(recorder.dropped(), 0u);
  }
  const Session s = read_session(file);
  EXPECT_EQ(s.header.rate, 1000.0);
  EXPECT_EQ(s.header.model, "fracture");
  EXPECT_EQ(s.header.tools, (std::vector<std::string>{"left", "right"}));
  ASSERT_EQ(s.ticks.size(), 50u);
  for (std::uint64_t k = 0; k < 50; ++k) {
    const TickRecord e = record(k);
    const TickRecord& r = s.ticks[k];
    EXPECT_EQ(r.tick, k);
    EXPECT_EQ(r.t, e.t);
    for (std::size_t i = 0; i < 2; ++i) {
      EXPECT_EQ(r.tool[i].position, e.tool[i].position);
      EXPECT_EQ(r.tool[i].velocity, e.tool[i].velocity);
      EXPECT_EQ(r.tool[i].model_force, e.tool[i].model_force);
      EXPECT_EQ(r.tool[i].force, e.tool[i].force);
      EXPECT_EQ(r.tool[i].mode, e.tool[i].mode);
      EXPECT_EQ(r.tool[i].status, e.tool[i].status);
      EXPECT_EQ(r.tool[i].injected, e.tool[i].injected);
    }
  }
  const auto states = session_tool_states(s);
  ASSERT_EQ(states.size(), 2u);
  EXPECT_EQ(states[1][7].position, record(7).tool[1].position);
  EXPECT_EQ(states[0][7].time, 0.007);
}

TEST(SessionFile, FullRingDropsAndCountsWithoutBlocking) {
  const auto file = temp_file("full.csv");
  SessionRecorder recorder(file, {1000.0, "m", "s", {"a"}}, 4);
  int accepted = 0;
  for (std::uint64_t k = 0; k < 1000; ++k) accepted += recorder.push(record(k)) ? 1 : 0;
  recorder.close();
  EXPECT_EQ(recorder.written() + recorder.dropped(), 1000u);
  EXPECT_EQ(recorder.written(), static_cast<std::uint64_t>(accepted));
  EXPECT_GE(recorder.dropped(), 1u); // 1000 pushes into 4 slots cannot all fit before a 20 ms drain
}

TEST(SessionFile, RowCutByACrashIsDroppedAndBadFilesNameTheLine) {
  const auto file = temp_file("cut.csv");
  {
    SessionRecorder recorder(file, {500.0, "m", "s", {"a", "b"}}, 16);
    for (std::uint64_t k = 0; k < 3; ++k) recorder.push(record(k));
    recorder.close();
  }
  // Append tick 3's first row and half of its second, as a crash mid-write would leave it.
  std::string text;
  {
    std::ifstream in(file);
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  // The row of tool "a" of the last tick (the second-to-last line).
  const auto last = text.rfind('\n', text.size() - 2);
  const auto before = text.rfind('\n', last - 1);
  const auto row = text.substr(before + 1, last - before);
  {
    std::ofstream out(file, std::ios::app);
    out << "3" << row.substr(row.find(',')) << row.substr(0, 30);
  }
  EXPECT_EQ(read_session(file).ticks.size(), 3u);

  {
    std::ofstream out(file, std::ios::app);
    out << "\nnot,a,row\n";
  }
  try {
    read_session(file);
    FAIL() << "a malformed row was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cut.csv:"), std::string::npos) << e.what();
  }
  std::ofstream(temp_file("other.csv")) << "t,px,py,pz\n0,0,0,0\n";
  EXPECT_THROW(read_session(temp_file("other.csv")), std::runtime_error);
}
