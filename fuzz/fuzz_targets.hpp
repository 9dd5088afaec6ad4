#pragma once
// The fuzz harnesses: one per input format kerf parses (docs/reliability.md). Each takes the raw bytes of
// one input and returns normally when the parser either accepted it (and what it returned
// satisfies the format's documented invariants) or rejected it with the documented error type.
// Anything else escapes: an undocumented exception (libFuzzer aborts on it and saves the input),
// a FuzzFinding (a documented invariant broken), or a sanitizer report.
//
// The same functions run in two places: the libFuzzer programs of fuzz/ (clang, built with
// -DKERF_FUZZ=ON) and, in the normal test suite, tests/faults/test_fuzz_regressions.cpp, which
// replays every saved crash input (fuzz/regressions/TARGET/) and the seed corpus through them.

#include <cstddef>
#include <span>
#include <stdexcept>
#include <string_view>

namespace kerf::fuzz {

/// A parser accepted an input but what it returned breaks the format's documented invariants.
class FuzzFinding : public std::logic_error {
public:
  using std::logic_error::logic_error;
};

/// Device protocol decoder (realtime/haptics/device_protocol.hpp). The input is a stream of
/// datagrams, each one length byte followed by that many bytes (a short tail is a datagram of
/// its own). Each datagram is decoded as a device state and as a force command; accepted ones
/// must be finite with a unit quaternion and encode back to the same bytes; all of them go
/// through receive_device_state, after which received = accepted + dropped.
void fuzz_device_protocol(std::span<const std::byte> data);

/// Quantities with units (formats/scene/quantity.hpp): the first byte picks the Dimension,
/// the rest is the text. Only QuantityError may be thrown; a result must be finite.
void fuzz_quantity(std::span<const std::byte> data);

/// Scene files (formats/scene/scene_reader.hpp): the input is written as scene.toml in the
/// scratch folder (its `geo = "NAME.geo"` resolves to meshes/geo). Only SceneError may be thrown.
/// TOML itself is parsed by the toml++ that kerf links (Debian's compiled libtomlplusplus, not
/// instrumented): its header-only form, instrumented, stops at once on toml++ 3.3.0's issue #190
/// (is_non_ascii_horizontal_whitespace() reaches TOML_UNREACHABLE for a code point such as U+00A7
/// where whitespace may stand, e.g. "[a §]"); Debian's build rejects those inputs correctly
/// (tests/faults/test_fuzz_regressions.cpp), so the fuzzer works on kerf's reader above it.
void fuzz_scene(std::span<const std::byte> data);

/// Recorded trajectory CSV (formats/trajectory/trajectory.hpp), resampled at 1 kHz. Only
/// std::runtime_error may be thrown; samples must be finite, time-ordered at 1 ms.
void fuzz_trajectory_csv(std::span<const std::byte> data);

/// Haptic session files (realtime/haptics/session_file.hpp). Only std::runtime_error may be
/// thrown; ticks must be in order with every tool present and finite.
void fuzz_session_csv(std::span<const std::byte> data);

/// Force profile CSV (formats/profile/force_profile.hpp), as the study reads it back. Only
/// std::runtime_error may be thrown; rows must be finite with a tool name.
void fuzz_profile_csv(std::span<const std::byte> data);

/// Study files (experiments/study/study_spec.hpp, `kerf study FILE`): the input is written as
/// study.toml in the scratch folder, beside a parameter file calibrated.toml ([models.fracture])
/// that a [calibration] entry may name; scene names resolve beside it, then in experiments/scenes.
/// Only StudyError may be thrown; an accepted study must satisfy study_spec.hpp's ranges (a name,
/// at least one existing scene and one catalogue model, degree 1 or 2, levels 0..4, samples >= 2,
/// calibrations only for its scenes).
void fuzz_study(std::span<const std::byte> data);

/// Parameter files (`kerf calibrate -o`, included by scenes; formats/scene/scene_reader.hpp):
/// the first byte picks one of the repository's scenes (experiments/scenes/*.toml, sorted), the
/// rest is the parameter file given to read_scene after the scene's own includes. The same file
/// goes through calibrated_models (the study's reader of parameter files). Only SceneError (scene)
/// and StudyError (study) may be thrown; a file the scene accepts calibrates only fracture, voxel
/// or springs, and the scene read with it has that model's section.
void fuzz_parameter_file(std::span<const std::byte> data);

/// Study tables read back by `kerf recommend` (experiments/study/model_recommendation.hpp). Only
/// std::runtime_error may be thrown; for every scene of the rows read, a recommended row must be
/// of that scene, not a reference row, and within both budgets (0 <= error <= 10 %, 0 <= p99 cost
/// <= 1 ms).
void fuzz_study_table(std::span<const std::byte> data);

/// Reference checkpoints (experiments/reference_run/reference_checkpoint.hpp, read by `kerf reference
/// --resume`). Only std::runtime_error may be thrown; an accepted checkpoint has no more samples
/// solved than requested, valid modes, and sample records that run_reference can resume from
/// (what it reads of them is read here too: a JSON type error escaping is a finding).
void fuzz_reference_checkpoint(std::span<const std::byte> data);

/// Replay files of the `replay:FILE` device (realtime/haptics/replay_device.hpp): a trajectory
/// CSV or a session file, played as tool 0. Only std::runtime_error may be thrown; an accepted
/// replay has a positive duration and gives a finite position at every poll, before, during and
/// after its time span.
void fuzz_replay(std::span<const std::byte> data);

/// A harness by name ("device_protocol", "quantity", "scene", "trajectory_csv", "session_csv",
/// "profile_csv", "study", "parameter_file", "study_table", "reference_checkpoint", "replay"), or
/// nullptr.
using FuzzHarness = void (*)(std::span<const std::byte>);
FuzzHarness find_harness(std::string_view name);

} // namespace kerf::fuzz
