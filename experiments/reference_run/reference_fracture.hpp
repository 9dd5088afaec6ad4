#pragma once
// The scene-level side of Reference II: a cutting or tearing scene's crack path (its conformingly
// meshed `cut_plane`) split and joined by the bilinear cohesive law with the scene's σ_c and J_c,
// the check that the mesh resolves the cohesive zone, the modes and crack extent read from the
// interface, and the energy bookkeeping every run's manifest carries.
//
// Includes reference/*.hpp only, which include no deal.II.

#include "formats/scene/cohesive_zone.hpp"
#include "formats/scene/scene.hpp"
#include "realtime/force_sample.hpp"
#include "reference/cohesive/cohesive_zone.hpp"
#include "reference/finite_strain_solver.hpp"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <string>

namespace kerf {

/// Whether a reference run models fracture along the crack path.
enum class ReferenceFracture {
  automatic, ///< when the scene has cutting or tearing, a `cut_plane` surface, σ_c and J_c
  off,       ///< never: the body only deforms (Reference I)
  on         ///< always; an error if the scene cannot have it
};

/// What `add_crack_path` did.
struct CrackPathInfo {
  bool active = false;
  std::size_t interface_triangles = 0; ///< crack triangles joined by the cohesive law
  double zone_length = 0.0;           ///< the governing zone [m] (CohesiveZone::length)
  /// The element size where the crack runs [m]: the side of the equilateral triangle of the mean
  /// area of the crack path's triangles in the blade's sweep (from the top down to the deepest point its edge reaches plus one zone
  /// length; the whole path for a tear), measured on the mesh and halved by each refinement.
  double element_size = 0.0;
  double elements_in_zone = 0.0;      ///< zone_length / element_size
  double viscosity = 0.0;             ///< η [Pa s/m] of the law's viscous regularisation (0: none)
  double interface_area = 0.0;        ///< reference area of the crack path joined by the law [m^2]
  std::string warning;                ///< non-empty when the zone spans fewer than 3 elements (Turon et al. 2007)
};

/// If `mode` asks for it (see ReferenceFracture), splits `problem.mesh` along `cut_plane`
/// (meshes/crack_split.hpp) and adds the cohesive interface with the scene's cohesive_strength and
/// fracture_toughness. `refinements` (global, each halving h) enters the zone-resolution check.
/// `viscous_time` τ [s] >= 0 switches on the law's viscous regularisation (Gao & Bower 2004, Eq. 5;
/// reference/cohesive/cohesive_law.hpp) with η = σ_c τ / δ_f: the viscous traction reaches σ_c
/// when the opening grows by δ_f in τ. Throws std::invalid_argument naming the scene when `mode` is
/// `on` and the scene has no cut_plane, σ_c or J_c, or when τ is negative or not finite.
CrackPathInfo add_crack_path(const Scene& scene, reference::FiniteStrainProblem& problem, ReferenceFracture mode,
                             int refinements, double viscous_time = 0.0);

/// The energy bookkeeping of a run (docs/cohesive-fracture.md): external work by the tools on the body
/// (trapezoid rule over the solved samples, W = Σ ½ (F_k + F_{k−1})·(x_k − x_{k−1}) with F the force
/// of the tool on the body), stored elastic energy ∫ψ dV, interface energy, the penalty energy of
/// the tool contact, cohesive dissipation, viscous dissipation, friction dissipation (0: the
/// reference tool is frictionless), and the balance error
/// (W − stored − interface − contact − kinetic − dissipations) / max(W, stored + …), with the kinetic
/// energy ½ vᵀ M v and the Kelvin–Voigt damping dissipation of the dynamic step (0 for a
/// quasi-static run). With the dynamic step (Newmark average acceleration = the trapezoidal rule)
/// the trapezoid-rule work of the tools' forces (their reactions, which include the inertia of the
/// driven nodes) equals ΔK plus the trapezoid rule of the internal and viscous forces' work exactly
/// (Hughes, The Finite Element Method, §9.1), so what the balance then measures is only the
/// trapezoid rule's error on the nonlinear internal forces over a step. The largest such error is
/// the cohesive law's kinks (a point that opens past the peak or past δ_f within one step): the
/// interface's own trapezoid work is measured point by point
/// (reference::CohesiveSummary::trapezoid_work), and its excess over the interface energy and
/// cohesive dissipation is reported as the time integration's error at the kinks,
/// `cohesive_time_integration_J` (0 for a quasi-static run). It is not booked in the balance: the
/// load path's interface energy control keeps it small (reference/load_path.hpp), and the balance
/// error includes it.
/// The trapezoid rule is exact for a force linear between samples; a crack that advances by an
/// unstable jump between two samples (a snap-through of an under-resolved cohesive zone) releases
/// energy that a quasi-static solution does not see, and the balance error then measures that loss.
class EnergyBookkeeping {
public:
  /// One solved sample: the tool reference points [m] and the forces of the tools on the body [N]
  /// (one entry per tool), the body's strain energy [J], the interface summary and the contact's
  /// penalty energy [J] (EquilibriumReport::contact_energy).
  /// `kinetic_energy` and `damping_dissipation` [J]: the dynamic step's (FiniteStrainSolver).
  void add_sample(const std::vector<Eigen::Vector3d>& positions, const std::vector<Eigen::Vector3d>& forces_on_body,
                  double strain_energy, const reference::CohesiveSummary& interface, double contact_energy = 0.0,
                  double kinetic_energy = 0.0, double damping_dissipation = 0.0);
  [[nodiscard]] double external_work() const { return m_work; }
  [[nodiscard]] double balance_error() const;
  /// The interface's trapezoid work minus its stored energy and cohesive dissipation [J] (dynamic
  /// step; 0 otherwise): the time integration's error at the kinks of the cohesive law.
  [[nodiscard]] double cohesive_time_integration() const;
  [[nodiscard]] nlohmann::json to_json() const;
  /// Restores the bookkeeping from to_json() (a checkpoint).
  static EnergyBookkeeping from_json(const nlohmann::json& j);

private:
  std::vector<Eigen::Vector3d> m_positions, m_forces;
  double m_work = 0.0, m_strain = 0.0, m_contact = 0.0, m_kinetic = 0.0, m_damping = 0.0;
  reference::CohesiveSummary m_interface;
};

} // namespace kerf
