#pragma once
// Blade edge contact: the rigid blade's edge line, sampled into slave points, pressed against the
// body's boundary facets by a penalty — node-to-surface contact with the rigid tool as the slave
// side (Wriggers 2006, "Computational Contact Mechanics", 2nd ed., §4.3 closest-point projection
// and gap; §9.3 node-to-segment discretisation, its residual and consistent tangent; the penalty
// method of §6.3). It is the second pass of a two-pass scheme: the body's boundary quadrature
// points are tested against the blade's flanks (rigid_tool.hpp, tool_contact); this pass catches
// the edge, which is thinner than the body's facets and slips between their quadrature points.
//
// Each edge point p inside the body (behind the boundary facet nearest to it) at distance d from
// the boundary carries the penalty energy W = ½ ε_L w d² (ε_L [N/m²] a line penalty, w [m] the
// point's share of the edge length). The body's facet nodes receive f_i = −∂W/∂x_i = ε_L w λ_i r
// (r = p − x_c, x_c = Σ λ_i x_i the closest point), the tool −Σ f_i, and the tangent is
// ∂²W/∂x² = ½ ε_L w ∇²d² (point_triangle_distance.hpp). Units: SI.

#include "reference/contact/point_triangle_distance.hpp"
#include "reference/rigid_tool.hpp"

#include <Eigen/Core>

#include <array>
#include <span>
#include <vector>

namespace kerf::reference {

/// A flat triangle of the body's boundary: three node indices (node k's displacement is the
/// entries 3k, 3k+1, 3k+2 of the node-major displacement vector), ordered so that
/// (x1 − x0) × (x2 − x0) points out of the body.
using BoundaryFacet = std::array<int, 3>;

/// Parameters of the edge pass.
struct BladeEdgeContactSettings {
  double line_penalty = 0.0;    ///< ε_L [N/m²] > 0: a line load q [N/m] costs a penetration q / ε_L
  double point_spacing = 0.0;   ///< distance between edge points [m] > 0
  double search_distance = 0.0; ///< facets farther than this from an edge point are not considered [m] > 0
};

/// One active edge point's contribution, on the three nodes of its facet.
struct EdgeContactTerm {
  std::size_t facet = 0;   ///< index of the facet in the `facets` passed to blade_edge_contact
  BoundaryFacet nodes{};
  double weight = 0.0;     ///< the edge point's share w of the edge length [m]
  double line_load = 0.0;  ///< ε_L d [N/m]
  Eigen::Matrix<double, 9, 1> force_on_body = Eigen::Matrix<double, 9, 1>::Zero(); ///< f_i [N]
  Eigen::Matrix<double, 9, 9> stiffness = Eigen::Matrix<double, 9, 9>::Zero();     ///< ∂²W/∂x² [N/m]
};

/// The edge pass at one configuration.
struct BladeEdgeContact {
  std::vector<EdgeContactTerm> terms;
  Eigen::Vector3d force_on_body = Eigen::Vector3d::Zero(); ///< Σ f_i = −(force on the tool) [N]
  int active_points = 0;      ///< edge points inside the body
  int sampled_points = 0;     ///< edge points tested
  double contact_length = 0.0; ///< Σ w of the active points [m]
  double max_line_load = 0.0;  ///< max ε_L d [N/m]
};

/// The edge points of a wedge `tool` whose edge midpoint is at `position`: n = ⌈L/s⌉ + 1 points
/// evenly spaced over the edge length L (s the spacing), with trapezoid weights (L/(n−1), halved
/// at the ends). Throws std::invalid_argument if the tool is not a wedge or the spacing is not
/// positive.
std::vector<std::pair<Eigen::Vector3d, double>> blade_edge_points(const RigidToolShape& tool,
                                                                  const Eigen::Vector3d& position, double spacing);

/// Evaluates the edge pass (see file comment) on the body whose node k sits at
/// reference_positions[k] + displacement[3k .. 3k+2]. An edge point is inside the body when it
/// lies behind (n · (p − x_c) < 0, n the outward facet normal) every facet that attains the
/// smallest distance to it — so a point under a concave fold (two facets tied on their shared
/// edge) is inside, a point beside a convex ridge is not. Throws std::invalid_argument on bad
/// settings or a facet node out of range.
/// `part` of `parts`: only the edge points of that share of the edge (of the n points, those from
/// ⌊n part / parts⌋ to ⌊n (part + 1) / parts⌋ − 1, in edge order), e.g. one MPI process's; the
/// terms of the parts, concatenated in part order, are those of the whole edge in the same order.
BladeEdgeContact blade_edge_contact(const RigidToolShape& tool, const Eigen::Vector3d& position,
                                    std::span<const BoundaryFacet> facets,
                                    std::span<const Eigen::Vector3d> reference_positions,
                                    std::span<const double> displacement, const BladeEdgeContactSettings& settings,
                                    std::size_t part = 0, std::size_t parts = 1);

} // namespace kerf::reference
