#pragma once
// ViewFrame: one snapshot of a running model, taken in the thread that steps the model and read
// by the render thread through a TripleBuffer (realtime/haptics/triple_buffer.hpp). Everything is
// sized before the session (ModelAdapter::reserve), so taking a snapshot only copies numbers.
// VTK-free: the servo side of the viewer never touches rendering.

#include "realtime/force_sample.hpp"
#include "realtime/haptics/session_file.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace kerf {

/// The part of a model's state that carries its geometry, as plain arrays a model adapter fills
/// (viewer/model_adapter.hpp says what each adapter puts where). Capacities are fixed before the
/// session; `point_count` and `cell_count` say how much of them is in use.
struct ModelState {
  Eigen::Matrix3Xd points;                  ///< 3 x capacity: current positions [m] (network nodes, polygon vertices, edge points)
  Eigen::Matrix3Xd rest;                    ///< 3 x capacity: rest positions of the same points [m]
  std::vector<std::array<int, 8>> cells;    ///< capacity: point indices per cell (network cells)
  int point_count = 0;
  int cell_count = 0;
  std::array<double, 24> scalars{};         ///< model-specific numbers (adapter-defined, SI units)
  std::uint64_t topology = 0;               ///< changes whenever `cells` changes (tears, cuts)
  /// An object the model published and never changes afterwards (adapter-defined: the
  /// shape-forming stage), or null. Read by the render thread; it lives until the model is reset
  /// or destroyed, which happens only between sessions.
  const void* published = nullptr;
};

/// Servo statistics as the servo thread last saw them (all zero outside a live session).
struct ServoCounters {
  std::uint64_t ticks = 0;
  std::uint64_t overruns = 0;
  std::uint64_t missed_deadlines = 0;
  double tick_mean = 0.0; ///< [s]
  double tick_max = 0.0;  ///< [s]
};

/// One snapshot: the model time, each tool's state and force sample, the servo statistics and
/// the model's geometry-bearing state.
struct ViewFrame {
  double time = -1.0;                                     ///< model time [s]; < 0: nothing captured yet
  std::uint64_t sequence = 0;                             ///< counts snapshots
  int tool_count = 0;
  std::array<Eigen::Vector3d, max_session_tools> tool_position{};  ///< [m]
  std::array<ForceSample, max_session_tools> force{};              ///< force of the body on each tool [N]
  ServoCounters servo;
  ModelState model;
};

} // namespace kerf
