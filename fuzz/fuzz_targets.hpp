#pragma once
// The fuzz harnesses: one per input format kerf parses (issue 10). Each takes the raw bytes of
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

/// Quantities with units (experiments/scene/quantity.hpp): the first byte picks the Dimension,
/// the rest is the text. Only QuantityError may be thrown; a result must be finite.
void fuzz_quantity(std::span<const std::byte> data);

/// Scene files (experiments/scene/scene_reader.hpp): the input is written as scene.toml in the
/// scratch folder (its `geo = "NAME.geo"` resolves to meshes/geo). Only SceneError may be thrown.
/// TOML itself is parsed by the toml++ that kerf links (Debian's compiled libtomlplusplus, not
/// instrumented): its header-only form, instrumented, stops at once on toml++ 3.3.0's issue #190
/// (is_non_ascii_horizontal_whitespace() reaches TOML_UNREACHABLE for a code point such as U+00A7
/// where whitespace may stand, e.g. "[a §]"); Debian's build rejects those inputs correctly
/// (tests/faults/test_fuzz_regressions.cpp), so the fuzzer works on kerf's reader above it.
void fuzz_scene(std::span<const std::byte> data);

/// Recorded trajectory CSV (experiments/trajectory/trajectory.hpp), resampled at 1 kHz. Only
/// std::runtime_error may be thrown; samples must be finite, time-ordered at 1 ms.
void fuzz_trajectory_csv(std::span<const std::byte> data);

/// Haptic session files (realtime/haptics/session_file.hpp). Only std::runtime_error may be
/// thrown; ticks must be in order with every tool present and finite.
void fuzz_session_csv(std::span<const std::byte> data);

/// Force profile CSV (experiments/profile/force_profile.hpp), as the study reads it back. Only
/// std::runtime_error may be thrown; rows must be finite with a tool name.
void fuzz_profile_csv(std::span<const std::byte> data);

/// A harness by name ("device_protocol", "quantity", "scene", "trajectory_csv", "session_csv",
/// "profile_csv"), or nullptr.
using FuzzHarness = void (*)(std::span<const std::byte>);
FuzzHarness find_harness(std::string_view name);

} // namespace kerf::fuzz
