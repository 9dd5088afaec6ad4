#pragma once
// The scene's body as tetrahedra, meshed from the scene: its geometry file and element size, the
// physical regions its tools define (the disc a stylus grasps), and — for the finite-element
// reference — the grading the physics needs (fine at each grasp rim, where the traction of a tied
// disc is singular; on the crack path, where the cohesive zone needs three elements), with no
// hand-edited .geo parameters.

#include "formats/scene/scene.hpp"
#include "meshes/tet_mesh.hpp"
#include "meshes/tet_quality.hpp"

#include <map>
#include <string>

namespace kerf {

/// What a mesh is for: the scene's own (every model's geometry; the problem's regions, no
/// grading), or the finite-element reference's (the same regions, graded where the physics needs
/// resolution).
enum class MeshPurpose { scene, reference };

/// Elements per grasp radius at each grasp rim of a reference mesh: the rim size is
/// min(h, a / grasp_rim_elements_per_radius), growing away from the rim by half the distance
/// (grasp_size_growth 0.5). A tied disc's traction is singular at its rim (a rigid punch,
/// Johnson 1985 §3.8: p ∝ (a² − r²)^(-1/2)), and a compliant layer's has a kink there (its
/// stiffness falls to zero at the rim): the force converges at about first order in the rim's
/// element size, so the rim is resolved finely (clay_pull at P2: a/6 gave a GCI of 2.0 % on the
/// RMS force, a/12 0.74 %; docs/reference.md, "Convergence of clay_pull").
inline constexpr double grasp_rim_elements_per_radius = 12.0;

/// The .geo parameters kerf derives from `scene` for `purpose`, beside the scene file's own:
/// - `grasp<k>_radius`, `grasp<k>_x`, `grasp<k>_y` (k = 1, 2 in tool order) for each sphere tool
///   with a grasp radius: the disc under its start position on the top face;
/// - for the reference, `grasp_element_size` (see grasp_rim_elements_per_radius), and for a cutting
///   or tearing scene with a cohesive law on a geometry that declares them, the crack path's grading
///   `cut_element_size` = min(h0, zone / 3) (the cohesive zone with at least three elements, Turon
///   et al. 2007; CohesiveZone in cohesive_zone.hpp), `cut_far_size`, `cut_grading_distance`
///   and `cut_refine_depth` (the blade's reach plus one zone).
/// Every derived size is scaled by element_size / nominal_element_size, so that meshing the scene
/// at another element size refines the whole graded mesh systematically. Throws
/// std::invalid_argument for a grasping stylus on a geometry that is not a .geo, or for more than
/// two grasping styluses.
std::map<std::string, double> scene_mesh_parameters(const Scene& scene, MeshPurpose purpose);

/// The scene's body as tetrahedra: its .geo meshed with the scene's parameters, the derived ones
/// (scene_mesh_parameters) and its element size, its STL meshed, or its .msh read. Checked before
/// anyone uses it: a mesh with inverted or degenerate elements, without a `body` volume, or without
/// the `grasp<k>` surface a grasping stylus needs is a MeshError naming the geometry file.
TetMesh scene_mesh(const Scene& scene, MeshPurpose purpose = MeshPurpose::scene);

/// The name of the physical surface the k-th grasping stylus of a scene (k = 1, 2 in tool order)
/// grasps: "grasp<k>".
std::string grasp_surface_name(int k);

} // namespace kerf
