#include "reference/cohesive/cohesive_law.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kerf::reference {

void validate(const CohesiveLawParameters& p) {
  auto require = [](bool ok, const char* what, double value) {
    if (!ok) throw std::invalid_argument(std::string("cohesive law: ") + what + " (found " + std::to_string(value) + ")");
  };
  require(std::isfinite(p.cohesive_strength) && p.cohesive_strength > 0.0, "cohesive_strength must be > 0 Pa", p.cohesive_strength);
  require(std::isfinite(p.fracture_toughness) && p.fracture_toughness > 0.0, "fracture_toughness must be > 0 J/m^2", p.fracture_toughness);
  require(p.initial_opening_ratio > 0.0 && p.initial_opening_ratio < 1.0, "initial_opening_ratio δ_0/δ_f must lie in (0, 1)",
          p.initial_opening_ratio);
  require(std::isfinite(p.shear_weight) && p.shear_weight >= 0.0, "shear_weight β must be >= 0", p.shear_weight);
  require(std::isfinite(p.viscosity) && p.viscosity >= 0.0, "viscosity η must be >= 0 Pa s/m", p.viscosity);
}

double cohesive_envelope(const CohesiveLawParameters& p, double d) {
  const double d0 = p.peak_opening(), df = p.failure_opening(), sc = p.cohesive_strength;
  if (d <= d0) return sc * std::max(d, 0.0) / d0; // rising branch
  if (d < df) return sc * (df - d) / (df - d0);   // linear softening
  return 0.0;                                     // failed
}

double cohesive_dissipation(const CohesiveLawParameters& p, double kappa) {
  const double d0 = p.peak_opening(), df = p.failure_opening(), sc = p.cohesive_strength;
  if (kappa <= d0) return 0.0;
  if (kappa >= df) return p.fracture_toughness; // the whole area under the envelope, J_c
  // φ_d(κ) = ∫₀^κ T dδ − ½ T(κ) κ: the area between the envelope and the secant unloading line.
  const double loaded = 0.5 * sc * d0 + sc * ((df - d0) * (df - d0) - (df - kappa) * (df - kappa)) / (2.0 * (df - d0));
  return loaded - 0.5 * cohesive_envelope(p, kappa) * kappa;
}

double viscous_weight(const CohesiveLawParameters& p, double kappa) {
  const double d0 = p.peak_opening(), df = p.failure_opening();
  if (kappa <= d0) return 1.0;
  if (kappa >= df) return 0.0;
  return (df - kappa) / (df - d0); // T(κ)/σ_c on the softening branch
}

CohesiveResponse cohesive_response(const CohesiveLawParameters& p, const CohesiveState& state, const Eigen::Vector3d& opening,
                                   const Eigen::Vector3d& n, double dt, bool secant_tangent) {
  const double d0 = p.peak_opening(), df = p.failure_opening(), k0 = p.initial_stiffness();
  const double beta2 = p.shear_weight * p.shear_weight;
  const Eigen::Matrix3d nn = n * n.transpose();

  // Components and effective opening (Ortiz–Pandolfi Eq. 17).
  const double dn = opening.dot(n);
  const Eigen::Vector3d ds = opening - dn * n;
  const double dn_open = std::max(dn, 0.0);
  const double d = std::sqrt(dn_open * dn_open + beta2 * ds.squaredNorm());

  // Damage: κ is the largest effective opening reached; loading when δ passes it.
  const double kappa_old = std::max(state.max_opening, d0);
  const bool loading = d >= kappa_old && d > d0;
  const double kappa = std::max(kappa_old, d);
  const double secant = kappa >= df ? 0.0 : cohesive_envelope(p, kappa) / kappa; // K(κ) = T(κ)/κ

  // Traction t = K(κ) (β² δ_s + ⟨δ_n⟩ n) (Ortiz–Pandolfi Eq. 19) and its tangent.
  const Eigen::Vector3d q = beta2 * ds + dn_open * n;
  CohesiveResponse r;
  r.traction = secant * q;
  Eigen::Matrix3d m = beta2 * (Eigen::Matrix3d::Identity() - nn);
  if (dn > 0.0) m += nn;
  r.tangent = secant * m;
  if (loading && d < df && !secant_tangent) {
    // On the envelope t = (T(δ)/δ) q with dδ = q·dΔ/δ, so ∂t/∂Δ = (T/δ) M + (T'δ − T)/δ³ q qᵀ,
    // T' = −σ_c/(δ_f − δ_0) on the softening branch (the rising branch is only reached with δ <= δ_0,
    // which is never "loading" here).
    const double slope = -p.cohesive_strength / (df - d0);
    r.tangent += (slope * d - cohesive_envelope(p, d)) / (d * d * d) * (q * q.transpose());
  }
  // Crack faces in compression: penalty against interpenetration with the initial stiffness.
  if (dn < 0.0) {
    r.traction += k0 * dn * n;
    r.tangent += k0 * nn;
  }
  // Viscous regularisation (Gao & Bower 2004, Eq. 5), weighted by the strength left at the start
  // of the step, w = T(κ_n)/σ_c past the peak (1 before it, 0 once failed), so that a separated
  // point carries no traction at all: t_v = η w(κ_n) (Δ − Δ_n)/Δt.
  if (p.viscosity > 0.0 && dt > 0.0) {
    const double weight = viscous_weight(p, state.max_opening);
    const Eigen::Vector3d rate = (opening - state.previous_opening) / dt;
    r.traction += p.viscosity * weight * rate;
    r.tangent += (p.viscosity * weight / dt) * Eigen::Matrix3d::Identity();
    r.viscous_power_density = p.viscosity * weight * rate.squaredNorm();
  }

  r.effective_opening = d;
  r.damage_opening = kappa;
  r.damage = 1.0 - secant / k0;
  r.failed = kappa >= df;
  r.stored_energy = 0.5 * secant * d * d + (dn < 0.0 ? 0.5 * k0 * dn * dn : 0.0);
  r.dissipated_energy = cohesive_dissipation(p, kappa);
  return r;
}

} // namespace kerf::reference
