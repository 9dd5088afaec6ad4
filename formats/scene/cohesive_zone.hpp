#pragma once
// The cohesive zone a scene's crack path must resolve: from the material's cohesive law (σ_c,
// J_c) and the blade's wedge. The scene's mesh grades its crack path to it (scene_mesh.hpp) and
// the reference checks its resolution (experiments/reference_run/reference_fracture.hpp).

#include "formats/scene/scene.hpp"

namespace kerf {

/// The cohesive zone a crack path must resolve (docs/cohesive-fracture.md, "Steady cutting"):
/// Rice's zone of a crack loaded from afar, l_cz = (9π/32) E' J_c/σ_c² (reference/cohesive/cohesive_zone.hpp), and,
/// in front of a blade's wedge, the zone the wedge itself sets: its flanks open the crack faces by
/// 2 s tan(θ/2) at a distance s behind the edge, which reaches the failure opening δ_f = 2 J_c/σ_c
/// at s_f = δ_f / (2 tan(θ/2)). The longer of the two governs; a mesh resolves it with
/// minimum_elements_in_cohesive_zone elements (Turon et al. 2007).
struct CohesiveZone {
  double rice = 0.0;  ///< l_cz [m]
  double wedge = 0.0; ///< s_f [m]; 0 without a blade
  double length() const { return rice > wedge ? rice : wedge; }
};

/// How far `blade`'s edge reaches along its cutting direction c over its trajectory,
/// max_k p_k · c [m] (p_k the edge midpoint's sampled positions).
double blade_reach(const Tool& blade);

/// The lowest height the edge of `blade` reaches over its trajectory, min_k (p_k,z − (L/2)|e_z|) [m]
/// (p_k the edge midpoint's sampled positions, L the edge length, e its direction; z up).
double blade_lowest_edge_point(const Tool& blade);

/// The zone of `scene`'s cohesive law and blade; both 0 when the scene gives no σ_c or J_c.
CohesiveZone scene_cohesive_zone(const Scene& scene);

/// Whether `scene` declares a way to come apart (cutting or tearing) and gives the cohesive law
/// (cohesive_strength and fracture_toughness) that a reference crack path needs.
bool scene_has_cohesive_law(const Scene& scene);

} // namespace kerf
