#pragma once
// Rigid tools of the reference: the scene's sphere (stylus tip) and blade (a wedge with its edge
// and two flanks, closed by a slab of the blade's thickness), as signed-distance functions for
// penalty contact (Wriggers 2006, "Computational Contact Mechanics", §5.2, §6.3): a body point
// x inside the tool has penetration p = −g > 0 and is pushed out along the tool's outward normal n
// by the traction t = ε_N p n (per unit reference area).

#include "meshes/blade_shape.hpp"

#include <Eigen/Core>

#include <array>
#include <span>

namespace kerf::reference {

/// The geometry of a rigid tool relative to its reference point (the sphere's centre or the
/// blade edge's midpoint). Units: metres, radians.
struct RigidToolShape {
  enum class Kind { sphere, wedge };
  Kind kind = Kind::sphere;
  double radius = 0.0; ///< sphere radius [m] > 0
  /// Wedge: the blade (meshes/blade_shape.hpp): edge direction e, cutting direction d ⟂ e, edge
  /// length L centred on the reference point, included angle θ, back thickness t.
  BladeShape blade;
};

/// Throws std::invalid_argument naming the field if the shape is not usable (non-positive size,
/// non-unit or non-orthogonal directions, angle out of range).
void validate(const RigidToolShape& shape);

/// Closest-exit contact of one point against the tool placed at `position`.
struct ToolContactPoint {
  bool inside = false;        ///< x lies inside the tool (penetration > 0)
  double penetration = 0.0;   ///< p = −g >= 0 [m]
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();    ///< outward unit normal n of the tool surface
  Eigen::Matrix3d normal_derivative = Eigen::Matrix3d::Zero(); ///< ∂n/∂x [1/m] (sphere: (I − n⊗n)/r; planes: 0)
};

/// Where x is relative to the tool at `position`.
/// Sphere: g = |x − c| − R, n = (x − c)/|x − c|.
/// Wedge: in the frame (d, m = e × d), the solid is the intersection of the half-spaces
///   s₁ = (x−c)·(sin φ d + cos φ m) <= 0,  s₂ = (x−c)·(sin φ d − cos φ m) <= 0 (the flanks, φ = θ/2),
///   s₃ = (x−c)·m − t/2 <= 0,               s₄ = −(x−c)·m − t/2 <= 0 (the back slab),
///   s₅ = (x−c)·e − L/2 <= 0,               s₆ = −(x−c)·e − L/2 <= 0 (the ends of the edge),
/// infinite behind the edge; the penetration is −max sₖ and n the normal of the face attaining it
/// (the nearest exit). The edge itself is pressed against the body by blade_edge_contact.hpp.
///
/// `side` (wedge only; zero = none): for a point on one face of a crack the blade runs in, the unit
/// direction into that face's own material. Such a point leaves the wedge only through a face
/// whose outward normal does not point against it (normal · side >= 0), so the two faces of the
/// crack are pushed apart to their own sides even where the blade's two flanks are equally near
/// (on the crack plane, at the edge), instead of one of them being pushed through the blade.
ToolContactPoint tool_contact(const RigidToolShape& shape, const Eigen::Vector3d& position, const Eigen::Vector3d& x,
                              const Eigen::Vector3d& side = Eigen::Vector3d::Zero());

/// Six half-spaces whose intersection holds the tool: a point x with
/// normal[k] · (x − position) >= offset[k] for some k is not inside the tool (tool_contact).
/// Wedge: its six faces s₁ … s₆ above (inside iff every sₖ < 0). Sphere: its bounding box
/// ±(x − c)_i < R. Used to skip the contact search where a whole set of points cannot touch
/// the tool (outside_together).
struct ToolHalfSpaces {
  std::array<Eigen::Vector3d, 6> normal;
  std::array<double, 6> offset{};
};
[[nodiscard]] ToolHalfSpaces bounding_half_spaces(const RigidToolShape& shape);

/// True when every point lies outside one and the same half-space of `h` (the tool at
/// `position`). Then so does every convex combination of the points (a half-space is convex):
/// no point of their convex hull is inside the tool.
[[nodiscard]] bool outside_together(const ToolHalfSpaces& h, const Eigen::Vector3d& position,
                                    std::span<const Eigen::Vector3d> points);

} // namespace kerf::reference
