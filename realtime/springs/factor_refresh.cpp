#include "realtime/springs/factor_refresh.hpp"

#include <algorithm>
#include <exception>

namespace kerf {

FactorRefresh::FactorRefresh() : m_thread([this] { work(); }) {}

FactorRefresh::~FactorRefresh() {
  wait();
  m_state.store(stopping, std::memory_order_release);
  m_state.notify_all();
  m_thread.join();
}

void FactorRefresh::reserve(const SpringNetwork& net) {
  wait();
  m_net = net;
  m_x.setZero(3, net.node_capacity());
}

bool FactorRefresh::start(NetworkSystem& system, const SpringNetwork& net, const Eigen::Matrix3Xd& x, double mass_weight,
                          double stiffness_weight, long tag, CellTangent tangent, bool reanalyse) noexcept {
  if (m_state.load(std::memory_order_acquire) != idle) return false;
  if (net.node_capacity() != m_net.node_capacity() || net.cell_count() != m_net.cell_count()) return false; // not reserved
  // The snapshot: what assembling and binding read and a tear changes (sizes fixed at reserve).
  const int n = net.node_count;
  std::copy(net.cell_nodes.begin(), net.cell_nodes.end(), m_net.cell_nodes.begin());
  std::copy(net.mass.begin(), net.mass.begin() + n, m_net.mass.begin());
  std::copy(net.constraint.begin(), net.constraint.begin() + n, m_net.constraint.begin());
  m_net.rest.leftCols(n) = net.rest.leftCols(n);
  m_net.node_count = n;
  m_x.leftCols(n) = x.leftCols(n);
  m_system = &system;
  m_mass_weight = mass_weight;
  m_stiffness_weight = stiffness_weight;
  m_tangent = tangent;
  m_reanalyse = reanalyse;
  m_result = Result{false, CellTangent::projected, tag};
  m_state.store(requested, std::memory_order_release);
  m_state.notify_one();
  return true;
}

void FactorRefresh::wait() const noexcept {
  for (int s = m_state.load(std::memory_order_acquire); s == requested; s = m_state.load(std::memory_order_acquire))
    m_state.wait(s, std::memory_order_acquire);
}

FactorRefresh::Result FactorRefresh::collect() noexcept {
  const Result r = m_result;
  m_state.store(idle, std::memory_order_release);
  return r;
}

void FactorRefresh::work() {
  for (;;) {
    int s = m_state.load(std::memory_order_acquire);
    while (s != requested && s != stopping) {
      m_state.wait(s, std::memory_order_acquire);
      s = m_state.load(std::memory_order_acquire);
    }
    if (s == stopping) return;
    NetworkSystem& system = *m_system;
    // Re-analysed for the network as it is; or the splits since the system was last bound, where
    // a split the pattern cannot take is left to the servo (it rebuilds, which allocates), and
    // the job reports no factor.
    bool ok = true;
    if (m_reanalyse) {
      try {
        system.rebuild(m_net, NetworkSystem::SplitRoom::decoupled_shadows, false); // factorised below
      } catch (const std::exception&) {
        ok = false; // off the lattice or CHOLMOD out of memory: no factor this time
      }
    } else {
      ok = m_net.node_count == system.bound_nodes() || system.bind_split_vertices(m_net);
    }
    CellTangent tangent = m_tangent;
    if (ok) {
      system.assemble(m_net, m_x, m_mass_weight, m_stiffness_weight, tangent);
      ok = system.factorize();
      if (!ok && tangent == CellTangent::exact) {
        // Not positive definite with the exact tangent (the state is past a buckling point):
        // the projected one, positive definite by construction.
        tangent = CellTangent::projected;
        system.assemble(m_net, m_x, m_mass_weight, m_stiffness_weight, tangent);
        ok = system.factorize();
      }
    }
    m_result.factorised = ok;
    m_result.tangent = tangent;
    m_state.store(done, std::memory_order_release);
    m_state.notify_all();
  }
}

} // namespace kerf
