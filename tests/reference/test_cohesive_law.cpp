// The bilinear cohesive law (reference/cohesive/cohesive_law.hpp) against its defining
// properties: the work of separation equals J_c (the area under the envelope, Park & Paulino 2011
// §3.1), unloading is linear to the origin and never heals (Camacho & Ortiz 1996 §3), the reported
// dissipation equals the work lost in a load–unload cycle (integrated here numerically from the
// tractions, independently of cohesive_dissipation's closed form), and the tangent is the
// derivative of the traction (central differences).

#include "reference/cohesive/cohesive_law.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <utility>

namespace kerf::reference {
namespace {

CohesiveLawParameters potato() {
  CohesiveLawParameters p;
  p.cohesive_strength = 0.5e6;  // within potato's σ_c range (0.3-1 MPa; two_layer_cut's lower layer; the potato scenes take 1 MPa)
  p.fracture_toughness = 200.0; // the potato scenes' J_c (paper 001 footnote 1)
  p.initial_opening_ratio = 0.01;
  p.shear_weight = 1.0;
  return p;
}

/// Work per area ∫ t·dΔ along a straight path from `from` to `to` in `steps` trapezoid steps,
/// committing the history at each step (as converged load steps would).
double work_along(const CohesiveLawParameters& p, CohesiveState& state, const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                  const Eigen::Vector3d& n, int steps) {
  double work = 0.0;
  Eigen::Vector3d previous_traction = cohesive_response(p, state, from, n, 0.0).traction;
  for (int k = 1; k <= steps; ++k) {
    const Eigen::Vector3d a = from + (to - from) * (k - 1) / steps, b = from + (to - from) * k / steps;
    const CohesiveResponse r = cohesive_response(p, state, b, n, 0.0);
    work += 0.5 * (previous_traction + r.traction).dot(b - a);
    previous_traction = r.traction;
    state.max_opening = r.damage_opening;
    state.previous_opening = b;
  }
  return work;
}

TEST(CohesiveLaw, WorkOfSeparationIsTheToughness) {
  const CohesiveLawParameters p = potato();
  const Eigen::Vector3d n = Eigen::Vector3d::UnitX();
  for (const Eigen::Vector3d& direction : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(1, 1, 0).normalized()}) {
    CohesiveState state;
    // Open monotonically to 1.5 δ_f (past failure) in mode I, mode II and mixed: with β = 1 the
    // effective opening is |Δ| for any opening direction, so the work is J_c in every mode.
    const double w = work_along(p, state, Eigen::Vector3d::Zero(), 1.5 * p.failure_opening() * direction, n, 20000);
    EXPECT_NEAR(w, p.fracture_toughness, 1e-4 * p.fracture_toughness) << direction.transpose();
    const CohesiveResponse end = cohesive_response(p, state, 1.5 * p.failure_opening() * direction, n, 0.0);
    EXPECT_TRUE(end.failed);
    EXPECT_EQ(end.traction.norm(), 0.0);
    EXPECT_DOUBLE_EQ(end.dissipated_energy, p.fracture_toughness);
  }
}

TEST(CohesiveLaw, PeakTractionIsTheCohesiveStrength) {
  const CohesiveLawParameters p = potato();
  const Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  const CohesiveResponse r = cohesive_response(p, {}, p.peak_opening() * n, n, 0.0);
  EXPECT_NEAR(r.traction.z(), p.cohesive_strength, 1e-9 * p.cohesive_strength);
  EXPECT_NEAR(r.damage, 0.0, 1e-12);
}

TEST(CohesiveLaw, UnloadsToTheOriginAndNeverHeals) {
  const CohesiveLawParameters p = potato();
  const Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  const double kappa = 0.5 * (p.peak_opening() + p.failure_opening());
  CohesiveState state;
  const double loading_work = work_along(p, state, Eigen::Vector3d::Zero(), kappa * n, n, 20000);
  const double t_kappa = cohesive_envelope(p, kappa);
  // Unloading: linear in the opening along the secant t = T(κ)/κ · δ.
  for (double f : {0.75, 0.5, 0.25}) {
    const CohesiveResponse r = cohesive_response(p, state, f * kappa * n, n, 0.0);
    EXPECT_NEAR(r.traction.z(), f * t_kappa, 1e-9 * t_kappa);
    EXPECT_DOUBLE_EQ(r.damage_opening, kappa);
  }
  // The work given back on unloading to zero, subtracted from the loading work, is what the
  // interface dissipated: the closed form φ_d(κ) must equal this numerically integrated loss.
  const double unloading_work = work_along(p, state, kappa * n, Eigen::Vector3d::Zero(), n, 20000);
  const double lost = loading_work + unloading_work;
  EXPECT_NEAR(lost, cohesive_dissipation(p, kappa), 1e-4 * cohesive_dissipation(p, kappa));
  // Back at zero opening the traction is zero (the secant passes through the origin), and
  // reloading follows the secant up to κ, not the undamaged rising branch: no healing.
  EXPECT_NEAR(cohesive_response(p, state, Eigen::Vector3d::Zero(), n, 0.0).traction.norm(), 0.0, 1e-12);
  const CohesiveResponse reload = cohesive_response(p, state, 0.5 * p.peak_opening() * n, n, 0.0);
  EXPECT_NEAR(reload.traction.z(), t_kappa / kappa * 0.5 * p.peak_opening(), 1e-9 * p.cohesive_strength);
  EXPECT_LT(reload.traction.z(), 0.5 * p.cohesive_strength);
}

TEST(CohesiveLaw, CrackFacesDoNotInterpenetrate) {
  const CohesiveLawParameters p = potato();
  const Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  CohesiveState failed;
  failed.max_opening = 2.0 * p.failure_opening(); // a fully failed point
  const Eigen::Vector3d closing = -0.1 * p.peak_opening() * n;
  const CohesiveResponse r = cohesive_response(p, failed, closing, n, 0.0);
  // Compression is resisted with the initial stiffness K_0 whatever the damage.
  EXPECT_NEAR(r.traction.z(), -0.1 * p.cohesive_strength, 1e-9 * p.cohesive_strength);
  // Sliding of a failed point carries nothing.
  EXPECT_NEAR(cohesive_response(p, failed, Eigen::Vector3d(1e-3, 0, 0), n, 0.0).traction.norm(), 0.0, 1e-12);
}

TEST(CohesiveLaw, TangentIsTheDerivativeOfTheTraction) {
  CohesiveLawParameters p = potato();
  p.shear_weight = 0.7;
  p.viscosity = 1e3;
  const Eigen::Vector3d n = Eigen::Vector3d(1, 2, 2).normalized();
  const double df = p.failure_opening();
  CohesiveState loaded;
  loaded.max_opening = 0.3 * df;
  loaded.previous_opening = Eigen::Vector3d(1e-7, -2e-7, 3e-7);
  // Points on the rising branch, softening (loading), unloading, and in compression.
  const Eigen::Vector3d t1 = Eigen::Vector3d(1, 0, 0).cross(n).normalized();
  for (const Eigen::Vector3d& opening :
       {Eigen::Vector3d(0.004 * df * n), Eigen::Vector3d(0.5 * df * n + 0.2 * df * t1), Eigen::Vector3d(0.1 * df * n),
        Eigen::Vector3d(-0.002 * df * n + 0.05 * df * t1)}) {
    const double dt = 1e-3;
    const CohesiveResponse r = cohesive_response(p, loaded, opening, n, dt);
    const double h = 1e-7 * df;
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d e = Eigen::Vector3d::Unit(c) * h;
      const Eigen::Vector3d numeric =
          (cohesive_response(p, loaded, opening + e, n, dt).traction - cohesive_response(p, loaded, opening - e, n, dt).traction) / (2 * h);
      EXPECT_LT((numeric - r.tangent.col(c)).norm(), 1e-5 * r.tangent.norm()) << "opening " << opening.transpose() << " column " << c;
    }
  }
}

// The viscous term: η times the opening rate on an intact point (Gao & Bower 2004, Eq. 5), scaled
// by the strength left, T(κ)/σ_c, on a softening point, and absent on a failed one; its power
// density is the traction's power, t_v · (Δ − Δ_n)/Δt.
TEST(CohesiveLaw, ViscousTractionFadesWithTheStrengthLeft) {
  CohesiveLawParameters p = potato();
  p.viscosity = 2e6;
  const Eigen::Vector3d n(0, 0, 1);
  const double df = p.failure_opening(), d0 = p.peak_opening(), dt = 0.01;
  const Eigen::Vector3d step = Eigen::Vector3d(1e-6, -2e-6, 0);
  auto viscous = [&](double kappa, const Eigen::Vector3d& base) {
    CohesiveState s;
    s.max_opening = kappa;
    s.previous_opening = base;
    CohesiveLawParameters plain = p;
    plain.viscosity = 0.0;
    // The sliding-only step keeps the cohesive part unchanged between the two evaluations.
    return std::pair{cohesive_response(p, s, base + step, n, dt), cohesive_response(plain, s, base + step, n, dt)};
  };
  const Eigen::Vector3d rate = step / dt;
  {
    const auto [with, without] = viscous(0.0, Eigen::Vector3d::Zero());
    EXPECT_LT((with.traction - without.traction - p.viscosity * rate).norm(), 1e-9 * p.viscosity * rate.norm());
    EXPECT_NEAR(with.viscous_power_density, p.viscosity * rate.squaredNorm(), 1e-9 * p.viscosity * rate.squaredNorm());
  }
  {
    const double kappa = 0.75 * df;
    const double w = (df - kappa) / (df - d0);
    EXPECT_NEAR(viscous_weight(p, kappa), cohesive_envelope(p, kappa) / p.cohesive_strength, 1e-12);
    const auto [with, without] = viscous(kappa, Eigen::Vector3d(0, 0, 0.5 * df));
    EXPECT_LT((with.traction - without.traction - w * p.viscosity * rate).norm(), 1e-9 * p.viscosity * rate.norm());
    EXPECT_NEAR(with.viscous_power_density, (with.traction - without.traction).dot(rate), 1e-9 * with.viscous_power_density);
  }
  {
    const auto [with, without] = viscous(1.5 * df, Eigen::Vector3d(0, 0, 2.0 * df));
    EXPECT_EQ(with.traction.norm(), 0.0);
    EXPECT_EQ(with.viscous_power_density, 0.0);
  }
}

TEST(CohesiveLaw, RefusesBadParameters) {
  CohesiveLawParameters p = potato();
  p.cohesive_strength = 0.0;
  EXPECT_THROW(validate(p), std::invalid_argument);
  p = potato();
  p.initial_opening_ratio = 1.0;
  EXPECT_THROW(validate(p), std::invalid_argument);
  EXPECT_NO_THROW(validate(potato()));
}

} // namespace
} // namespace kerf::reference
