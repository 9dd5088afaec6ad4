#include "reference/contact/blade_edge_contact.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace kerf::reference {

std::vector<std::pair<Eigen::Vector3d, double>> blade_edge_points(const RigidToolShape& tool,
                                                                  const Eigen::Vector3d& position, double spacing) {
  if (tool.kind != RigidToolShape::Kind::wedge)
    throw std::invalid_argument("blade edge contact: the tool is not a wedge (blade)");
  if (!(spacing > 0.0) || !std::isfinite(spacing))
    throw std::invalid_argument("blade edge contact: point spacing must be positive, got " + std::to_string(spacing));
  const double L = tool.blade.edge_length;
  const auto segments = static_cast<int>(std::ceil(L / spacing));
  if (segments > 1000000)
    throw std::invalid_argument("blade edge contact: point spacing " + std::to_string(spacing) +
                                " m gives more than 1e6 points on a " + std::to_string(L) + " m edge");
  std::vector<std::pair<Eigen::Vector3d, double>> points;
  const double w = L / segments;
  for (int k = 0; k <= segments; ++k) {
    // p_k = c + (−L/2 + k L/n) e, trapezoid weight
    const double s = -0.5 * L + w * k;
    points.emplace_back(position + s * tool.blade.edge_direction, (k == 0 || k == segments) ? 0.5 * w : w);
  }
  return points;
}

BladeEdgeContact blade_edge_contact(const RigidToolShape& tool, const Eigen::Vector3d& position,
                                    std::span<const BoundaryFacet> facets,
                                    std::span<const Eigen::Vector3d> reference_positions,
                                    std::span<const double> displacement, const BladeEdgeContactSettings& settings,
                                    std::size_t part, std::size_t parts) {
  if (!(settings.line_penalty > 0.0) || !(settings.search_distance > 0.0))
    throw std::invalid_argument("blade edge contact: line_penalty and search_distance must be positive");
  if (parts == 0 || part >= parts)
    throw std::invalid_argument("blade edge contact: part " + std::to_string(part) + " of " + std::to_string(parts));
  if (displacement.size() != 3 * reference_positions.size())
    throw std::invalid_argument("blade edge contact: " + std::to_string(displacement.size()) +
                                " displacement entries for " + std::to_string(reference_positions.size()) + " nodes");
  auto points = blade_edge_points(tool, position, settings.point_spacing);
  if (parts > 1) { // this part's share, k in [n part / parts, n (part + 1) / parts)
    const std::size_t n = points.size();
    points = std::vector<std::pair<Eigen::Vector3d, double>>(points.begin() + static_cast<std::ptrdiff_t>(n * part / parts),
                                                             points.begin() + static_cast<std::ptrdiff_t>(n * (part + 1) / parts));
  }
  BladeEdgeContact out;
  out.sampled_points = static_cast<int>(points.size());
  if (points.empty()) return out;
  const auto node_count = static_cast<int>(reference_positions.size());
  auto x_of = [&](int k) {
    if (k < 0 || k >= node_count)
      throw std::invalid_argument("blade edge contact: facet node " + std::to_string(k) + " out of range");
    const auto i = static_cast<std::size_t>(k);
    return Eigen::Vector3d(reference_positions[i] + Eigen::Vector3d(displacement[3 * i], displacement[3 * i + 1],
                                                                      displacement[3 * i + 2]));
  };

  // Candidate facets: those whose current bounding box comes within the search distance of the
  // edge segment's bounding box.
  const double r = settings.search_distance;
  Eigen::Vector3d lo = points.front().first.cwiseMin(points.back().first) - Eigen::Vector3d::Constant(r);
  Eigen::Vector3d hi = points.front().first.cwiseMax(points.back().first) + Eigen::Vector3d::Constant(r);
  struct Candidate {
    std::size_t facet;
    std::array<Eigen::Vector3d, 3> x;
    Eigen::Vector3d lo, hi;
  };
  std::vector<Candidate> candidates;
  for (std::size_t f = 0; f < facets.size(); ++f) {
    Candidate c{f, {x_of(facets[f][0]), x_of(facets[f][1]), x_of(facets[f][2])}, {}, {}};
    c.lo = c.x[0].cwiseMin(c.x[1]).cwiseMin(c.x[2]);
    c.hi = c.x[0].cwiseMax(c.x[1]).cwiseMax(c.x[2]);
    if ((c.lo.array() <= hi.array()).all() && (c.hi.array() >= lo.array()).all()) candidates.push_back(c);
  }

  for (const auto& [p, w] : points) {
    // The nearest facets within the search distance.
    double best = r * r;
    std::vector<std::pair<const Candidate*, PointTriangleDistance>> nearest;
    for (const Candidate& c : candidates) {
      const Eigen::Vector3d gap = (c.lo - p).cwiseMax(p - c.hi).cwiseMax(0.0);
      if (gap.squaredNorm() > best * (1.0 + 1e-9)) continue;
      PointTriangleDistance d = point_triangle_distance(p, c.x[0], c.x[1], c.x[2]);
      const double tie = 1e-9 * best + 1e-30;
      if (d.squared_distance < best - tie) {
        nearest.clear();
        best = d.squared_distance;
      }
      if (d.squared_distance <= best + tie) nearest.emplace_back(&c, std::move(d));
    }
    if (nearest.empty()) continue;
    // Inside: behind every nearest facet, n · (p − x_c) < 0, n = (x1 − x0) × (x2 − x0).
    bool inside = true;
    for (const auto& [c, d] : nearest) {
      const Eigen::Vector3d n = (c->x[1] - c->x[0]).cross(c->x[2] - c->x[0]);
      if (!(n.dot(p - d.closest) < 0.0)) inside = false;
    }
    if (!inside) continue;
    const auto& [c, d] = nearest.front();
    EdgeContactTerm term;
    term.facet = c->facet;
    term.nodes = facets[c->facet];
    term.weight = w;
    term.line_load = settings.line_penalty * std::sqrt(d.squared_distance);
    // W = ½ ε_L w d²: f = −∂W/∂x = −½ ε_L w ∇d², ∂²W/∂x² = ½ ε_L w ∇²d²
    const double k = 0.5 * settings.line_penalty * w;
    term.force_on_body = -k * d.gradient;
    term.stiffness = k * d.hessian;
    for (int i = 0; i < 3; ++i) out.force_on_body += term.force_on_body.segment<3>(3 * i);
    out.terms.push_back(std::move(term));
    ++out.active_points;
    out.contact_length += w;
    out.max_line_load = std::max(out.max_line_load, settings.line_penalty * std::sqrt(d.squared_distance));
  }
  return out;
}

} // namespace kerf::reference
