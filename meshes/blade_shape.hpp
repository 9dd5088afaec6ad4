#pragma once
// BladeShape: the geometry of a cutting blade (paper 001, Mahvash & Hayward, "Haptic Rendering of
// Cutting: A Fracture Mechanics Approach", §4: a sharp tool whose edge meets the body along the
// contact length l and advances along the cutting axis), the one definition that the scene, the
// realtime models and the reference's rigid tool read.

#include <Eigen/Core>

namespace kerf {

/// A blade relative to its reference point c (the tool's position: the midpoint of its edge).
/// SI units: metres and radians.
///
/// - The edge is the straight segment c + s e, s in [−L/2, L/2], e = `edge_direction` (unit),
///   L = `edge_length`; the part of it inside the body is paper 001's contact length l.
/// - The edge advances along d = `cutting_direction` (unit, orthogonal to e): paper 001's cutting
///   axis x, along which the crack is opened.
/// - Behind the edge (against d) lies a wedge of included angle θ = `wedge_angle` between its two
///   flanks, symmetric about the plane of e and d: with m = e × d the flanks are the planes
///   through the edge with normals sin(θ/2) d ± cos(θ/2) m; the wedge is closed by a slab of
///   `thickness` t (|(x − c)·m| <= t/2) behind the point where the flanks are t apart,
///   t / (2 tan(θ/2)) behind the edge; it is bounded along e by the edge's ends. The reference's
///   rigid tool is this wedge (reference/rigid_tool.hpp); the realtime models press the edge as a
///   line (e, d, L).
struct BladeShape {
  Eigen::Vector3d edge_direction = Eigen::Vector3d::UnitY();     ///< e: unit, along the edge
  Eigen::Vector3d cutting_direction = -Eigen::Vector3d::UnitZ(); ///< d: unit, orthogonal to e; the edge advances along it
  double edge_length = 0.0;  ///< L [m] > 0, centred on the reference point
  double wedge_angle = 0.0;  ///< θ [rad] in (0, π), the included angle between the flanks
  double thickness = 0.0;    ///< t [m] > 0, the back thickness of the blade (the slab behind the flanks)
};

} // namespace kerf
