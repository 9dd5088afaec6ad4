#include "realtime/edge/background_cut.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>

namespace kerf {

namespace {

/// How often the worker looks at the hand-over state [ms]: the servo thread never signals it.
constexpr auto poll_interval = std::chrono::milliseconds(1);

} // namespace

BackgroundCut::BackgroundCut(TetMesh mesh, BladeShape blade, GeometricCutOptions options, int capacity,
                             AfterCut after_cut)
    : m_original(std::move(mesh)), m_body(m_original), m_blade(blade), m_options(options),
      m_after_cut(std::move(after_cut)) {
  if (std::abs(m_blade.edge_direction.norm() - 1.0) > 1e-9) throw std::invalid_argument("background cut: edge direction must be a unit vector");
  if (!(m_blade.edge_length > 0.0) || !std::isfinite(m_blade.edge_length)) throw std::invalid_argument("background cut: edge length must be positive");
  if (capacity < 2) throw std::invalid_argument("background cut: the buffer must hold at least two positions");
  m_buffer.assign(static_cast<std::size_t>(capacity), Eigen::Vector3d::Zero());
  m_worker = std::thread([this] { work(); });
}

BackgroundCut::~BackgroundCut() {
  m_stop.store(true, std::memory_order_release);
  m_worker.join();
}

bool BackgroundCut::record(const Eigen::Vector3d& centre) noexcept {
  if (m_state.load(std::memory_order_acquire) != 0 || m_count >= static_cast<int>(m_buffer.size()) || !centre.allFinite()) {
    m_dropped.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  m_buffer[static_cast<std::size_t>(m_count++)] = centre;
  return true;
}

bool BackgroundCut::submit() noexcept {
  if (m_state.load(std::memory_order_acquire) != 0 || m_count < 2) return false;
  m_busy.store(true, std::memory_order_release);
  m_state.store(1, std::memory_order_release);
  return true;
}

int BackgroundCut::recorded() const noexcept { return m_state.load(std::memory_order_acquire) == 0 ? m_count : 0; }

const Eigen::Vector3d& BackgroundCut::last_recorded() const noexcept {
  return m_buffer[static_cast<std::size_t>(m_count > 0 ? m_count - 1 : 0)];
}

void BackgroundCut::work() {
  std::vector<Eigen::Vector3d> pass;
  while (!m_stop.load(std::memory_order_acquire)) {
    if (m_state.load(std::memory_order_acquire) != 1) {
      std::this_thread::sleep_for(poll_interval);
      continue;
    }
    pass.assign(m_buffer.begin(), m_buffer.begin() + m_count);
    m_count = 0;
    m_state.store(0, std::memory_order_release);
    try {
      // Paper 000 §3.2: "the trajectory surface is defined as a set of triangular patches".
      const SweptSurface surface = sweep_edge(pass, m_blade.edge_direction, m_blade.edge_length);
      const GeometricCutReport report = m_body.cut(surface, m_options);
      m_reports.push_back(report);
      if (m_after_cut) m_after_cut(m_body, report);
    } catch (const std::exception& e) {
      m_error = e.what();
    }
    m_cuts_done.fetch_add(1, std::memory_order_release);
    m_busy.store(false, std::memory_order_release);
  }
}

void BackgroundCut::wait_until_idle() const {
  while (m_busy.load(std::memory_order_acquire)) std::this_thread::sleep_for(poll_interval);
}

void BackgroundCut::reset() {
  wait_until_idle();
  m_body = CuttableBody(m_original);
  m_reports.clear();
  m_error.clear();
  m_count = 0;
  m_cuts_done.store(0, std::memory_order_release);
  m_dropped.store(0, std::memory_order_relaxed);
}

} // namespace kerf
