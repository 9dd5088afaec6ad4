#pragma once
// The parsers kerf fuzzes read files (scene TOML, trajectory / session / profile CSV), so each
// fuzz input is written to a file first: one per process (libFuzzer runs inputs one after the
// other in a process; parallel jobs are separate processes), in /dev/shm when it exists so the
// round trip stays in memory.

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>

namespace kerf::fuzz {

/// A scratch folder of this process: /dev/shm/kerf_fuzz_PID (or TMPDIR/kerf_fuzz_PID), created
/// on first use and removed at exit.
const std::filesystem::path& scratch_directory();

/// Writes `data` to `scratch_directory() / name` (truncating) and returns the path. Throws
/// std::runtime_error if the file cannot be written (a harness failure, not a finding).
std::filesystem::path write_input_file(std::span<const std::byte> data, const std::string& name);

} // namespace kerf::fuzz
