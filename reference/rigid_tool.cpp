#include "reference/rigid_tool.hpp"

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace kerf::reference {

void validate(const RigidToolShape& s) {
  if (s.kind == RigidToolShape::Kind::sphere) {
    if (!(s.radius > 0.0) || !std::isfinite(s.radius))
      throw std::invalid_argument("rigid tool: sphere radius must be positive, got " + std::to_string(s.radius));
    return;
  }
  if (std::abs(s.blade.edge_direction.norm() - 1.0) > 1e-9 || std::abs(s.blade.cutting_direction.norm() - 1.0) > 1e-9)
    throw std::invalid_argument("rigid tool: wedge edge_direction and cutting_direction must be unit vectors");
  if (std::abs(s.blade.edge_direction.dot(s.blade.cutting_direction)) > 1e-9)
    throw std::invalid_argument("rigid tool: wedge cutting_direction must be orthogonal to edge_direction");
  if (!(s.blade.wedge_angle > 0.0 && s.blade.wedge_angle < std::numbers::pi))
    throw std::invalid_argument("rigid tool: wedge_angle must lie in (0, pi), got " + std::to_string(s.blade.wedge_angle));
  if (!(s.blade.thickness > 0.0) || !std::isfinite(s.blade.thickness))
    throw std::invalid_argument("rigid tool: wedge thickness must be positive, got " + std::to_string(s.blade.thickness));
  if (!(s.blade.edge_length > 0.0) || !std::isfinite(s.blade.edge_length))
    throw std::invalid_argument("rigid tool: wedge edge_length must be positive, got " + std::to_string(s.blade.edge_length));
}

ToolHalfSpaces bounding_half_spaces(const RigidToolShape& s) {
  ToolHalfSpaces h;
  if (s.kind == RigidToolShape::Kind::sphere) {
    for (int i = 0; i < 3; ++i) {
      h.normal[static_cast<std::size_t>(2 * i)] = Eigen::Vector3d::Unit(i);
      h.normal[static_cast<std::size_t>(2 * i + 1)] = -Eigen::Vector3d::Unit(i);
    }
    h.offset.fill(s.radius);
    return h;
  }
  // The wedge's faces (rigid_tool.hpp): the flanks s₁, s₂, the back slab s₃, s₄, the edge's ends s₅, s₆.
  const Eigen::Vector3d& d = s.blade.cutting_direction;
  const Eigen::Vector3d m = s.blade.edge_direction.cross(d);
  const double phi = 0.5 * s.blade.wedge_angle;
  const Eigen::Vector3d& e = s.blade.edge_direction;
  h.normal = {std::sin(phi) * d + std::cos(phi) * m, std::sin(phi) * d - std::cos(phi) * m, m, -m, e, -e};
  // An edge_length of 0 (a shape that skipped validate) leaves the wedge unbounded along e.
  const double half_length = s.blade.edge_length > 0.0 ? 0.5 * s.blade.edge_length : std::numeric_limits<double>::infinity();
  h.offset = {0.0, 0.0, 0.5 * s.blade.thickness, 0.5 * s.blade.thickness, half_length, half_length};
  return h;
}

bool outside_together(const ToolHalfSpaces& h, const Eigen::Vector3d& position, std::span<const Eigen::Vector3d> points) {
  if (points.empty()) return true;
  for (std::size_t k = 0; k < h.normal.size(); ++k) {
    bool all = true;
    for (const Eigen::Vector3d& x : points)
      if (!((x - position).dot(h.normal[k]) >= h.offset[k])) {
        all = false;
        break;
      }
    if (all) return true;
  }
  return false;
}

ToolContactPoint tool_contact(const RigidToolShape& s, const Eigen::Vector3d& c, const Eigen::Vector3d& x,
                              const Eigen::Vector3d& side) {
  ToolContactPoint out;
  const Eigen::Vector3d r = x - c;
  if (s.kind == RigidToolShape::Kind::sphere) {
    const double dist = r.norm();
    // g = |x − c| − R; a point at the centre has no defined normal: it cannot occur in a converged
    // state (the penalty grows without bound) and is left out.
    if (dist >= s.radius || dist < 1e-12 * s.radius) return out;
    out.inside = true;
    out.penetration = s.radius - dist;
    out.normal = r / dist;
    // ∂n/∂x = (I − n⊗n) / |x − c|
    out.normal_derivative = (Eigen::Matrix3d::Identity() - out.normal * out.normal.transpose()) / dist;
    return out;
  }
  const ToolHalfSpaces faces = bounding_half_spaces(s);
  const std::array<Eigen::Vector3d, 6>& normals = faces.normal;
  const std::array<double, 6>& offsets = faces.offset;
  // Inside iff every s_k < 0 (whatever the side); the exit is the allowed face with the largest s_k.
  int face = -1;
  double largest = -std::numeric_limits<double>::infinity(), largest_any = largest;
  for (std::size_t k = 0; k < normals.size(); ++k) {
    const double sk = r.dot(normals[k]) - offsets[k];
    largest_any = std::max(largest_any, sk);
    if (normals[k].dot(side) < -1e-12) continue; // an exit into the other face's material
    if (sk > largest) {
      largest = sk;
      face = static_cast<int>(k);
    }
  }
  if (largest_any >= 0.0) return out;
  out.inside = true;
  out.penetration = -largest;
  out.normal = normals[static_cast<std::size_t>(face)];
  return out;
}

} // namespace kerf::reference
