#pragma once
// FactorRefresh: a spring network's Newton matrix assembled and factorised on a worker thread,
// so that the servo thread never factorises (docs/spring-network.md §2, "The kept factor and
// its refresh"). The servo thread hands over a snapshot of the state (positions, and the cells'
// corners, masses and constraints that a tear changes) and a NetworkSystem it does not touch
// until the job is collected; the worker binds the snapshot's vertex splits into that system
// (or, asked to re-analyse, rebuilds it for the network as it is, with decoupled shadows:
// allocation on the worker's side only), assembles A = w_m M + w_k K(x) with the exact tangent
// (the derivative of the forces) or the projected one as asked, an exact A that is not positive definite (a buckling spring, a
// collapsing cell) with the projected one instead, and factorises it.
//
// Handing over and collecting are lock-free and allocation-free on the servo thread: the
// snapshot's storage is sized by `reserve`, and one atomic state word (release on one side,
// acquire on the other) orders the job's data; the worker sleeps on that word (a futex:
// std::atomic::wait). `wait` blocks the calling thread until the job has finished: a caller
// that must adopt a factor at a given sample (a deterministic run) uses it; one that only
// polls `finished` never blocks.

#include "realtime/springs/cell_stiffness.hpp"
#include "realtime/springs/network_system.hpp"
#include "realtime/springs/spring_network.hpp"

#include <Eigen/Core>

#include <atomic>
#include <thread>

namespace kerf {

class FactorRefresh {
public:
  /// What a finished job did.
  struct Result {
    bool factorised = false;                     ///< A positive definite with one of the tangents
    CellTangent tangent = CellTangent::projected; ///< the tangent of the factor
    long tag = 0;                                ///< the caller's tag given to `start`
  };

  /// Starts the worker thread (it sleeps until a job comes).
  FactorRefresh();
  /// Waits for a running job, then stops and joins the worker.
  ~FactorRefresh();
  FactorRefresh(const FactorRefresh&) = delete;
  FactorRefresh& operator=(const FactorRefresh&) = delete;

  /// Sizes the snapshot for `net` (allocates). Only while idle (no job started and not collected).
  void reserve(const SpringNetwork& net);

  /// Servo thread: starts a job on `system` (which the caller leaves alone until `collect`) at
  /// positions `x` of `net`, A = mass_weight M + stiffness_weight K(x) with K of `tangent` (the
  /// exact one falls back to the projected one where A is not positive definite); `tag` is handed
  /// back in the result. `reanalyse`: the worker first rebuilds `system` for the snapshot's
  /// network with decoupled shadows (NetworkSystem::SplitRoom), so that its factor is the torn
  /// network's own size. False (nothing started) while a job is running or not yet collected.
  /// Allocation-free and lock-free (one release store and a futex wake).
  bool start(NetworkSystem& system, const SpringNetwork& net, const Eigen::Matrix3Xd& x, double mass_weight,
             double stiffness_weight, long tag, CellTangent tangent = CellTangent::exact, bool reanalyse = false) noexcept;
  /// A job was started and not yet collected.
  [[nodiscard]] bool busy() const noexcept { return m_state.load(std::memory_order_acquire) != idle; }
  /// The started job has finished (acquire: its results are visible to the caller).
  [[nodiscard]] bool finished() const noexcept { return m_state.load(std::memory_order_acquire) == done; }
  /// Blocks until the started job has finished (returns at once if none is running).
  void wait() const noexcept;
  /// After `finished`: the job's result; the refresh is idle again.
  Result collect() noexcept;
  /// The positions the last started job was assembled at (its snapshot of `x`, node_count
  /// columns of the snapshot's network); read it after `collect`, before the next `start`.
  [[nodiscard]] const Eigen::Matrix3Xd& positions() const noexcept { return m_x; }

private:
  enum State : int { idle = 0, requested = 1, done = 2, stopping = 3 };
  void work();

  std::atomic<int> m_state{idle};
  // The job (written by the servo before the release store of `requested`, read by the worker).
  NetworkSystem* m_system = nullptr;
  SpringNetwork m_net;   ///< snapshot: cell corners, rest positions, masses, constraints, node count
  Eigen::Matrix3Xd m_x;  ///< snapshot: positions
  double m_mass_weight = 0.0, m_stiffness_weight = 0.0;
  CellTangent m_tangent = CellTangent::exact;
  bool m_reanalyse = false;
  Result m_result;       ///< written by the worker before the release store of `done`
  std::thread m_thread;
};

} // namespace kerf
