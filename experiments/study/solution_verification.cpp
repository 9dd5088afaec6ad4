#include "experiments/study/solution_verification.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace kerf {

GridConvergence grid_convergence(const GridTriplet& g, double safety_factor) {
  if (!(g.h1 > 0.0 && g.h2 > g.h1 && g.h3 > g.h2) || !std::isfinite(g.h3))
    throw std::invalid_argument("grid convergence: element sizes must satisfy 0 < h1 < h2 < h3 (finest first), got " +
                                std::to_string(g.h1) + ", " + std::to_string(g.h2) + ", " + std::to_string(g.h3));
  if (!std::isfinite(g.phi1) || !std::isfinite(g.phi2) || !std::isfinite(g.phi3))
    throw std::invalid_argument("grid convergence: a non-finite value of the quantity");
  GridConvergence out;
  out.grids = g;
  out.r21 = g.h2 / g.h1;
  out.r32 = g.h3 / g.h2;
  const double e21 = g.phi2 - g.phi1, e32 = g.phi3 - g.phi2;
  out.approximate_relative_error = g.phi1 != 0.0 ? std::abs(e21 / g.phi1) : 0.0;
  if (e21 == 0.0 || e32 == 0.0) {
    // Celik et al. 2008: "if either ε32 or ε21 is very close to zero, the above procedure does not work".
    out.unusable = e21 == 0.0 && e32 == 0.0 ? "the quantity is the same on all three meshes: no observed order"
                                            : "a difference between two meshes is zero (oscillation or the exact value reached): no observed order";
    return out;
  }
  const double s = e32 / e21 > 0.0 ? 1.0 : -1.0;
  out.oscillatory = s < 0.0;
  const double log_ratio = std::log(std::abs(e32 / e21)), log_r21 = std::log(out.r21);
  const auto q = [&](double p) { return std::log((std::pow(out.r21, p) - s) / (std::pow(out.r32, p) - s)); };
  // Fixed-point iteration p <- |ln|ε32/ε21| + q(p)| / ln r21 from q = 0.
  double p = std::abs(log_ratio) / log_r21;
  bool converged = false;
  for (out.iterations = 1; out.iterations <= 500; ++out.iterations) {
    if (!(p > 1e-12) || !std::isfinite(p)) break;
    const double next = std::abs(log_ratio + q(p)) / log_r21;
    const bool done = std::abs(next - p) <= 1e-14 * std::max(1.0, std::abs(p));
    p = next;
    if (done) {
      converged = true;
      break;
    }
  }
  char text[200];
  if (!converged || !(p > 1e-12) || !std::isfinite(p)) {
    std::snprintf(text, sizeof text, "no observed order: the fixed-point iteration for p did not converge (last p = %.3g)", p);
    out.unusable = text;
    return out;
  }
  if (log_ratio + q(p) < 0.0) {
    // The absolute value of Eq. 3a made a growing difference look like convergence.
    std::snprintf(text, sizeof text, "the differences grow under refinement (ε21 = %.3g, ε32 = %.3g): divergence, no observed order", e21, e32);
    out.unusable = text;
    return out;
  }
  out.observed_order = p;
  const double rp = std::pow(out.r21, p);
  out.extrapolated = (rp * g.phi1 - g.phi2) / (rp - 1.0);
  if (*out.extrapolated != 0.0) out.extrapolated_relative_error = std::abs((*out.extrapolated - g.phi1) / *out.extrapolated);
  if (g.phi1 == 0.0) {
    out.unusable = "the finest value is zero: no relative uncertainty";
    return out;
  }
  out.gci_fine = safety_factor * out.approximate_relative_error / (rp - 1.0);
  return out;
}

DifferenceConvergence difference_convergence(double h1, double h2, double h3, double e21, double e32, double formal_order,
                                             double safety_factor) {
  if (!(h1 > 0.0) || !(h2 > h1) || !(h3 > h2) || !std::isfinite(h3))
    throw std::invalid_argument("difference convergence: needs element sizes 0 < h1 < h2 < h3");
  if (!(e21 >= 0.0) || !(e32 >= 0.0) || !std::isfinite(e21) || !std::isfinite(e32))
    throw std::invalid_argument("difference convergence: needs finite difference norms >= 0");
  if (!(formal_order > 0.0) || !std::isfinite(formal_order))
    throw std::invalid_argument("difference convergence: needs a formal order > 0");
  DifferenceConvergence c;
  c.r21 = h2 / h1;
  c.r32 = h3 / h2;
  c.e21 = e21;
  c.e32 = e32;
  c.formal_order = formal_order;
  if (e21 == 0.0) {
    c.unusable = "the two finest levels agree at every sample: no difference to extrapolate from";
    return c;
  }
  if (e32 <= e21) {
    char why[160];
    std::snprintf(why, sizeof why, "the level differences do not shrink under refinement (%.3g, then %.3g): no observed order", e32, e21);
    c.unusable = why;
    return c;
  }
  // g(p) = ln(r21^p (r32^p − 1) / (r21^p − 1)) rises from ln(ln r32 / ln r21) (p → 0) without
  // bound: bisection on ln(e32/e21) = g(p), bracketed in (0, 64].
  const double target = std::log(e32 / e21);
  const auto g = [&](double p) { return p * std::log(c.r21) + std::log(std::expm1(p * std::log(c.r32)) / std::expm1(p * std::log(c.r21))); };
  double low = 1e-9, high = 64.0;
  if (target <= g(low)) {
    c.unusable = "the level differences shrink too little for the refinement ratios: no positive observed order";
    return c;
  }
  if (target >= g(high)) low = high;
  for (int k = 0; k < 200 && high - low > 1e-13; ++k) {
    const double mid = 0.5 * (low + high);
    (g(mid) < target ? low : high) = mid;
  }
  c.observed_order = 0.5 * (low + high);
  c.order_used = std::min(*c.observed_order, formal_order);
  c.uncertainty = safety_factor * e21 / std::expm1(*c.order_used * std::log(c.r21));
  return c;
}

std::vector<double> gci_band_half_width(const std::vector<double>& fine, const std::vector<double>& medium, double r21,
                                        double observed_order, double safety_factor) {
  if (fine.size() != medium.size())
    throw std::invalid_argument("GCI band: " + std::to_string(fine.size()) + " fine samples against " + std::to_string(medium.size()) +
                                " medium ones");
  if (!(r21 > 1.0) || !(observed_order > 0.0) || !std::isfinite(r21) || !std::isfinite(observed_order))
    throw std::invalid_argument("GCI band: needs a refinement ratio > 1 and an observed order > 0");
  const double denominator = std::pow(r21, observed_order) - 1.0;
  std::vector<double> u(fine.size());
  for (std::size_t k = 0; k < fine.size(); ++k) u[k] = safety_factor * std::abs(fine[k] - medium[k]) / denominator;
  return u;
}

} // namespace kerf
