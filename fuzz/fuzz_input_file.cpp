#include "fuzz/fuzz_input_file.hpp"

#include <unistd.h>

#include <cstdio>
#include <memory>
#include <stdexcept>
#include <system_error>

namespace kerf::fuzz {

namespace {

/// Removes the scratch folder when the process ends normally.
struct ScratchDirectory {
  std::filesystem::path path;
  ScratchDirectory() {
    const std::filesystem::path shm("/dev/shm");
    std::error_code ec;
    const std::filesystem::path base = std::filesystem::is_directory(shm, ec) ? shm : std::filesystem::temp_directory_path();
    path = base / ("kerf_fuzz_" + std::to_string(getpid()));
    std::filesystem::create_directories(path);
  }
  ~ScratchDirectory() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};

} // namespace

const std::filesystem::path& scratch_directory() {
  static const ScratchDirectory directory;
  return directory.path;
}

std::filesystem::path write_input_file(std::span<const std::byte> data, const std::string& name) {
  const std::filesystem::path file = scratch_directory() / name;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(file.c_str(), "wb"), &std::fclose);
  if (!f) throw std::runtime_error(file.string() + ": cannot write the fuzz input");
  if (!data.empty() && std::fwrite(data.data(), 1, data.size(), f.get()) != data.size())
    throw std::runtime_error(file.string() + ": short write of the fuzz input");
  return file;
}

} // namespace kerf::fuzz
