#include "experiments/calibration/nelder_mead.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <vector>

namespace kerf {

NelderMeadResult nelder_mead(const std::function<double(const Eigen::VectorXd&)>& f, const Eigen::VectorXd& x0,
                             const NelderMeadSettings& s) {
  const Eigen::Index n = x0.size();
  if (n == 0) throw std::invalid_argument("nelder_mead: no parameters to minimise over");
  if (!(s.initial_step > 0.0) || s.max_evaluations < 1 || !(s.step_tolerance > 0.0))
    throw std::invalid_argument("nelder_mead: initial_step, max_evaluations and step_tolerance must be > 0");

  NelderMeadResult out;
  auto value = [&](const Eigen::VectorXd& x) {
    ++out.evaluations;
    const double v = f(x);
    return std::isfinite(v) ? v : std::numeric_limits<double>::infinity();
  };
  // Lagarias et al. Eq. (2.1): ρ = 1, χ = 2, γ = 1/2, σ = 1/2.
  constexpr double rho = 1.0, chi = 2.0, gamma = 0.5, sigma = 0.5;

  std::vector<Eigen::VectorXd> x(static_cast<std::size_t>(n + 1), x0);
  std::vector<double> fx(x.size());
  for (Eigen::Index k = 0; k < n; ++k) x[static_cast<std::size_t>(k + 1)][k] += s.initial_step;
  for (std::size_t k = 0; k < x.size(); ++k) fx[k] = value(x[k]);
  std::vector<std::size_t> order(x.size());

  while (true) {
    // Order the vertices best first; ties keep the older vertex first (Lagarias et al. §2).
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return fx[a] < fx[b]; });
    const std::size_t best = order.front(), worst = order.back(), second = order[order.size() - 2];

    double spread = 0.0;
    for (std::size_t k = 0; k < x.size(); ++k) spread = std::max(spread, (x[k] - x[best]).lpNorm<Eigen::Infinity>());
    const bool flat = std::isfinite(fx[worst]) && fx[worst] - fx[best] <= s.value_tolerance;
    if (spread <= s.step_tolerance && flat) {
      out.converged = true;
      break;
    }
    if (spread <= s.step_tolerance * 1e-3) { // collapsed onto a plateau edge: nothing left to learn
      out.converged = true;
      break;
    }
    if (out.evaluations >= s.max_evaluations) break;

    // Centroid of all vertices but the worst.
    Eigen::VectorXd centroid = Eigen::VectorXd::Zero(n);
    for (std::size_t k = 0; k < x.size(); ++k)
      if (k != worst) centroid += x[k];
    centroid /= static_cast<double>(n);

    // Reflection: x_r = c + ρ (c − x_worst).
    const Eigen::VectorXd xr = centroid + rho * (centroid - x[worst]);
    const double fr = value(xr);
    if (fr < fx[best]) {
      // Expansion: x_e = c + χ (x_r − c).
      const Eigen::VectorXd xe = centroid + chi * (xr - centroid);
      const double fe = value(xe);
      if (fe < fr) {
        x[worst] = xe;
        fx[worst] = fe;
      } else {
        x[worst] = xr;
        fx[worst] = fr;
      }
      continue;
    }
    if (fr < fx[second]) {
      x[worst] = xr;
      fx[worst] = fr;
      continue;
    }
    // Contraction: outside x_c = c + γ (x_r − c) if f_r < f_worst, else inside x_cc = c − γ (c − x_worst).
    const bool outside = fr < fx[worst];
    const Eigen::VectorXd xc = outside ? Eigen::VectorXd(centroid + gamma * (xr - centroid))
                                       : Eigen::VectorXd(centroid - gamma * (centroid - x[worst]));
    const double fc = value(xc);
    if (outside ? fc <= fr : fc < fx[worst]) {
      x[worst] = xc;
      fx[worst] = fc;
      continue;
    }
    // Shrink towards the best: x_k = x_best + σ (x_k − x_best).
    for (std::size_t k = 0; k < x.size(); ++k) {
      if (k == best) continue;
      x[k] = x[best] + sigma * (x[k] - x[best]);
      fx[k] = value(x[k]);
    }
  }
  const auto best = static_cast<std::size_t>(std::min_element(fx.begin(), fx.end()) - fx.begin());
  out.x = x[best];
  out.value = fx[best];
  return out;
}

} // namespace kerf
