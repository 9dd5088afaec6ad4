// Every input the fuzzers of fuzz/ found a defect with (fuzz/regressions/TARGET/FILE) replayed
// through the same harness in the normal suite (and so under ASan + UBSan in the asan stage),
// and, for each finding, what the fixed parser now says about it.

#include "experiments/calibration/calibration.hpp"
#include "experiments/models/model_catalogue.hpp"
#include "experiments/reference_run/reference_checkpoint.hpp"
#include "formats/scene/scene_reader.hpp"
#include "experiments/study/model_recommendation.hpp"
#include "experiments/study/study_spec.hpp"
#include "formats/trajectory/trajectory.hpp"
#include "fuzz/fuzz_targets.hpp"
#include "realtime/haptics/replay_device.hpp"
#include "realtime/haptics/session_file.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
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

/// The message of the `Error` `read` throws ("" if it throws nothing; any other exception fails
/// the test that called it).
template <typename Error = std::runtime_error, typename Read>
std::string error_of(Read read) {
  try {
    read();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

/// The message of the StudyError read_study throws for `file` ("" if it reads).
std::string study_error_of(const fs::path& file) { return error_of<StudyError>([&] { read_study(file); }); }

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
  const std::string from = "description = \"Paper 000 §2.1: a stylus pulls the centre of a clay block's top face up 6 mm and holds\"";
  ASSERT_NE(text.find(from), std::string::npos) << "clay_pull.toml changed: update this test";
  text.replace(text.find(from), from.size(), "description = \"\"\"\\\n   \xC2\xA7 5.1\"\"\"");
  const fs::path scene_file = scratch("clay_pull.toml");
  std::ofstream(scene_file) << text;
  EXPECT_EQ(read_scene(scene_file).description, "\xC2\xA7 5.1");
}

TEST(FuzzRegressions, CorruptReferenceCheckpointsAreErrorsNotJsonExceptionsOrHugeAllocations) {
  // Findings (fuzz_reference_checkpoint): (1) sample records that are not JSON escaped from
  // read_reference_checkpoint as nlohmann::json::parse_error (saved input: a control character
  // in a key), and records of the wrong shape would have escaped run_reference's resume as
  // nlohmann type errors, or converted a JSON number outside int with undefined behaviour;
  // (2) a count was trusted up to 2^32 items (2^34 for the state): a 42 kB input made the reader
  // allocate 1.2 GB (libFuzzer peak RSS, 6 inputs/s), and the saved 164-byte input asks for
  // 2^32 - 1 indices, 32 GiB. Now a count must fit in the bytes left in the file, and the records
  // must be what run_reference resumes from; both are std::runtime_errors naming the file.
  const fs::path dir = regressions / "reference_checkpoint";
  const auto message = [](const fs::path& file) { return error_of([&] { read_reference_checkpoint(file); }); };
  EXPECT_NE(message(dir / "json_control_character.bin").find("corrupt sample records"), std::string::npos);
  EXPECT_NE(message(dir / "huge_index_count.bin").find("corrupt count"), std::string::npos);

  // A checkpoint as run_reference writes it reads back whole (the independent check: every field
  // equal to what was written).
  ReferenceCheckpoint c;
  c.scene_sha256 = std::string(64, 'a');
  c.degree = 2;
  c.refinements = 1;
  c.processes = 3;
  c.dynamic = true;
  c.damped = true;
  c.indices = {0, 4, 8};
  c.solved = 2;
  c.last.load_factor = 0.5;
  c.last.tool_position = {1e-3, 2e-3, 3e-3};
  c.state = {1.0, -2.0, 3.5};
  for (int k = 0; k < 2; ++k) {
    ProfileRow row;
    row.t = 0.1 * k;
    row.tool = "stylus";
    row.force = {0.0, 0.0, 1.5 * k};
    row.mode = InteractionMode::deformation_1;
    c.profile.rows.push_back(row);
    c.samples.push_back({{"index", 4 * k}, {"newton_iterations", 3}, {"contact_points", k}});
  }
  c.solve_seconds = 1.25;
  c.interface_step = 2.5e-4;
  const fs::path file = scratch("checkpoint.bin");
  write_reference_checkpoint(c, file);
  const ReferenceCheckpoint back = read_reference_checkpoint(file);
  EXPECT_EQ(back.scene_sha256, c.scene_sha256);
  EXPECT_EQ(back.indices, c.indices);
  EXPECT_EQ(back.solved, 2u);
  EXPECT_EQ(back.state, c.state);
  EXPECT_EQ(back.last.tool_position, c.last.tool_position);
  ASSERT_EQ(back.profile.rows.size(), 2u);
  EXPECT_EQ(back.profile.rows[1].force, c.profile.rows[1].force);
  EXPECT_EQ(back.samples, c.samples);
  EXPECT_EQ(back.solve_seconds, 1.25);
  EXPECT_TRUE(back.dynamic);
  EXPECT_TRUE(back.damped);
  EXPECT_EQ(back.interface_step, 2.5e-4);

  // Version 3 (before the damping): the same bytes without the damping field after the time
  // integration and without the load path's interface step at the end, read as undamped; version 2 (before the dynamic step; the saved regression inputs
  // above are version 2 too): without the time-integration field either, read as a quasi-static
  // run. Offsets: magic 8 + sha (8 + 64) + degree, refinements, processes 3 × 4 = 92 (time
  // integration), 96 (damping).
  {
    std::ifstream in(file, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_EQ(bytes.substr(0, 8), "KERFREF4");
    std::string v3 = bytes;
    v3[7] = '3';
    v3.erase(v3.size() - 8);
    v3.erase(96, 4);
    const fs::path v3_file = scratch("checkpoint_v3.bin");
    std::ofstream(v3_file, std::ios::binary) << v3;
    const ReferenceCheckpoint third = read_reference_checkpoint(v3_file);
    EXPECT_TRUE(third.dynamic);
    EXPECT_FALSE(third.damped);
    EXPECT_EQ(third.interface_step, 0.0);
    EXPECT_EQ(third.state, c.state);
    EXPECT_EQ(third.samples, c.samples);
    std::string bad_damping = bytes;
    bad_damping[96] = 7;
    std::ofstream(v3_file, std::ios::binary) << bad_damping;
    EXPECT_NE(message(v3_file).find("corrupt damping"), std::string::npos);
    std::string v2 = v3;
    v2[7] = '2';
    v2.erase(92, 4);
    const fs::path old_file = scratch("checkpoint_v2.bin");
    std::ofstream(old_file, std::ios::binary) << v2;
    const ReferenceCheckpoint old = read_reference_checkpoint(old_file);
    EXPECT_FALSE(old.dynamic);
    EXPECT_FALSE(old.damped);
    EXPECT_EQ(old.indices, c.indices);
    EXPECT_EQ(old.state, c.state);
    EXPECT_EQ(old.samples, c.samples);
    // A time-integration value other than 0 or 1 is a corrupt file.
    std::string bad = bytes;
    bad[92] = 7;
    std::ofstream(old_file, std::ios::binary) << bad;
    EXPECT_NE(message(old_file).find("corrupt time integration"), std::string::npos);
  }

  // Records run_reference could not resume from.
  for (const nlohmann::json& bad : {nlohmann::json{{"newton_iterations", 1e300}, {"contact_points", 0}},
                                    nlohmann::json{{"newton_iterations", "3"}, {"contact_points", 0}},
                                    nlohmann::json{{"newton_iterations", 3}},
                                    nlohmann::json{{"newton_iterations", 3}, {"contact_points", 0}, {"energy", 1}},
                                    nlohmann::json{{"newton_iterations", 3},
                                                   {"contact_points", 0},
                                                   {"energy",
                                                    {{"external_work_J", 1.0},
                                                     {"stored_elastic_energy_J", 1.0},
                                                     {"interface_energy_J", 0.0},
                                                     {"cohesive_dissipation_J", 0.0},
                                                     {"viscous_dissipation_J", 0.0},
                                                     {"failed_area_m2", 0.0},
                                                     {"kinetic_energy_J", "0"},
                                                     {"last_positions_m", nlohmann::json::array()},
                                                     {"last_forces_on_body_N", nlohmann::json::array()}}}}}) {
    ReferenceCheckpoint corrupt = c;
    corrupt.samples[1] = bad;
    write_reference_checkpoint(corrupt, file);
    EXPECT_NE(message(file).find("corrupt sample records"), std::string::npos) << bad.dump();
  }
  ReferenceCheckpoint short_records = c;
  short_records.samples.erase(1); // two solved samples, one record
  write_reference_checkpoint(short_records, file);
  EXPECT_NE(message(file).find("corrupt sample records"), std::string::npos);
}

TEST(FuzzRegressions, StudyWithAnUnlookableSceneNameOrSamplesPastIntIsAStudyError) {
  // Found by reading study_spec.cpp, confirmed through fuzz_study (the 4-minute run did not reach
  // them): (1) a scene name the file system cannot look up (300 characters: ENAMETOOLONG) escaped
  // as std::filesystem::filesystem_error, which names no line; (2) samples = 4294967297 was
  // accepted and converted to int as 1 (below the documented minimum of 2). Both are
  // StudyErrors naming file:line:column and the key.
  const std::string name = study_error_of(regressions / "study" / "scene_name_too_long.toml");
  EXPECT_NE(name.find("scene_name_too_long.toml:3:"), std::string::npos) << name;
  EXPECT_NE(name.find("study.scenes: no scene"), std::string::npos) << name;
  const std::string samples = study_error_of(regressions / "study" / "samples_past_int.toml");
  EXPECT_NE(samples.find("samples_past_int.toml:6:"), std::string::npos) << samples;
  EXPECT_NE(samples.find("reference.samples: expected an integer in 2..2147483647"), std::string::npos) << samples;
  // The largest int still reads (the bound is the type's, not a smaller policy).
  const fs::path ok = scratch("largest_samples.toml");
  std::ofstream(ok) << "[study]\nname = \"x\"\nscenes = [\"clay_pull\"]\nmodels = [\"springs\"]\n"
                    << "[reference]\nsamples = 2147483647\n";
  EXPECT_EQ(read_study(ok).reference.samples, 2147483647);
}

TEST(FuzzRegressions, StudyIntegerGivenAsAHugeFloatIsAStudyErrorNotUndefinedBehaviour) {
  // Finding (fuzz_study, the campaign): samples = 6.67e87 (a float) was read with toml++'s
  // value<int64_t>(), which casts a float to int64_t unchecked (UBSan: "6.66667e+87 is outside the
  // range of representable values of type 'long'"). The study reader takes integers only as
  // TOML integers (value_exact), as the scene reader does: any float is "expected an integer".
  const std::string huge = study_error_of(regressions / "study" / "float_samples_beyond_int64.toml");
  EXPECT_NE(huge.find("float_samples_beyond_int64.toml:9:"), std::string::npos) << huge;
  EXPECT_NE(huge.find("reference.samples: expected an integer in 2..2147483647"), std::string::npos) << huge;
  // A whole float is a float too, in every integer key of a study file.
  for (const char* line : {"[reference]\nsamples = 12.0\n", "[reference]\ndegree = 2.0\n", "[reference]\nrefinements = [0.0]\n",
                           "[models.springs]\nresolutions = [4.0]\n"}) {
    const fs::path file = scratch("float_integer.toml");
    std::ofstream(file) << "[study]\nname = \"x\"\nscenes = [\"clay_pull\"]\nmodels = [\"springs\"]\n" << line;
    EXPECT_NE(study_error_of(file).find("expected"), std::string::npos) << line;
  }
}

TEST(FuzzRegressions, StudyTableWithANonFiniteOrNegativeMeasurementIsAnError) {
  // Found by reading model_recommendation.cpp, confirmed through fuzz_study_table: "nan" in the
  // error column (or "-inf" as a cost) read as a number, passed every budget comparison of
  // recommend_model and was recommended ("nan %" within 10 %). A measured error or cost is now
  // empty or a finite number >= 0; anything else is an error naming file:line.
  for (const char* name : {"nan_error.csv", "negative_infinite_cost.csv"}) {
    const std::string message = error_of([&] { read_study_rows(regressions / "study_table" / name); });
    EXPECT_NE(message.find(std::string(name) + ":2: "), std::string::npos) << message;
    EXPECT_NE(message.find("is not a finite number >= 0"), std::string::npos) << message;
  }
  // Zero and an empty field still read (a perfect model; a row that was not scored).
  const fs::path ok = scratch("study.csv");
  std::ofstream(ok) << "scene,model,RMS force error [%],p99 cost [\xC2\xB5s]\npotato,a,0,0\npotato,b,,\n";
  const auto rows = read_study_rows(ok);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].rms_error, 0.0);
  EXPECT_FALSE(rows[1].rms_error.has_value());
  EXPECT_EQ(recommend_model(rows, "potato", 0.1, 1000.0).choice->model, "a");
}

TEST(FuzzRegressions, ReplayNeverGivesANonFinitePosition) {
  // Finding (fuzz_replay, the 4-minute run): a session file whose tick 1 has the time "0.<NUL
  // bytes>35099..." read as t = 0 (strtod stops at the NUL, and the check looked for the NUL,
  // not the field's end), so ticks 0 and 1 had the same time; the replay divided by that zero
  // time step and gave a NaN position, which no link check stands between it and the model.
  // Now a number must fill its whole field (session files and replay CSVs), and a session's
  // times must increase strictly to be replayed.
  const std::string session = error_of([] { read_session(regressions / "replay" / "session_time_with_nul.csv"); });
  EXPECT_NE(session.find("session_time_with_nul.csv:5: column t: expected a finite number"), std::string::npos) << session;
  const std::string header = "# kerf haptic session v1\n# rate_hz=1000 model=m scene=s tools=a\n" +
                             std::string(session_csv_header) + "\n";
  const std::string row_tail = ",a,0,0,0,0,0,0,1,0,0,0,0,0,0,0,0,0,0,no-contact,0,0,0,0,0,0\n";
  const fs::path same_time = scratch("same_time.csv");
  std::ofstream(same_time) << header << "0,0.5" << row_tail << "1,0.5" << row_tail;
  EXPECT_EQ(read_session(same_time).ticks.size(), 2u); // a valid session file ...
  EXPECT_NE(error_of([&] { ReplayDevice device(same_time, 0, 8.5); }).find("tick 1: time must increase strictly"),
            std::string::npos); // ... but not a replay
  // Found by reading the interpolation, confirmed through fuzz_replay: finite samples whose
  // difference overflows (1e308 m, then -1e308 m) gave NaN at the first poll (0 x -Inf). Now
  // (1 - s) p0 + s p1, finite; and a normal replay still interpolates linearly (independent
  // value: halfway between (0,0,0) and (2,4,6) mm at t = 0.5 s of 1 s is (1,2,3) mm).
  ReplayDevice extreme(regressions / "replay" / "position_difference_overflows.csv", 0, 8.5);
  for (const double now : {0.0, 0.5, 1.0, 2.0}) {
    extreme.poll(now);
    EXPECT_TRUE(extreme.state().position.allFinite()) << now;
  }
  const fs::path line = scratch("line.csv");
  std::ofstream(line) << "t,px,py,pz\n0,0,0,0\n1,0.002,0.004,0.006\n";
  ReplayDevice replay(line, 0, 8.5);
  replay.poll(10.0);
  replay.poll(10.5);
  EXPECT_NEAR((replay.state().position - Eigen::Vector3d(0.001, 0.002, 0.003)).norm(), 0.0, 1e-15);
}

TEST(FuzzHarnesses, EveryModelTheStudyReaderAcceptsHasABuilder) {
  // The study reader (and the fuzz build) accepts the names of model_description.cpp; each must be
  // one the catalogue can check and build: asked for a scene, it answers with the scene's fit
  // (ModelMismatch or nothing), never with "unknown model".
  const Scene scene = read_scene(std::filesystem::path(KERF_SCENES_DIR) / "potato_rect_cut.toml");
  ASSERT_FALSE(model_catalogue().empty());
  for (const ModelDescription& d : model_catalogue()) {
    try {
      EXPECT_EQ(require_model_for_scene(d.name, scene).name, d.name);
    } catch (const ModelMismatch&) {
    } catch (const std::invalid_argument& e) {
      ADD_FAILURE() << d.name << ": " << e.what();
    }
  }
  EXPECT_THROW(require_model_for_scene("no-such-model", scene), std::invalid_argument);
}

TEST(FuzzHarnesses, ParameterFilesWrittenByCalibrateReadBackThroughTheHarness) {
  // Every parameter file `kerf calibrate` can write for a repository scene (parameter_file_text
  // with the scene's own values) passes fuzz_parameter_file with that scene picked, and the
  // scene read with it has the values written, to the 9 significant digits they are written with.
  const fuzz::FuzzHarness harness = fuzz::find_harness("parameter_file");
  ASSERT_NE(harness, nullptr);
  std::vector<fs::path> scenes;
  for (const auto& e : fs::directory_iterator(KERF_SCENES_DIR))
    if (e.path().extension() == ".toml") scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end()); // the harness's order: the first byte is the index
  int written = 0;
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    const Scene scene = read_scene(scenes[k]);
    for (const std::string model : {"fracture", "springs", "voxel"}) {
      CalibratedParameters p;
      try {
        p = scene_parameters(model, scene);
      } catch (const std::exception&) {
        continue; // the scene has no section for the model, or the model no free parameter
      }
      for (double& v : p.values) v *= 1.5; // values the scene does not already have
      const std::string text = parameter_file_text(p, "calibrated for the test\n\nby hand");
      std::vector<std::byte> data{static_cast<std::byte>(k)};
      for (char c : text) data.push_back(static_cast<std::byte>(c));
      EXPECT_NO_THROW(harness(data)) << scenes[k] << " " << model;
      const fs::path file = scratch("calibrated.toml");
      std::ofstream(file) << text;
      const CalibratedParameters back = scene_parameters(model, read_scene(scenes[k], {file}));
      ASSERT_EQ(back.values.size(), p.values.size());
      for (std::size_t i = 0; i < p.values.size(); ++i)
        EXPECT_NEAR(back.values[i], p.values[i], 1e-8 * std::abs(p.values[i])) << scenes[k] << " " << model << " " << i;
      ++written;
    }
  }
  EXPECT_GE(written, 5); // fracture on the cutting scenes, voxel on the sponges, springs on the clay scenes
}

TEST(FuzzHarnesses, TheRepositoryStudiesPassTheStudyHarness) {
  // The seeds of fuzz_study: every study file of the repository is accepted, as it is.
  const fuzz::FuzzHarness harness = fuzz::find_harness("study");
  ASSERT_NE(harness, nullptr);
  int studies = 0;
  for (const auto& e : fs::directory_iterator(KERF_STUDIES_DIR)) {
    if (e.path().extension() != ".toml") continue;
    EXPECT_NO_THROW(harness(bytes_of(e.path()))) << e.path();
    EXPECT_NO_THROW(read_study(e.path())) << e.path();
    ++studies;
  }
  EXPECT_GE(studies, 1);
}
