#pragma once
// Writing a file so that a reader never sees half of it: write beside the final name, then
// rename(2), which POSIX makes atomic within one file system.

#include <filesystem>
#include <functional>

namespace kerf {

/// Calls `write(temporary_path)`, then renames the temporary file to `final_path`. If `write`
/// throws, the temporary file is removed and the exception propagates; whatever was at
/// `final_path` before is untouched. Parent directories of `final_path` are created.
void write_atomically(const std::filesystem::path& final_path,
                      const std::function<void(const std::filesystem::path& temporary_path)>& write);

} // namespace kerf
