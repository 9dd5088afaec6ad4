#include "realtime/springs/newton_stepper.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kerf {

NewtonStepper::NewtonStepper(const SpringNetwork& net, Mode mode, int max_iterations, double relative_tolerance,
                             bool tear_ready)
    : m_mode(mode), m_max_iterations(max_iterations),
      // Backward Euler's A = M/h² + … is well conditioned (the mass term), so its kept factor is
      // read in single precision; the quasi-static K_T (regularised by 10⁻⁸ M only) is not.
      m_system(mode != Mode::quasi_static ? NetworkSystem::SolvePrecision::single_precision
                                          : NetworkSystem::SolvePrecision::double_precision),
      m_tolerance_ratio(relative_tolerance), m_tear_ready(tear_ready) {
  if (max_iterations < 1) throw std::invalid_argument("NewtonStepper: max_iterations must be >= 1");
  if (!(relative_tolerance > 0.0)) throw std::invalid_argument("NewtonStepper: the relative tolerance must be > 0");
  rebuild(net);
}

void NewtonStepper::rebuild(const SpringNetwork& net) {
  // Tear-ready only on an untorn network (one still on its lattice); a rebuild after a split
  // that did not fit is plain.
  m_system.rebuild(net, m_tear_ready && LatticeForces(net).applies(net));
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
  m_r.setZero(m_system.dof_count());
  m_dx.setZero(m_system.dof_count());
  bind_free_entries(net);
  m_factor_dt = -1.0;
  // Quasi-static regulariser: 1e-8 of the stiffness-to-mass scale k₁ / (cell mass / 8).
  m_static_regularisation = 1e-8 * net.stiffness.edge / (net.cell_mass / 8.0);
}

bool NewtonStepper::retopologise(const SpringNetwork& net) noexcept {
  if (!m_system.bind_split_vertices(net)) return false;
  bind_free_entries(net);
  m_factor_dt = -1.0;
  return true;
}

void NewtonStepper::bind_free_entries(const SpringNetwork& net) noexcept {
  // Sized for every entry of the capacity (3 x capacity) at rebuild: binding after a split
  // only rewrites them.
  const auto& dof = m_system.dof_of();
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

bool NewtonStepper::refactor(const SpringNetwork& net, const Eigen::Matrix3Xd& x, double dt) noexcept {
  if (m_mode != Mode::quasi_static)
    m_system.assemble(net, x, 1.0 / (dt * dt), 1.0 + net.damping_time / dt);
  else
    m_system.assemble(net, x, m_static_regularisation, 1.0);
  m_factor_dt = dt;
  return m_system.factorize();
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
  m_forces.evaluate(net, x, implicit ? v : m_zero, m_f, precision);
  const double* F = m_f.data();
  double norm = 0.0;
  for (int k = 0; k < m_free_count; ++k) {
    const int e = m_free_entry[static_cast<std::size_t>(k)];
    // implicit: r = M (x − xₙ − h vₙ)/h² − f;  quasi-static: r = −f
    double r = -F[e];
    if (implicit) r += m_free_mass[static_cast<std::size_t>(k)] * (X[e] - X0[e] - dt * V0[e]) * inverse_dt2;
    m_r[m_free_dof[static_cast<std::size_t>(k)]] = r;
    norm = std::max(norm, std::abs(r));
  }
  return norm;
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
  bool fresh = false;
  if (m_factor_dt != dt) {
    if (!refactor(net, x, dt)) {
      report.residual = residual(net, x, v, dt); // leaves forces() at the returned state
      return report;
    }
    ++report.factorisations;
    fresh = true;
  }
  // r(x*) = M (x* − xₙ − h vₙ)/h² − f(x*, v*) = −f(x*, vₙ): v* = (x* − xₙ)/h = vₙ on the free
  // entries (the fixed ones hold their prescribed velocities), and the inertia term vanishes.
  // The forces in single precision on the lattice, straight into the solve's vector.
  m_forces.evaluate_on_lattice(net, x, v);
  const float* F = m_forces.single_forces();
  float* b = m_system.single_precision_vector();
  float largest = 0.0f;
  for (int k = 0; k < m_free_count; ++k) {
    const float f = F[lattice[k]];
    b[dof[k]] = f;
    largest = std::max(largest, std::abs(f));
  }
  const double norm = largest;
  // A kept factorisation that a check found stale is refreshed at this predictor (see advance).
  if (m_refresh_pending && !fresh) {
    if (!refactor(net, x, dt)) {
      // A not positive definite at x*: no step this sample (the state stays at the predictor,
      // v = vₙ, reported unconverged), the refresh is tried again at the next.
      report.residual = norm;
      return report;
    }
    ++report.factorisations;
  }
  m_refresh_pending = false;
  // A y = f(x*) = −r(x*):  x = x* + y,  v = (x − xₙ)/h = vₙ + y/h.
  m_system.solve_in_place();
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

NewtonReport NewtonStepper::advance(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v,
                                    double dt) noexcept {
  if (m_mode == Mode::linearly_implicit_euler && m_forces.applies(net)) return advance_linearised_on_lattice(net, x, v, dt);
  NewtonReport report;
  const int n = net.node_count;
  m_x0.leftCols(n) = x.leftCols(n);
  m_v0.leftCols(n) = v.leftCols(n);
  const bool implicit = m_mode != Mode::quasi_static;
  // Warm start: the implicit step starts from the explicit predictor xₙ + h vₙ.
  if (implicit)
    for (int k = 0; k < m_free_count; ++k) {
      const int e = m_free_entry[static_cast<std::size_t>(k)];
      x.data()[e] += dt * v.data()[e];
    }
  // `fresh`: the kept factorisation was computed at the current iterate.
  bool fresh = false;
  if (implicit ? m_factor_dt != dt : m_factor_dt < 0.0) {
    if (!refactor(net, x, dt)) {
      report.residual = residual(net, x, v, dt); // leaves forces() at the returned state
      return report;
    }
    ++report.factorisations;
    fresh = true;
  }
  const double tolerance = m_tolerance_ratio * net.stiffness.edge * net.block.cell_size;
  // Backward Euler's predictor residual only sets the first Newton step (an approximate one
  // already: the kept factor, read in single precision), so its forces are evaluated in single
  // precision; every residual that decides convergence or a line-search step is double.
  double norm = residual(net, x, v, dt,
                         implicit ? LatticeForces::ForcePrecision::single_precision : LatticeForces::ForcePrecision::double_precision);
  if (m_mode == Mode::implicit_euler && norm <= tolerance) norm = residual(net, x, v, dt); // converged already: decide in double
  if (m_mode == Mode::linearly_implicit_euler) {
    // A kept factorisation that no longer approximates the Jacobian lets a mode grow from
    // sample to sample (the step's error (I − A_kept⁻¹ A) e is amplified). Every
    // `linearised_check_interval`-th call the residual after the step is evaluated too, and if
    // the step reduced it by less than 4 x (modified Newton's criterion) the factorisation is
    // refreshed at the next call's predictor.
    if (m_refresh_pending && !fresh) {
      if (!refactor(net, x, dt)) {
        // A not positive definite at x*: no step this sample (the state stays at the predictor,
        // reported unconverged), the refresh is tried again at the next.
        for (int k = 0; k < m_free_count; ++k) {
          const int e = m_free_entry[static_cast<std::size_t>(k)];
          v.data()[e] = (x.data()[e] - m_x0.data()[e]) * (1.0 / dt);
        }
        report.residual = norm;
        return report;
      }
      ++report.factorisations;
    }
    m_refresh_pending = false;
    // x = x* − A⁻¹ r(x*), v = (x − xₙ)/h: one linear solve.
    m_system.solve(m_r, m_dx);
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
  double previous = INFINITY;
  int refreshes = 0;
  while (report.iterations < m_max_iterations && norm > tolerance) {
    // The kept factorisation no longer converges fast: refresh it (at most `max_refreshes`
    // times per call: where even a fresh one converges slowly, as through a snap-through of
    // crushed cells, refreshing at every iteration only multiplies the cost).
    if (!fresh && norm > 0.25 * previous && refreshes < max_refreshes) {
      ++refreshes;
      if (!refactor(net, x, dt)) break;
      ++report.factorisations;
      fresh = true;
    }
    m_system.solve(m_r, m_dx);
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
