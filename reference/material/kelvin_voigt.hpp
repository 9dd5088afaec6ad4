#pragma once
// Kelvin–Voigt damping of the reference's dynamic step: a viscous second Piola–Kirchhoff stress
// on the rate of the Green–Lagrange strain, added to the hyperelastic one (S = S_e(C) + S_v(Ė)),
//
//   S_v = τ ℂ₀ : Ė = τ (λ tr(Ė) I + 2μ Ė),   Ė = sym(Fᵀ Ḟ),   τ = η / E,
//
// with ℂ₀ the small-strain elasticity tensor of the region (λ, μ from E, ν) and τ the retardation
// time from the scene's Kelvin–Voigt viscosity η [Pa s] (docs/scenes.md `damping`). It derives
// from the dissipation potential φ(Ė) = ½ τ Ė : ℂ₀ : Ė (S_v = ∂φ/∂Ė), so the dissipated power per
// reference volume S_v : Ė = 2φ is never negative; S = S_e + S_v is the additive split into an
// equilibrium and a viscous part of finite-strain viscoelasticity (Holzapfel 2000, Nonlinear
// Solid Mechanics, §6.10). In the small-strain limit it is σ = ℂ₀:ε + τ ℂ₀:ε̇, the spring
// network's Kelvin–Voigt damping (docs/spring-network.md, "Damping": dashpots c = τ k), i.e.
// stiffness-proportional Rayleigh damping C = τ K, under which every vibration mode ω has the
// damping ratio ζ = ωτ/2 (Chopra, Dynamics of Structures, §11.4).
//
// Eigen only.

#include "reference/material/hyperelastic_law.hpp"

#include <Eigen/Core>

namespace kerf::reference {

/// The Kelvin–Voigt damping of one material region.
struct KelvinVoigtDamping {
  double retardation_time = 0.0; ///< τ = η / E [s] >= 0 (0: no damping)
  double lambda = 0.0;           ///< λ of ℂ₀ [Pa]
  double mu = 0.0;               ///< μ of ℂ₀ [Pa]
};

/// The damping of a region with Young's modulus E [Pa] > 0, Poisson's ratio ν in (−1, 0.5) and
/// Kelvin–Voigt viscosity η [Pa s] >= 0: τ = η/E, λ = Eν/((1+ν)(1−2ν)), μ = E/(2(1+ν)). Throws
/// std::invalid_argument naming the value when η is negative or not finite.
KelvinVoigtDamping kelvin_voigt_damping(double youngs_modulus, double poisson_ratio, double viscosity);

/// The viscous first Piola–Kirchhoff stress P_v = F S_v [Pa] at deformation gradient F and rate
/// Ḟ = Grad v [1/s], and its tangent for a time step in which Ḟ depends on F linearly,
/// ∂Ḟ/∂F = `rate_per_displacement` (γ/(βh) for Newmark: 2/h for β = 1/4, γ = 1/2):
///   δP_v = δF S_v + F τ ℂ₀ : (sym(δFᵀ Ḟ) + c sym(Fᵀ δF)),   c = rate_per_displacement,
/// as a 9 × 9 matrix (3i+J, 3k+L) like StressTangent::tangent (added to the law's).
StressTangent kelvin_voigt_stress(const KelvinVoigtDamping& damping, const Eigen::Matrix3d& F,
                                  const Eigen::Matrix3d& F_rate, double rate_per_displacement);

/// The dissipated power per unit reference volume S_v : Ė = τ (λ tr(Ė)² + 2μ Ė:Ė) [W/m^3] (>= 0).
double kelvin_voigt_dissipation_rate(const KelvinVoigtDamping& damping, const Eigen::Matrix3d& F,
                                     const Eigen::Matrix3d& F_rate);

} // namespace kerf::reference
