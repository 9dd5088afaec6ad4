// libFuzzer's entry point for one harness, chosen at compile time (KERF_FUZZ_HARNESS, see
// fuzz/CMakeLists.txt): one program per input format.

#include "fuzz/fuzz_targets.hpp"

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  kerf::fuzz::KERF_FUZZ_HARNESS({reinterpret_cast<const std::byte*>(data), size});
  return 0;
}
