#include "meshes/atomic_file.hpp"

#include <stdexcept>
#include <system_error>

#include <unistd.h>

namespace kerf {

void write_atomically(const std::filesystem::path& final_path,
                      const std::function<void(const std::filesystem::path&)>& write) {
  namespace fs = std::filesystem;
  if (final_path.has_parent_path()) fs::create_directories(final_path.parent_path());
  // Same directory as the final file (rename is atomic only within one file system); the
  // extension is kept last so writers that pick a format from it (VTK, gmsh) still do.
  fs::path temporary = final_path;
  temporary.replace_filename(final_path.stem().string() + ".tmp." + std::to_string(::getpid()) +
                             final_path.extension().string());
  try {
    write(temporary);
    if (!fs::exists(temporary))
      throw std::runtime_error("writing " + final_path.string() + ": the writer produced no file");
    fs::rename(temporary, final_path);
  } catch (...) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw;
  }
}

} // namespace kerf
