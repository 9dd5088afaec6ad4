#pragma once
// BackgroundCut: the geometric cut of paper 000 §3.2 run off the servo thread. The servo thread
// records the cutting edge's trajectory into a buffer sized in advance and hands it over with one
// atomic store; a worker thread turns it into the swept surface (Fig. 9), cuts the body and
// publishes the count of cuts applied with another atomic store. The servo side never allocates,
// locks, waits or signals.

#include "meshes/blade_shape.hpp"
#include "realtime/edge/geometric_cut.hpp"

#include <Eigen/Core>

#include <atomic>
#include <functional>
#include <string>
#include <thread>
#include <vector>

namespace kerf {

/// Hand-over protocol (single producer, single consumer, on one atomic state word):
/// - recording (state 0): the servo thread owns the buffer; `record` appends edge-centre
///   positions, `submit` publishes the count and stores state 1 (release);
/// - submitted (state 1): the worker, which polls the state every millisecond (acquire), owns the
///   buffer: it copies the positions, empties the buffer and stores state 0 (release), then
///   builds the swept surface, cuts, runs the after-cut hook and increments `cuts_done` (release).
/// While a pass is handed over the servo thread's `record` and `submit` return false (nothing
/// waits; the positions are dropped and counted). The worker keeps the body; it is read through
/// `body()` only after `wait_until_idle()`.
class BackgroundCut {
public:
  /// Called on the worker thread after each cut, with the body as cut and what the cut did.
  using AfterCut = std::function<void(const CuttableBody&, const GeometricCutReport&)>;

  /// Takes the body's mesh (positively oriented tetrahedra), the blade whose edge's trajectory is
  /// recorded (its edge_direction and edge_length L, the swept strip's width, sweep_edge; the
  /// wedge is not used), the cut's tolerances, the buffer capacity in positions (>= 2) and an
  /// optional hook; starts the worker. Throws std::invalid_argument on a bad edge or capacity.
  BackgroundCut(TetMesh mesh, BladeShape blade, GeometricCutOptions options = {}, int capacity = 4096,
                AfterCut after_cut = {});
  ~BackgroundCut();
  BackgroundCut(const BackgroundCut&) = delete;
  BackgroundCut& operator=(const BackgroundCut&) = delete;

  // Servo thread: no allocation, no lock, no wait.
  /// Appends the edge centre `centre` [m] to the pass being recorded; false (and dropped) when
  /// the buffer is full or handed over.
  bool record(const Eigen::Vector3d& centre) noexcept;
  /// Hands the recorded pass (at least two positions) to the worker; false when there are fewer
  /// or a pass is still handed over.
  bool submit() noexcept;
  /// Positions recorded in the pass so far (0 while handed over).
  [[nodiscard]] int recorded() const noexcept;
  /// The last position recorded (valid when recorded() > 0).
  [[nodiscard]] const Eigen::Vector3d& last_recorded() const noexcept;
  /// Passes the worker has finished (cut, or failed with error()).
  [[nodiscard]] int cuts_done() const noexcept { return m_cuts_done.load(std::memory_order_acquire); }
  /// A pass is handed over or being cut.
  [[nodiscard]] bool busy() const noexcept { return m_busy.load(std::memory_order_acquire); }
  /// Positions dropped because the buffer was full or handed over.
  [[nodiscard]] long dropped() const noexcept { return m_dropped.load(std::memory_order_relaxed); }

  // Any other thread (not realtime).
  /// Blocks (polling) until no pass is handed over or being cut.
  void wait_until_idle() const;
  /// The body as cut so far, its cut reports, and the message of a cut that threw (empty when
  /// none did). Call after wait_until_idle().
  [[nodiscard]] const CuttableBody& body() const { return m_body; }
  [[nodiscard]] const std::vector<GeometricCutReport>& reports() const { return m_reports; }
  [[nodiscard]] const std::string& error() const { return m_error; }
  /// Waits until idle, then restores the uncut body and empties the buffer.
  void reset();

private:
  void work();

  const TetMesh m_original;
  CuttableBody m_body;
  BladeShape m_blade;
  GeometricCutOptions m_options;
  AfterCut m_after_cut;
  std::vector<Eigen::Vector3d> m_buffer; ///< sized once
  int m_count = 0;                       ///< owned by whoever owns the buffer (see the protocol)
  std::atomic<int> m_state{0};           ///< 0 recording, 1 handed over
  std::atomic<bool> m_busy{false};
  std::atomic<int> m_cuts_done{0};
  std::atomic<long> m_dropped{0};
  std::atomic<bool> m_stop{false};
  std::vector<GeometricCutReport> m_reports;
  std::string m_error;
  std::thread m_worker;
};

} // namespace kerf
