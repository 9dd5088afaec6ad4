#include "reference/load_path.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

namespace kerf::reference {

LoadState interpolate(const LoadState& a, const LoadState& b, double f) {
  LoadState out;
  out.load_factor = a.load_factor + f * (b.load_factor - a.load_factor);
  out.tool_position = a.tool_position + f * (b.tool_position - a.tool_position);
  out.time = a.time + f * (b.time - a.time);
  return out;
}

LoadPath::LoadPath(FiniteStrainSolver& solver, const LoadState& start, const LoadPathSettings& settings)
    : m_solver(solver), m_settings(settings), m_last(start), m_state(solver.state()) {
  if (settings.max_cutbacks < 0)
    throw std::invalid_argument("load path: max_cutbacks must be >= 0, got " + std::to_string(settings.max_cutbacks));
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
  double done = 0.0, step = 1.0;
  while (done < 1.0) {
    const double f = std::min(1.0, done + step);
    const LoadState trial = f >= 1.0 ? target.load : interpolate(from, target.load, f);
    const EquilibriumReport r = m_solver.solve(trial);
    out.newton_iterations += r.newton_iterations;
    if (r.converged) {
      done = f;
      m_last = trial;
      m_state = m_solver.state();
      ++out.increments;
      out.equilibrium = r;
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
  out.converged = true;
  out.tool_force = out.equilibrium.tool_force;
  out.support_reaction = out.equilibrium.support_reaction;
  out.final_residual = out.equilibrium.residual_history.empty() ? 0.0 : out.equilibrium.residual_history.back();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return out;
}

std::vector<LoadStepReport> LoadPath::run(const std::vector<LoadTarget>& targets) {
  std::vector<LoadStepReport> out;
  out.reserve(targets.size());
  for (const LoadTarget& t : targets) out.push_back(advance(t));
  return out;
}

} // namespace kerf::reference
