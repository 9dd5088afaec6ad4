#include "fuzz/fuzz_targets.hpp"

#include "formats/scene/quantity.hpp"

#include <cmath>
#include <string_view>

namespace kerf::fuzz {

void fuzz_quantity(std::span<const std::byte> data) {
  if (data.empty()) return;
  constexpr int dimensions = static_cast<int>(Dimension::stiffness_per_area) + 1;
  const auto dimension = static_cast<Dimension>(std::to_integer<int>(data[0]) % dimensions);
  const std::string_view text(reinterpret_cast<const char*>(data.data() + 1), data.size() - 1);
  try {
    const double value = parse_quantity(text, dimension);
    if (!std::isfinite(value)) throw FuzzFinding("parse_quantity returned a non-finite value");
  } catch (const QuantityError&) {
    // The documented rejection.
  }
}

} // namespace kerf::fuzz
