#pragma once
// ToolModel: the one question every model answers (../shared/DESIGN.md, "Model"): given the
// state of the tool(s) at a sample, what force does the body exert on each tool?

#include "realtime/force_sample.hpp"
#include "realtime/phenomena.hpp"
#include "realtime/tool_state.hpp"

#include <span>
#include <string_view>

namespace kerf {

/// Realtime contract (DESIGN.md): `step` allocates nothing, does no I/O, takes no lock, runs in
/// bounded time, and never returns a NaN or Inf force. Construction may allocate and take time.
class ToolModel {
public:
  virtual ~ToolModel() = default;

  /// Short name used on the command line and in profiles ("fracture", ...).
  [[nodiscard]] virtual std::string_view name() const = 0;

  /// Number of tools this model is built for; `step` takes exactly that many.
  [[nodiscard]] virtual int tool_count() const = 0;

  /// Back to the state before the first sample (no contact, no crack).
  virtual void reset() = 0;

  /// Advances the model by `dt` [s] to the tool states `tools` and writes one force sample per
  /// tool into `forces` (same size as `tools`).
  virtual void step(std::span<const ToolState> tools, double dt, std::span<ForceSample> forces) noexcept = 0;
};

} // namespace kerf
