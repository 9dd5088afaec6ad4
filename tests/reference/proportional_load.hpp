#pragma once
// Proportional loading in `steps` equal steps: target k (1..steps) at load factor and time k/steps,
// its sample k — the load path of the tests that ramp a boundary value (the DCB's opening, the
// cohesive bar's pull).

#include "reference/load_path.hpp"

namespace kerf::reference::test {

inline LoadTarget proportional_target(int k, int steps) {
  LoadTarget target;
  target.load.load_factor = static_cast<double>(k) / steps;
  target.load.time = target.load.load_factor;
  target.sample = static_cast<std::size_t>(k);
  return target;
}

} // namespace kerf::reference::test
