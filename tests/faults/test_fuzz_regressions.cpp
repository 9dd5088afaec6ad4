// Every input the fuzzers of fuzz/ found a defect with (fuzz/regressions/TARGET/FILE) replayed
// through the same harness in the normal suite (and so under ASan + UBSan in the asan stage),
// and, for each finding, what the fixed parser now says about it.

#include "experiments/scene/scene_reader.hpp"
#include "experiments/trajectory/trajectory.hpp"
#include "fuzz/fuzz_targets.hpp"
#include "realtime/haptics/session_file.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

namespace fs = std::filesystem;
using namespace kerf;

namespace {

const fs::path regressions = fs::path(KERF_SOURCE_DIR) / "fuzz" / "regressions";

std::vector<std::byte> bytes_of(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  const std::vector<char> chars((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::byte> out(chars.size());
  for (std::size_t k = 0; k < chars.size(); ++k) out[k] = static_cast<std::byte>(chars[k]);
  return out;
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_fuzz_" + std::to_string(getpid()));
  fs::create_directories(dir);
  return dir / name;
}

/// The message of the std::runtime_error `read` throws ("" if it throws nothing).
template <typename Read>
std::string error_of(Read read) {
  try {
    read();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

} // namespace

TEST(FuzzRegressions, EverySavedInputPassesItsHarness) {
  // Each folder of fuzz/regressions is named after its harness (fuzz_targets.hpp); an input that
  // made a harness crash, throw an undocumented exception or break an invariant before its fix
  // must now pass it (a FuzzFinding or any other escape fails the test, a sanitizer aborts it).
  int replayed = 0;
  for (const auto& folder : fs::directory_iterator(regressions)) {
    const fuzz::FuzzHarness harness = fuzz::find_harness(folder.path().filename().string());
    ASSERT_NE(harness, nullptr) << "no harness named " << folder.path().filename();
    for (const auto& input : fs::directory_iterator(folder.path())) {
      const std::vector<std::byte> data = bytes_of(input.path());
      EXPECT_NO_THROW(harness(data)) << input.path();
      ++replayed;
    }
  }
  EXPECT_GE(replayed, 3); // the three findings below at least
}

TEST(FuzzRegressions, SessionTickOutsideTheUnsignedRangeIsAnErrorNotUndefinedBehaviour) {
  // Finding (fuzz_session_csv): tick "-1" was converted to std::uint64_t unchecked (UBSan:
  // "-1 is outside the range of representable values"). Now a whole number from 0 is required,
  // and so for buttons and status (below 2^32).
  EXPECT_NE(error_of([] { read_session(regressions / "session_csv" / "negative_tick.csv"); }).find("column tick"),
            std::string::npos);
  const std::string header = "# kerf haptic session v1\n# rate_hz=1000 model=m scene=s tools=a\n" +
                             std::string(session_csv_header) + "\n";
  const std::string row_tail = ",a,0,0,0,0,0,0,1,0,0,0,";
  const std::string forces = ",0,0,0,0,0,0,no-contact,0,0,0,0,";
  struct Case { std::string row; std::string column; };
  for (const Case& c : {Case{"1e30,0" + row_tail + "0" + forces + "0,0\n", "column tick"},
                        Case{"0,0" + row_tail + "4294967296" + forces + "0,0\n", "column buttons"},
                        Case{"0,0" + row_tail + "0.5" + forces + "0,0\n", "column buttons"},
                        Case{"0,0" + row_tail + "0" + ",0,0,0,0,0,0,no-contact,0,0,0,0,-2,0\n", "column status"}}) {
    const fs::path file = scratch("session.csv");
    std::ofstream(file) << header << c.row;
    EXPECT_NE(error_of([&] { read_session(file); }).find(c.column), std::string::npos) << c.row;
  }
  // The largest valid values still read exactly.
  const fs::path file = scratch("session_ok.csv");
  std::ofstream(file) << header << "7,0" << row_tail << "4294967295" << ",0,0,0,0,0,0,no-contact,0,0,0,0,"
                      << "4294967295,0\n";
  const Session s = read_session(file);
  ASSERT_EQ(s.ticks.size(), 1u);
  EXPECT_EQ(s.ticks[0].tick, 7u);
  EXPECT_EQ(s.ticks[0].tool[0].buttons, 4294967295u);
  EXPECT_EQ(s.ticks[0].tool[0].status, 4294967295u);
}

TEST(FuzzRegressions, RecordedTrajectoryWithAnAbsurdTimeSpanIsAnErrorNotOutOfMemory) {
  // Finding (fuzz_trajectory_csv): a last time of 200006 s made the 1 kHz resampling allocate
  // 2e8 samples, ~18 GB (libFuzzer: out-of-memory), and a span beyond 2^64 samples converted to size_t
  // unchecked. Now over 1e7 samples is an error naming the file.
  const std::string message = error_of(
      [] { read_recorded_trajectory(regressions / "trajectory_csv" / "huge_time_span.csv", 1000.0); });
  EXPECT_NE(message.find("over 1e7 samples"), std::string::npos) << message;
  const fs::path file = scratch("span.csv");
  std::ofstream(file) << "t,px,py,pz\n-1e308,0,0,0\n1e308,0,0,0\n"; // the span overflows to Inf
  EXPECT_NE(error_of([&] { read_recorded_trajectory(file, 1000.0); }).find("over 1e7 samples"), std::string::npos);
  // A long, valid recording still resamples: 100 s at 1 kHz is 100,001 points (t = 0 .. 100 s).
  const fs::path ok = scratch("span_ok.csv");
  std::ofstream(ok) << "t,px,py,pz\n0,0,0,0\n100,1,0,0\n";
  const SampledTrajectory t = read_recorded_trajectory(ok, 1000.0);
  EXPECT_EQ(t.samples.size(), 100001u);
  EXPECT_DOUBLE_EQ(t.samples.back().position.x(), 1.0);
}

TEST(FuzzRegressions, NonAsciiWhereTomlExpectsWhitespaceIsASyntaxError) {
  // Finding (fuzz_scene, instrumented header-only toml++): toml++ 3.3.0 issue #190, "§" (U+00A7)
  // inside a table header reaches TOML_UNREACHABLE in is_non_ascii_horizontal_whitespace().
  // kerf links Debian's compiled toml++, which rejects it with a position: a SceneError naming
  // the line of the header (line 44 of the saved input).
  std::string message;
  try {
    read_scene(regressions / "scene" / "toml_issue_190_table_header.toml");
  } catch (const SceneError& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("toml_issue_190_table_header.toml:44:"), std::string::npos) << message;
  EXPECT_NE(message.find("TOML syntax"), std::string::npos) << message;
  // The other trigger of #190: a line-ending backslash in a multi-line string followed by "§"
  // reads as the string "§ 5.1" (TOML 1.0: the backslash trims the newline and whitespace).
  std::ifstream in(fs::path(KERF_SCENES_DIR) / "clay_pull.toml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string from = "description = \"Paper 000 §2.1: a stylus pulls the centre of a clay block's top face up 8 mm and holds\"";
  ASSERT_NE(text.find(from), std::string::npos) << "clay_pull.toml changed: update this test";
  text.replace(text.find(from), from.size(), "description = \"\"\"\\\n   \xC2\xA7 5.1\"\"\"");
  const fs::path scene_file = scratch("clay_pull.toml");
  std::ofstream(scene_file) << text;
  EXPECT_EQ(read_scene(scene_file).description, "\xC2\xA7 5.1");
}
