#include "reference/load_path.hpp"

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <utility>

namespace kerf::reference {

LoadState interpolate(const LoadState& a, const LoadState& b, double f) {
  LoadState out;
  out.load_factor = a.load_factor + f * (b.load_factor - a.load_factor);
  out.tool_position = a.tool_position + f * (b.tool_position - a.tool_position);
  out.time = a.time + f * (b.time - a.time);
  return out;
}

LoadPath::LoadPath(FiniteStrainSolver& solver, const LoadState& start, const LoadPathSettings& settings, LoadMotion motion)
    : m_solver(solver), m_settings(settings), m_motion(std::move(motion)), m_last(start), m_state(solver.state()) {
  if (settings.max_cutbacks < 0)
    throw std::invalid_argument("load path: max_cutbacks must be >= 0, got " + std::to_string(settings.max_cutbacks));
  if (!(settings.interface_error_relative >= 0.0) || !(settings.interface_error_absolute >= 0.0) ||
      !std::isfinite(settings.interface_error_relative) || !std::isfinite(settings.interface_error_absolute))
    throw std::invalid_argument("load path: the interface energy tolerances must be finite and >= 0, got " +
                                std::to_string(settings.interface_error_relative) + " and " +
                                std::to_string(settings.interface_error_absolute) + " J");
}

namespace {

std::string format_load(const LoadState& l) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "load factor %.6g, tool at (%.6g, %.6g, %.6g) mm", l.load_factor,
                l.tool_position.x() * 1e3, l.tool_position.y() * 1e3, l.tool_position.z() * 1e3);
  return buf;
}

} // namespace

LoadStepReport LoadPath::advance(const LoadTarget& target) {
  const auto begin = std::chrono::steady_clock::now();
  LoadStepReport out;
  out.sample = target.sample;
  out.time = target.time;
  // Bisection from the last converged load: `done` is the fraction of the interval reached,
  // `step` the increment currently trusted (halved on each failure, kept after a success).
  const LoadState from = m_last;
  const bool control = m_settings.interface_error_relative > 0.0 || m_settings.interface_error_absolute > 0.0;
  const double span = target.load.time - from.time;
  double done = 0.0, step = 1.0;
  if (control && m_interface_step > 0.0 && span > 0.0) step = std::min(1.0, m_interface_step / span);
  while (done < 1.0) {
    const double f = std::min(1.0, done + step);
    const LoadState trial = f >= 1.0 ? target.load : between(from, target.load, f);
    const EquilibriumReport r = m_solver.solve(trial);
    out.newton_iterations += r.newton_iterations;
    bool grow = false;
    if (r.converged && control) {
      // |e| <= relative × ΔD + absolute, else undo the increment and halve it (LoadPathSettings).
      const double error = std::abs(r.cohesive.step_time_integration_error);
      const double tolerance =
          m_settings.interface_error_relative * r.cohesive.step_dissipation + m_settings.interface_error_absolute;
      if (error > tolerance) {
        if (out.cutbacks < m_settings.max_cutbacks) {
          m_solver.set_state(m_state);
          ++out.cutbacks;
          ++out.interface_rejections;
          step *= 0.5;
          continue;
        }
        out.interface_tolerance_exceeded = true;
      }
      // e ∝ h² relative to ΔD: doubling the step quadruples it (LoadPathSettings).
      grow = 4.0 * error <= tolerance && out.cutbacks == out.interface_rejections;
    }
    if (r.converged) {
      out.interface_error += r.cohesive.step_time_integration_error;
      done = f;
      m_last = trial;
      m_state = m_solver.state();
      ++out.increments;
      out.equilibrium = r;
      if (grow) step = std::min(1.0, 2.0 * step);
      continue;
    }
    if (out.cutbacks >= m_settings.max_cutbacks) {
      m_solver.set_state(m_state); // the solver restores it on failure; make it explicit
      std::string history;
      for (double h : r.residual_history) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%s%.3e", history.empty() ? "" : ", ", h);
        history += buf;
      }
      char head[160];
      std::snprintf(head, sizeof head, "load path: sample %zu (t = %.6g s) did not converge after %d cut-backs",
                    target.sample, target.time, out.cutbacks);
      throw LoadPathError(std::string(head) + "; last attempt (" + format_load(trial) + "): " + r.failure +
                              "; residual history of the last attempt [N]: " + history +
                              "; the last converged state (" + format_load(m_last) + ") is saved",
                          target.sample, target.time);
    }
    ++out.cutbacks;
    step *= 0.5;
  }
  if (control) m_interface_step = step >= 1.0 || !(span > 0.0) ? 0.0 : step * span;
  out.converged = true;
  out.tool_force = out.equilibrium.tool_force;
  out.support_reaction = out.equilibrium.support_reaction;
  out.final_residual = out.equilibrium.residual_history.empty() ? 0.0 : out.equilibrium.residual_history.back();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return out;
}

LoadState LoadPath::between(const LoadState& from, const LoadState& to, double f) const {
  if (!m_motion) return interpolate(from, to, f);
  return m_motion(from.time + f * (to.time - from.time));
}

std::vector<LoadStepReport> LoadPath::run(const std::vector<LoadTarget>& targets) {
  std::vector<LoadStepReport> out;
  out.reserve(targets.size());
  for (const LoadTarget& t : targets) out.push_back(advance(t));
  return out;
}

} // namespace kerf::reference
