#include "realtime/springs/newton_stepper.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kerf {

namespace {
/// Anderson mixing keeps at most this many differences (the workspace's width).
constexpr int max_anderson_depth = 8;
/// Armijo's sufficient-decrease constant (Nocedal & Wright, Numerical Optimization, §3.1).
constexpr double armijo = 1e-4;
} // namespace

NewtonStepper::NewtonStepper(const SpringNetwork& net, Mode mode, int max_iterations, double relative_tolerance,
                             bool tear_ready, FactorRefreshPolicy policy)
    : m_mode(mode), m_max_iterations(max_iterations), m_policy(policy), m_tolerance_ratio(relative_tolerance),
      m_tear_ready(tear_ready) {
  if (max_iterations < 1) throw std::invalid_argument("NewtonStepper: max_iterations must be >= 1");
  if (!(relative_tolerance > 0.0)) throw std::invalid_argument("NewtonStepper: the relative tolerance must be > 0");
  if (policy.anderson_depth < 0 || policy.anderson_depth > max_anderson_depth)
    throw std::invalid_argument("NewtonStepper: the Anderson depth must be in [0, 8]");
  // Backward Euler's A = M/h² + … is well conditioned (the mass term), so its kept factor is
  // read in single precision; the quasi-static K (regularised by 10⁻⁸ M only) is not.
  const auto precision = mode != Mode::quasi_static ? NetworkSystem::SolvePrecision::single_precision
                                                    : NetworkSystem::SolvePrecision::double_precision;
  for (auto& s : m_systems) s = std::make_unique<NetworkSystem>(precision);
  if (mode == Mode::implicit_euler) m_refresh = std::make_unique<FactorRefresh>();
  rebuild(net);
}

void NewtonStepper::rebuild(const SpringNetwork& net) {
  if (m_refresh) {
    m_refresh->wait();
    if (m_refresh->busy()) m_refresh->collect(); // drop it: the pattern changes
  }
  // Room for splits only on an untorn network (one still on its lattice); a rebuild after a
  // split that did not fit is plain. Both systems get the same (deterministic) analysis.
  const bool tear_ready = m_tear_ready && LatticeForces(net).applies(net);
  for (auto& s : m_systems) s->rebuild(net, tear_ready ? split_room() : NetworkSystem::SplitRoom::none);
  m_active = 0;
  if (m_refresh) m_refresh->reserve(net);
  for (FactorState* f : {&m_kept, &m_fresh}) {
    f->correction.reserve(active().dof_count());
    f->x.setZero(3, net.node_capacity());
    f->dt = -1.0;
    f->uncorrected = false;
  }
  m_taking_up = false;
  m_forces = LatticeForces(net);
  const int cap = net.node_capacity();
  m_x0.setZero(3, cap);
  m_v0.setZero(3, cap);
  m_f.setZero(3, cap);
  m_zero.setZero(3, cap);
  m_x_before.setZero(3, cap);
  m_free_entry.assign(3 * static_cast<std::size_t>(cap), 0);
  m_free_dof.assign(3 * static_cast<std::size_t>(cap), 0);
  m_free_mass.assign(3 * static_cast<std::size_t>(cap), 0.0);
  m_free_lattice.assign(3 * static_cast<std::size_t>(cap), 0);
  m_r.setZero(active().dof_count());
  m_dx.setZero(active().dof_count());
  for (Eigen::VectorXd* w : {&m_u, &m_g, &m_u_previous, &m_g_previous, &m_u_next}) w->setZero(3 * cap);
  m_du.setZero(3 * cap, std::max(m_policy.anderson_depth, 1));
  m_dg.setZero(3 * cap, std::max(m_policy.anderson_depth, 1));
  bind_free_entries(net);
  m_splits = 0;
  // Quasi-static regulariser: 1e-8 of the stiffness-to-mass scale k₁ / (cell mass / 8).
  m_static_regularisation = 1e-8 * net.stiffness.edge / (net.cell_mass / 8.0);
}

NetworkSystem::SplitRoom NewtonStepper::split_room() const {
  // Implicit Euler never assembles after a split on the servo thread (the worker re-analyses the
  // torn network for each refresh), so its shadows stay out of the factor; the other modes
  // refactorise the torn network on the calling thread, into the pattern's room.
  return m_mode == Mode::implicit_euler ? NetworkSystem::SplitRoom::decoupled_shadows : NetworkSystem::SplitRoom::coupled_shadows;
}

double NewtonStepper::mass_weight(double dt) const { return m_mode == Mode::quasi_static ? m_static_regularisation : 1.0 / (dt * dt); }

double NewtonStepper::stiffness_weight(const SpringNetwork& net, double dt) const {
  return m_mode == Mode::quasi_static ? 1.0 : 1.0 + net.damping_time / dt;
}

bool NewtonStepper::refactor(const SpringNetwork& net, const Eigen::Matrix3Xd& x, double dt) noexcept {
  const double wm = mass_weight(dt), wk = stiffness_weight(net, dt);
  CellTangent tangent = m_tear_ready ? CellTangent::projected : CellTangent::exact;
  active().assemble(net, x, wm, wk, tangent);
  bool ok = active().factorize();
  if (!ok && tangent == CellTangent::exact) {
    tangent = CellTangent::projected;
    active().assemble(net, x, wm, wk, tangent);
    ok = active().factorize();
  }
  if (!ok) return false;
  m_kept.x.leftCols(net.node_count) = x.leftCols(net.node_count);
  m_kept.dt = dt;
  m_kept.tangent = tangent;
  m_kept.mass_weight = wm;
  m_kept.stiffness_weight = wk;
  m_kept.correction.clear();
  m_kept.uncorrected = false;
  m_taking_up = false; // a collected factor is older than this one
  return true;
}

bool NewtonStepper::prime(const SpringNetwork& net, const Eigen::Matrix3Xd& x, double dt) noexcept {
  if (m_refresh) {
    m_refresh->wait();
    if (m_refresh->busy()) m_refresh->collect();
  }
  return refactor(net, x, dt);
}

bool NewtonStepper::retopologise(const SpringNetwork& net, const Eigen::Matrix3Xd& x) noexcept {
  const int first_copy = active().bound_nodes();
  if (!active().bind_split_vertices(net)) return false;
  bind_free_entries(net);
  if (m_mode != Mode::implicit_euler) {
    m_kept.dt = -1.0; // refactorised at the next advance
    return true;
  }
  // The kept factor is of the matrix before these splits: correct it for each (the copy has
  // its original's rest position; their masses add up to the original's before the split).
  for (int copy = first_copy; copy < net.node_count; ++copy) {
    int original = -1;
    for (int p = 0; p < first_copy && original < 0; ++p)
      if (net.rest.col(p) == net.rest.col(copy)) original = p;
    if (original >= 0) {
      m_kept.x.col(copy) = m_kept.x.col(original);
      if (m_taking_up) m_fresh.x.col(copy) = m_fresh.x.col(original);
    }
    const long index = ++m_splits;
    RecordedSplit& r = m_recent[static_cast<std::size_t>(index % SplitCorrection::max_splits)];
    r = RecordedSplit{index, original, copy,
                      original >= 0 ? net.mass[static_cast<std::size_t>(original)] + net.mass[static_cast<std::size_t>(copy)] : 0.0};
    // Full (or H singular): the kept factor stays uncorrected for this split until a refresh;
    // Newton then converges more slowly (and says so when it does not).
    if (!correct_for_split(net, index, active(), m_kept)) m_kept.uncorrected = true;
  }
  // A fresh factor of the torn network (if none is being computed or taken up: that one is
  // corrected for this split when taken up).
  if (m_kept.dt > 0.0) request_refresh(net, x, m_kept.dt);
  return true;
}

bool NewtonStepper::correct_for_split(const SpringNetwork& net, long index, NetworkSystem& system, FactorState& factor) noexcept {
  const RecordedSplit& r = m_recent[static_cast<std::size_t>(index % SplitCorrection::max_splits)];
  if (r.index != index || r.original < 0 || factor.dt < 0.0) return false;
  // The splits made after this one (when corrected for after them): their copies' corners are
  // taken back at their originals.
  SplitCorrection::NodePair later[SplitCorrection::max_splits];
  int later_count = 0;
  for (long k = index + 1; k <= m_splits && later_count < SplitCorrection::max_splits; ++k) {
    const RecordedSplit& l = m_recent[static_cast<std::size_t>(k % SplitCorrection::max_splits)];
    if (l.index == k) later[later_count++] = {l.copy, l.original};
  }
  // The moved cells' stiffness where the kept matrix has the rest of the network's: taken at
  // the positions now, the correction would remove from the original's rows a stiffness the
  // kept matrix does not hold and leave a matrix of no one state (on clay_tear's pull, a
  // factor adopted with ten splits to correct then stepped 1.2-6 times too far, 10-75 degrees
  // off the torn network's own step, for the 16 samples until the next).
  return factor.correction.add(system, net, factor.x, r.original, r.copy, r.mass_before, factor.mass_weight, factor.stiffness_weight,
                               factor.tangent, later, later_count);
}

void NewtonStepper::request_refresh(const SpringNetwork& net, const Eigen::Matrix3Xd& x, double dt) noexcept {
  // (The worker's system holds the collected factor while it is taken up.)
  if (!m_refresh || m_refresh->busy() || m_taking_up) return;
  const double wm = mass_weight(dt), wk = stiffness_weight(net, dt);
  // With decoupled shadows the worker analyses the network as it is now (torn or not) first.
  const bool reanalyse = active().split_room() == NetworkSystem::SplitRoom::decoupled_shadows;
  if (m_refresh->start(*m_systems[static_cast<std::size_t>(1 - m_active)], net, x, wm, wk, m_splits,
                       m_tear_ready ? CellTangent::projected : CellTangent::exact, reanalyse)) {
    m_job_call = m_calls;
    m_job_dt = dt;
    m_job_mass_weight = wm;
    m_job_stiffness_weight = wk;
  }
}

void NewtonStepper::collect_refresh(const SpringNetwork& net, NewtonReport& report) noexcept {
  if (m_taking_up) return; // it goes on at the start of the call (advance_implicit)
  if (!m_refresh || !m_refresh->busy()) return;
  if (m_policy.delay >= 0) {
    if (m_calls < m_job_call + m_policy.delay) return;
    m_refresh->wait(); // deterministic: this call collects it, however long the worker took
  } else if (!m_refresh->finished()) {
    return;
  }
  const FactorRefresh::Result result = m_refresh->collect();
  if (!result.factorised) return;
  m_fresh.dt = m_job_dt;
  m_fresh.tangent = result.tangent;
  m_fresh.mass_weight = m_job_mass_weight;
  m_fresh.stiffness_weight = m_job_stiffness_weight;
  m_fresh.correction.clear();
  m_fresh.uncorrected = false;
  // The snapshot's positions, with the copies made since at their originals' places.
  m_fresh.x.leftCols(net.node_count) = m_refresh->positions().leftCols(net.node_count);
  for (long index = result.tag + 1; index <= m_splits; ++index)
    if (const RecordedSplit& r = m_recent[static_cast<std::size_t>(index % SplitCorrection::max_splits)]; r.index == index && r.original >= 0)
      m_fresh.x.col(r.copy) = m_fresh.x.col(r.original);
  m_fresh_next = result.tag + 1;
  m_taking_up = true;
  take_up(net, report);
}

void NewtonStepper::take_up(const SpringNetwork& net, NewtonReport& report) noexcept {
  NetworkSystem& fresh = *m_systems[static_cast<std::size_t>(1 - m_active)];
  // Splits made since its snapshot (or since the last call): bound, then corrected for, a few
  // per call.
  if (m_fresh_next <= m_splits && fresh.bound_nodes() < net.node_count && !fresh.bind_split_vertices(net)) m_fresh.uncorrected = true;
  const long last = m_policy.corrections_per_call > 0 ? std::min(m_splits, m_fresh_next + m_policy.corrections_per_call - 1) : m_splits;
  for (; m_fresh_next <= last; ++m_fresh_next, ++report.take_up_corrections)
    if (!correct_for_split(net, m_fresh_next, fresh, m_fresh)) m_fresh.uncorrected = true;
  if (m_fresh_next <= m_splits) return; // the kept factor (corrected for them all) serves meanwhile
  m_taking_up = false;
  m_active = 1 - m_active;
  std::swap(m_kept, m_fresh); // (the matrices and vectors swap their storage: allocation-free)
  ++report.refreshes;
  if (active().split_room() == NetworkSystem::SplitRoom::decoupled_shadows) {
    // Re-analysed: its own numbering of the dofs. The right-hand side's unused entries (the
    // decoupled shadows') must be zero.
    bind_free_entries(net);
    m_r.setZero();
  }
}

void NewtonStepper::bind_free_entries(const SpringNetwork& net) noexcept {
  // Sized for every entry of the capacity (3 x capacity) at rebuild: binding after a split
  // only rewrites them.
  const auto& dof = active().dof_of();
  const bool lattice = m_forces.applies(net);
  m_free_count = 0;
  for (int p = 0; p < net.node_count; ++p)
    for (int i = 0; i < 3; ++i)
      if (const int d = dof[static_cast<std::size_t>(3 * p + i)]; d >= 0) {
        const auto k = static_cast<std::size_t>(m_free_count++);
        m_free_entry[k] = 3 * p + i;
        m_free_dof[k] = d;
        m_free_mass[k] = net.mass[static_cast<std::size_t>(p)];
        m_free_lattice[k] = lattice ? m_forces.lattice_entry(p, i) : -1;
      }
}

void NewtonStepper::write_free(const Eigen::VectorXd& u, Eigen::Matrix3Xd& x) const noexcept {
  double* X = x.data();
  for (int k = 0; k < m_free_count; ++k) X[m_free_entry[static_cast<std::size_t>(k)]] = u[k];
}

double NewtonStepper::residual(const SpringNetwork& net, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double dt,
                               LatticeForces::ForcePrecision precision) noexcept {
  // Over the free entries only (entry e = 3 p + i of the 3 x capacity arrays, dof d, mass m).
  const bool implicit = m_mode != Mode::quasi_static;
  const double* X = x.data();
  const double* X0 = m_x0.data();
  const double* V0 = m_v0.data();
  double* V = v.data();
  // Products with 1/h and 1/h² instead of two divisions per entry (a scalar division is about
  // as costly as the rest of the entry's work).
  const double inverse_dt = 1.0 / dt, inverse_dt2 = inverse_dt * inverse_dt;
  if (implicit)
    for (int k = 0; k < m_free_count; ++k) {
      const int e = m_free_entry[static_cast<std::size_t>(k)];
      V[e] = (X[e] - X0[e]) * inverse_dt;
    }
  else
    for (int k = 0; k < m_free_count; ++k) V[m_free_entry[static_cast<std::size_t>(k)]] = 0.0;
  // Quasi-static equilibrium has no damping: forces at zero velocity.
  const double energy = m_forces.evaluate(net, x, implicit ? v : m_zero, m_f, precision);
  const double* F = m_f.data();
  double norm = 0.0, inertia = 0.0;
  for (int k = 0; k < m_free_count; ++k) {
    const int e = m_free_entry[static_cast<std::size_t>(k)];
    // implicit: r = M (x − xₙ − h vₙ)/h² − f;  quasi-static: r = −f
    double r = -F[e];
    if (implicit) {
      const double m = m_free_mass[static_cast<std::size_t>(k)], d = X[e] - X0[e] - dt * V0[e];
      r += m * d * inverse_dt2;
      inertia += 0.5 * m * d * d * inverse_dt2;
    }
    m_r[m_free_dof[static_cast<std::size_t>(k)]] = r;
    norm = std::max(norm, std::abs(r));
  }
  // The step's incremental potential, ½ |x − xₙ − h vₙ|²_M / h² + W(x), whose gradient is the
  // residual without the damping forces: the line search's second criterion.
  m_potential = energy + inertia;
  return norm;
}

NewtonReport NewtonStepper::advance(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double dt) noexcept {
  ++m_calls;
  switch (m_mode) {
  case Mode::quasi_static: return advance_static(net, x, v, dt);
  case Mode::linearly_implicit_euler:
    return m_forces.applies(net) ? advance_linearised_on_lattice(net, x, v, dt) : advance_linearised(net, x, v, dt);
  case Mode::implicit_euler: break;
  }
  return advance_implicit(net, x, v, dt);
}

NewtonReport NewtonStepper::advance_linearised_on_lattice(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v,
                                                          double dt) noexcept {
  NewtonReport report;
  double* X = x.data();
  double* V = v.data();
  double* X0 = m_x0.data();
  double* V0 = m_v0.data();
  const int* entry = m_free_entry.data();
  const int* dof = m_free_dof.data();
  const int* lattice = m_free_lattice.data();
  // The predictor x* = xₙ + h vₙ on the free entries (xₙ, vₙ kept for the check's residual).
  for (int k = 0; k < m_free_count; ++k) {
    const int e = entry[k];
    X0[e] = X[e];
    V0[e] = V[e];
    X[e] += dt * V[e];
  }
  // Never primed, a new dt, or a check found the kept factor stale: a fresh one at this
  // predictor, on this thread (the linearised step has no iteration to bridge a stale factor).
  if (m_kept.dt != dt || m_refresh_pending) {
    if (!refactor(net, x, dt)) {
      report.residual = residual(net, x, v, dt); // leaves forces() at the returned state
      return report;
    }
    ++report.factorisations;
    m_refresh_pending = false;
  }
  // r(x*) = M (x* − xₙ − h vₙ)/h² − f(x*, v*) = −f(x*, vₙ): v* = (x* − xₙ)/h = vₙ on the free
  // entries (the fixed ones hold their prescribed velocities), and the inertia term vanishes.
  // The forces in single precision on the lattice, straight into the solve's vector.
  m_forces.evaluate_on_lattice(net, x, v);
  const float* F = m_forces.single_forces();
  float* b = active().single_precision_vector();
  float largest = 0.0f;
  for (int k = 0; k < m_free_count; ++k) {
    const float f = F[lattice[k]];
    b[dof[k]] = f;
    largest = std::max(largest, std::abs(f));
  }
  const double norm = largest;
  // A y = f(x*) = −r(x*):  x = x* + y,  v = (x − xₙ)/h = vₙ + y/h.
  active().solve_in_place();
  const double inverse_dt = 1.0 / dt;
  bool finite = true;
  for (int k = 0; k < m_free_count; ++k) {
    const int e = entry[k];
    const double y = b[dof[k]];
    X[e] += y;
    V[e] += y * inverse_dt;
    finite = finite && std::isfinite(X[e]) && std::isfinite(V[e]);
  }
  report.iterations = 1;
  report.residual = norm;
  if (++m_calls_since_check >= linearised_check_interval) {
    m_calls_since_check = 0;
    report.residual = residual(net, x, v, dt); // also sets v = (x − xₙ)/h
    m_refresh_pending = report.residual > m_tolerance_ratio * net.stiffness.edge * net.block.cell_size && report.residual > 0.25 * norm;
  }
  report.converged = finite;
  return report;
}

NewtonReport NewtonStepper::advance_linearised(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v,
                                               double dt) noexcept {
  NewtonReport report;
  const int n = net.node_count;
  m_x0.leftCols(n) = x.leftCols(n);
  m_v0.leftCols(n) = v.leftCols(n);
  for (int k = 0; k < m_free_count; ++k) {
    const int e = m_free_entry[static_cast<std::size_t>(k)];
    x.data()[e] += dt * v.data()[e];
  }
  if (m_kept.dt != dt || m_refresh_pending) {
    if (!refactor(net, x, dt)) {
      report.residual = residual(net, x, v, dt);
      return report;
    }
    ++report.factorisations;
    m_refresh_pending = false;
  }
  const double tolerance = m_tolerance_ratio * net.stiffness.edge * net.block.cell_size;
  const double norm = residual(net, x, v, dt, LatticeForces::ForcePrecision::single_precision);
  // x = x* − A⁻¹ r(x*), v = (x − xₙ)/h: one linear solve.
  active().solve(m_r, m_dx);
  for (int k = 0; k < m_free_count; ++k) {
    const int e = m_free_entry[static_cast<std::size_t>(k)];
    x.data()[e] -= m_dx[m_free_dof[static_cast<std::size_t>(k)]];
  }
  report.iterations = 1;
  report.residual = norm;
  if (++m_calls_since_check >= linearised_check_interval) {
    m_calls_since_check = 0;
    report.residual = residual(net, x, v, dt); // also sets v
    m_refresh_pending = report.residual > tolerance && report.residual > 0.25 * norm;
  } else {
    for (int k = 0; k < m_free_count; ++k) {
      const int e = m_free_entry[static_cast<std::size_t>(k)];
      v.data()[e] = (x.data()[e] - m_x0.data()[e]) * (1.0 / dt);
    }
  }
  report.converged = x.leftCols(n).allFinite();
  return report;
}

// Anderson mixing (Walker & Ni, "Anderson acceleration for fixed-point iterations", SIAM J.
// Numer. Anal. 49(4), 2011): with the differences ΔU, ΔG of the last iterates and steps,
//   γ = argmin |g − ΔG γ|₂,   u ← u + g − (ΔU + ΔG) γ,
// the kept-factor iteration's GMRES-like acceleration (its error contracts by the kept
// factor's mismatch per step otherwise).
bool NewtonStepper::anderson_mix(AndersonState& state) noexcept {
  const int m = m_free_count;
  const int depth = m_policy.anderson_depth;
  m_u_next.head(m) = m_u.head(m) + m_g.head(m);
  bool mixed = false;
  if (depth > 0 && state.have_previous) {
    m_du.col(state.slot).head(m) = m_u.head(m) - m_u_previous.head(m);
    m_dg.col(state.slot).head(m) = m_g.head(m) - m_g_previous.head(m);
    state.slot = (state.slot + 1) % depth;
    state.history = std::min(state.history + 1, depth);
    const int history = state.history;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, max_anderson_depth, max_anderson_depth> gram(history, history);
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, max_anderson_depth, 1> rhs(history);
    for (int i = 0; i < history; ++i) {
      rhs[i] = m_dg.col(i).head(m).dot(m_g.head(m));
      for (int j = 0; j <= i; ++j) gram(i, j) = gram(j, i) = m_dg.col(i).head(m).dot(m_dg.col(j).head(m));
    }
    // Tikhonov regularisation of the normal equations at 10⁻¹⁰ of their scale.
    gram.diagonal().array() += 1e-10 * gram.diagonal().maxCoeff() + 1e-300;
    const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, max_anderson_depth, 1> gamma = gram.ldlt().solve(rhs);
    if (gamma.allFinite()) {
      for (int i = 0; i < history; ++i) m_u_next.head(m) -= gamma[i] * (m_du.col(i).head(m) + m_dg.col(i).head(m));
      mixed = true;
    }
  }
  m_u_previous.head(m) = m_u.head(m);
  m_g_previous.head(m) = m_g.head(m);
  state.have_previous = true;
  return mixed;
}

bool NewtonStepper::keep_factor_for(const SpringNetwork& net, const Eigen::Matrix3Xd& x, double dt,
                                    NewtonReport& report) noexcept {
  // A split the correction could not take (more splits than it holds before a refresh came):
  // with coupled shadows the torn network is factorised here, the one factorisation a servo step
  // may make; with decoupled ones (which cannot be assembled torn without a new analysis) the
  // iteration goes on with the factor as corrected so far while a fresh one is computed.
  const bool refactor_here = m_kept.dt < 0.0 || (m_kept.uncorrected && active().split_room() != NetworkSystem::SplitRoom::decoupled_shadows);
  if (refactor_here) {
    // Never primed, or uncorrected splits on coupled shadows: factorise here.
    if (m_refresh) {
      m_refresh->wait();
      if (m_refresh->busy()) m_refresh->collect(); // its system is about to be reused
    }
    if (!refactor(net, x, dt)) return false;
    ++report.factorisations;
  } else if (m_kept.dt != dt || m_kept.correction.splits() > 0 || m_kept.uncorrected || m_taking_up) {
    // A new dt, or splits the kept factor is only corrected for: a fresh factor (if none is
    // being computed already).
    request_refresh(net, x, dt);
    collect_refresh(net, report);
  }
  return true;
}

// The iteration's steps share its state (the accepted iterate, the Anderson history, whether the
// iterate's potential is double precision), so the kept-factor step, the acceptance and the
// backtracking stay in one function.
NewtonReport NewtonStepper::advance_implicit(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v,
                                             double dt) noexcept {
  NewtonReport report;
  if (m_taking_up) take_up(net, report); // (once per call: its corrections' budget is per call)
  collect_refresh(net, report);
  const int n = net.node_count;
  const int m = m_free_count;
  m_x0.leftCols(n) = x.leftCols(n);
  m_v0.leftCols(n) = v.leftCols(n);
  // Warm start: the explicit predictor xₙ + h vₙ.
  for (int k = 0; k < m; ++k) {
    const int e = m_free_entry[static_cast<std::size_t>(k)];
    x.data()[e] += dt * v.data()[e];
  }
  if (!keep_factor_for(net, x, dt, report)) {
    report.residual = residual(net, x, v, dt); // leaves forces() at the returned state
    return report;
  }
  const double tolerance = m_tolerance_ratio * net.stiffness.edge * net.block.cell_size;
  // The predictor's residual only sets the first step (an approximate one already: the kept
  // factor, read in single precision), so its forces are evaluated in single precision; every
  // residual that decides convergence or a line-search step is double.
  double norm = residual(net, x, v, dt, LatticeForces::ForcePrecision::single_precision);
  // Off the lattice (after a tear) the forces are double precision whatever was asked.
  bool potential_is_double = !m_forces.applies(net);
  if (norm <= tolerance && !potential_is_double) { // converged already: decide in double
    norm = residual(net, x, v, dt);
    potential_is_double = true;
  }
  for (int k = 0; k < m; ++k) m_u[k] = x.data()[m_free_entry[static_cast<std::size_t>(k)]];
  AndersonState anderson;
  bool stepped = false; // a step of this call was accepted
  while (report.iterations < m_max_iterations && norm > tolerance) {
    // The kept-factor step g = −Q⁻¹ r (Q: the kept factor corrected for the pending splits).
    m_kept.correction.solve(active(), m_r, m_dx);
    ++report.iterations;
    double slope = 0.0; // r · g: the potential's directional derivative along g (without damping)
    for (int k = 0; k < m; ++k) {
      const double g = -m_dx[m_free_dof[static_cast<std::size_t>(k)]];
      m_g[k] = g;
      slope += m_r[m_free_dof[static_cast<std::size_t>(k)]] * g;
    }
    bool mixed = anderson_mix(anderson);
    double mixed_slope = slope;
    if (mixed) {
      mixed_slope = 0.0;
      for (int k = 0; k < m; ++k) mixed_slope += m_r[m_free_dof[static_cast<std::size_t>(k)]] * (m_u_next[k] - m_u[k]);
      // Mixing is a least-squares fit of the last steps, not a descent method: its step may climb
      // the potential (r · Δu ≥ 0) while it happens to lower the residual's max-norm, and a run of
      // such steps can stall the iteration (the blade held still at a cut's bottom did). Such a
      // step is replaced by the plain kept-factor step g, a descent direction (r · g = −r Q⁻¹ r
      // < 0 for a positive definite Q), and the mixing's history restarts.
      if (mixed_slope >= 0.0) {
        m_u_next.head(m) = m_u.head(m) + m_g.head(m);
        mixed = false;
        mixed_slope = slope;
        anderson = AndersonState{};
      }
    }
    const double potential = m_potential;
    // Accepted: a lower residual, or (from a double-precision potential) Armijo's decrease of
    // the potential along a descent direction (through a snap-through the residual may have to
    // rise on the way to the other branch's equilibrium).
    const auto accepted = [&](double trial, double alpha, double s) {
      return trial < norm || (potential_is_double && s < 0.0 && m_potential <= potential + armijo * alpha * s);
    };
    write_free(m_u_next, x);
    double trial = residual(net, x, v, dt);
    if (accepted(trial, 1.0, mixed_slope)) {
      norm = trial;
      potential_is_double = true;
      stepped = true;
      m_u.head(m) = m_u_next.head(m);
      continue;
    }
    // Backtracking along the plain step g (the mixing's history restarts).
    anderson = AndersonState{};
    bool found = false;
    for (double alpha = mixed ? 1.0 : 0.5; alpha >= 1.0 / 32.0; alpha *= 0.5) {
      m_u_next.head(m) = m_u.head(m) + alpha * m_g.head(m);
      write_free(m_u_next, x);
      trial = residual(net, x, v, dt);
      if (accepted(trial, alpha, slope)) {
        found = true;
        break;
      }
    }
    if (!found) {
      // No step length helps: back to the iterate; a fresh factor is asked for below.
      write_free(m_u, x);
      norm = residual(net, x, v, dt);
      if (potential_is_double) break;
      // The iterate's potential was single precision (the predictor's): now it is double, so
      // the step is tried again with Armijo's condition too.
      potential_is_double = true;
      continue;
    }
    norm = trial;
    potential_is_double = true;
    stepped = true;
    m_u.head(m) = m_u_next.head(m);
  }
  if (!stepped && norm > tolerance) {
    norm = hold(net, x, v, dt);
    report.held = true;
  }
  report.residual = norm;
  report.converged = norm <= tolerance;
  if (!report.converged || report.iterations > refresh_after_iterations) request_refresh(net, x, dt);
  return report;
}

double NewtonStepper::hold(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double dt) noexcept {
  // A call that accepted no step still holds the predictor xₙ + h vₙ, which carries the previous
  // velocity on unopposed, and a run of such calls is free flight (on potato_rect_cut's
  // withdrawal, a crushed 4³ network's nodes flew off at 1.3 m/s under a stale factor and the
  // blade's force grew to 10²⁰ N). Held instead: x = xₙ and v = 0 on the free entries.
  for (int k = 0; k < m_free_count; ++k) {
    const int e = m_free_entry[static_cast<std::size_t>(k)];
    x.data()[e] = m_x0.data()[e];
  }
  return residual(net, x, v, dt); // (v = (x − xₙ)/h = 0; the forces at the held state)
}

NewtonReport NewtonStepper::advance_static(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double dt) noexcept {
  NewtonReport report;
  const int n = net.node_count;
  m_x0.leftCols(n) = x.leftCols(n);
  m_v0.leftCols(n) = v.leftCols(n);
  // `fresh`: the kept factorisation was computed at the current iterate.
  bool fresh = false;
  if (m_kept.dt < 0.0) {
    if (!refactor(net, x, dt)) {
      report.residual = residual(net, x, v, dt); // leaves forces() at the returned state
      return report;
    }
    ++report.factorisations;
    fresh = true;
  }
  const double tolerance = m_tolerance_ratio * net.stiffness.edge * net.block.cell_size;
  double norm = residual(net, x, v, dt);
  double previous = INFINITY;
  int refreshes = 0;
  // Refreshes of the kept factorisation within one call: where even a fresh one converges
  // slowly, refreshing at every iteration only multiplies the cost.
  constexpr int max_refreshes = 1;
  while (report.iterations < m_max_iterations && norm > tolerance) {
    if (!fresh && norm > 0.25 * previous && refreshes < max_refreshes) {
      ++refreshes;
      if (!refactor(net, x, dt)) break;
      ++report.factorisations;
      fresh = true;
    }
    active().solve(m_r, m_dx);
    ++report.iterations;
    m_x_before.leftCols(n) = x.leftCols(n);
    // Backtracking: x ← x − α Δx with α = 1, 1/2, …, 1/32, the first that lowers the residual.
    double trial = INFINITY;
    double alpha = 1.0;
    for (int halving = 0; halving <= 5; ++halving, alpha *= 0.5) {
      for (int k = 0; k < m_free_count; ++k) {
        const int e = m_free_entry[static_cast<std::size_t>(k)];
        x.data()[e] = m_x_before.data()[e] - alpha * m_dx[m_free_dof[static_cast<std::size_t>(k)]];
      }
      trial = residual(net, x, v, dt);
      if (trial < norm) break;
    }
    if (!(trial < norm)) {
      // No step length helps: back to the iterate, and refresh the factorisation once if it is stale.
      x.leftCols(n) = m_x_before.leftCols(n);
      norm = residual(net, x, v, dt);
      if (fresh || refreshes >= max_refreshes) break;
      ++refreshes;
      if (!refactor(net, x, dt)) break;
      ++report.factorisations;
      fresh = true;
      previous = INFINITY;
      continue;
    }
    previous = norm;
    norm = trial;
    fresh = false;
  }
  report.residual = norm;
  report.converged = norm <= tolerance;
  return report;
}

} // namespace kerf
