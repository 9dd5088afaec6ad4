#include "realtime/edge/discrete_edge_cutting_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kerf {

namespace {

void require(bool condition, const std::string& what) {
  if (!condition) throw std::invalid_argument("edge model: " + what);
}

bool finite_non_negative(double x) { return x >= 0.0 && std::isfinite(x); }

} // namespace

DiscreteEdgeCuttingModel::DiscreteEdgeCuttingModel(CollisionVoxels voxels, DiscreteEdgeSetup setup)
    : m_voxels(std::move(voxels)), m_setup(std::move(setup)) {
  require(std::abs(m_setup.blade.edge_direction.norm() - 1.0) < 1e-9, "edge direction must be a unit vector");
  require(std::abs(m_setup.blade.cutting_direction.norm() - 1.0) < 1e-9, "cutting direction must be a unit vector");
  require(m_setup.blade.edge_length > 0.0 && std::isfinite(m_setup.blade.edge_length), "edge length must be positive");
  require(m_setup.point_count >= 1 && m_setup.point_count <= 100000, "point count K must be in [1, 100000]");
  require(!m_setup.materials.empty(), "at least one material is needed");
  for (const EdgeMaterial& m : m_setup.materials) {
    require(m.stiffness_per_length > 0.0 && std::isfinite(m.stiffness_per_length), "stiffness per length must be positive");
    require(m.shear_limit_per_length > 0.0 && std::isfinite(m.shear_limit_per_length), "shear limit per length must be positive");
    require(finite_non_negative(m.drag_per_length), "drag per length must be >= 0");
  }
  require(finite_non_negative(m_setup.friction_coefficient), "friction coefficient must be >= 0");
  require(finite_non_negative(m_setup.channel_capture_width), "channel capture width must be >= 0");
  m_piece_length = m_setup.blade.edge_length / m_setup.point_count;
  m_points.assign(static_cast<std::size_t>(m_setup.point_count), Point{});
}

void DiscreteEdgeCuttingModel::reset() {
  std::fill(m_points.begin(), m_points.end(), Point{});
  m_have_previous = false;
  m_pass_open = false;
  if (m_cut) m_cut->reset();
}

void DiscreteEdgeCuttingModel::attach_geometric_cut(std::unique_ptr<BackgroundCut> cut, double record_spacing) {
  require(cut != nullptr, "the geometric cut to attach is missing");
  require(record_spacing > 0.0 && std::isfinite(record_spacing), "record spacing must be positive");
  m_cut = std::move(cut);
  m_record_spacing = record_spacing;
  m_pass_open = false;
}

void DiscreteEdgeCuttingModel::finish_geometric_cut() {
  if (!m_cut) return;
  if (m_pass_open) close_pass(m_last_front);
  m_cut->wait_until_idle();
}

void DiscreteEdgeCuttingModel::close_pass(const Eigen::Vector3d& centre) noexcept {
  if (m_cut->recorded() == 0 || m_last_front != m_cut->last_recorded()) m_cut->record(m_last_front);
  if ((centre - m_last_front).dot(m_pass_inward) > 0.0) m_cut->record(centre); // on through the body
  m_cut->submit();
  m_pass_open = false;
}

void DiscreteEdgeCuttingModel::record_pass(const Eigen::Vector3d& centre, bool any_contact, int cut_points,
                                           const Eigen::Vector3d& entry, const Eigen::Vector3d& front,
                                           const Eigen::Vector3d& inward) noexcept {
  if (cut_points > 0) {
    if (!m_pass_open) {
      m_cut->record(entry);
      m_pass_open = true;
      m_pass_inward = inward;
    }
    if (m_cut->recorded() == 0 || (front - m_cut->last_recorded()).norm() >= m_record_spacing) m_cut->record(front);
    m_last_front = front;
  }
  if (m_pass_open && !any_contact) close_pass(centre);
}

double DiscreteEdgeCuttingModel::point_stiffness(int region) const {
  return m_setup.materials.at(static_cast<std::size_t>(region)).stiffness_per_length * m_piece_length;
}
double DiscreteEdgeCuttingModel::point_shear_limit(int region) const {
  return m_setup.materials.at(static_cast<std::size_t>(region)).shear_limit_per_length * m_piece_length;
}
double DiscreteEdgeCuttingModel::point_drag(int region) const {
  return m_setup.materials.at(static_cast<std::size_t>(region)).drag_per_length * m_piece_length;
}

Eigen::Vector3d DiscreteEdgeCuttingModel::entry_point(const Eigen::Vector3d& outside,
                                                      const Eigen::Vector3d& inside) const noexcept {
  Eigen::Vector3d out = outside, in = inside;
  for (int k = 0; k < 60; ++k) {
    const Eigen::Vector3d mid = 0.5 * (out + in);
    if (m_voxels.marked(mid)) in = mid;
    else out = mid;
  }
  return in;
}

void DiscreteEdgeCuttingModel::update_point(Point& point, const Eigen::Vector3d& p, const Eigen::Vector3d& velocity,
                                            bool have_previous) noexcept {
  const Eigen::Vector3d previous = point.present;
  point.present = p;
  point.force.setZero();
  point.cutting = false;
  const int region = m_voxels.region_at(p);
  point.region = region;
  if (region < 0 || region >= static_cast<int>(m_setup.materials.size())) { // §3.3: not in a marked voxel
    point.in_contact = false;
    return;
  }

  if (!point.in_contact) {
    // A new collision: the relaxed point is where the edge entered the undeformed object.
    const Eigen::Vector3d motion = have_previous ? Eigen::Vector3d(p - previous) : Eigen::Vector3d::Zero();
    const double length = motion.norm();
    const Eigen::Vector3d n = length > 0.0 ? Eigen::Vector3d(motion / length) : m_setup.blade.cutting_direction;
    const Eigen::Vector3d surface = have_previous && !m_voxels.marked(previous) ? entry_point(previous, p) : p;
    bool in_channel = false;
    if (point.has_cut) { // back into the cut this point made: the material starts at its front
      const Eigen::Vector3d w = surface - point.entry;
      const double along = w.dot(point.inward);
      const double across = (w - along * point.inward).norm();
      const double capture = m_setup.channel_capture_width;
      in_channel = across <= capture && along >= -capture && along <= point.depth + capture;
    }
    if (in_channel) {
      point.relaxed = point.entry + point.depth * point.inward;
    } else {
      point.relaxed = surface;
      point.entry = surface;
      point.inward = n;
      point.depth = 0.0;
      point.has_cut = false;
    }
    point.in_contact = true;
  }

  const EdgeMaterial& material = m_setup.materials[static_cast<std::size_t>(region)];
  const double k = material.stiffness_per_length * m_piece_length;
  const double shear_limit = material.shear_limit_per_length * m_piece_length;
  const double b = material.drag_per_length * m_piece_length;
  const Eigen::Vector3d& e = m_setup.blade.edge_direction;

  Eigen::Vector3d elastic = Eigen::Vector3d::Zero();
  const Eigen::Vector3d d = p - point.relaxed; // the deformation: disparity of present and relaxed points
  if (d.dot(point.inward) > 0.0) {             // else slack: behind the relaxed point, inside the cut
    double d_axial = d.dot(e);
    Eigen::Vector3d d_normal = d - d_axial * e;
    double d_normal_length = d_normal.norm();
    // Cutting resistance: k |d_n| <= F_s; beyond it the material is destroyed and the relaxed
    // point advances along d_n until k |d_n| = F_s.
    if (k * d_normal_length > shear_limit) {
      const double kept = shear_limit / k;
      const Eigen::Vector3d unit = d_normal / d_normal_length;
      point.relaxed += (d_normal_length - kept) * unit;
      d_normal = kept * unit;
      d_normal_length = kept;
      point.cutting = true;
      point.has_cut = true;
      point.depth = std::max(point.depth, (point.relaxed - point.entry).dot(point.inward));
    }
    // Friction along the edge (non-destructive): k |d_a| <= μ k |d_n|; beyond it the relaxed
    // point slides along e.
    const double limit = m_setup.friction_coefficient * d_normal_length;
    if (std::abs(d_axial) > limit) {
      const double kept = std::copysign(limit, d_axial);
      point.relaxed += (d_axial - kept) * e;
      d_axial = kept;
    }
    // f = -k (p - r)
    elastic = -k * (d_normal + d_axial * e);
  }
  // Viscous drag: f = -b v.
  point.force = elastic - b * velocity;
}

void DiscreteEdgeCuttingModel::step(std::span<const ToolState> tools, double /*dt*/,
                                    std::span<ForceSample> forces) noexcept {
  ForceSample& out = forces[0];
  out = ForceSample{};
  const Eigen::Vector3d c = tools[0].position;
  const Eigen::Vector3d v = tools[0].velocity.allFinite() ? tools[0].velocity : Eigen::Vector3d::Zero();
  if (!finite_input(c, m_non_finite)) return;
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  bool any_cutting = false, any_fresh = false, any_in_cut = false;
  double crack_extent = 0.0;
  bool any_contact = false;
  int cut_points = 0;
  Eigen::Vector3d entry = Eigen::Vector3d::Zero(), front = Eigen::Vector3d::Zero(), inward = Eigen::Vector3d::Zero();
  const double half = 0.5 * m_setup.blade.edge_length;
  for (std::size_t i = 0; i < m_points.size(); ++i) {
    // p_i = c + s_i e, s_i the midpoint of the i-th of K equal pieces.
    const double s = -half + (static_cast<double>(i) + 0.5) * m_piece_length;
    Point& point = m_points[i];
    update_point(point, c + s * m_setup.blade.edge_direction, v, m_have_previous);
    total += point.force;
    any_cutting = any_cutting || point.cutting;
    if (point.in_contact) {
      if (point.has_cut) any_in_cut = true;
      else any_fresh = true;
    }
    if (point.has_cut) crack_extent = std::max(crack_extent, point.depth);
    any_contact = any_contact || point.in_contact;
    if (point.in_contact && point.has_cut) { // the crack front and its entry, referred to the edge's centre
      ++cut_points;
      entry += point.entry - s * m_setup.blade.edge_direction;
      front += point.relaxed - s * m_setup.blade.edge_direction;
      inward += point.inward;
    }
  }
  m_have_previous = true;
  if (m_cut && total.allFinite()) {
    if (cut_points > 0) {
      entry /= cut_points;
      front /= cut_points;
      inward.normalize();
    }
    record_pass(c, any_contact, any_cutting ? cut_points : 0, entry, front, inward);
  }

  const InteractionMode mode = any_cutting ? InteractionMode::cutting
                              : any_fresh ? InteractionMode::deformation_1
                              : any_in_cut ? InteractionMode::deformation_2
                                           : InteractionMode::no_contact;
  write_sample(out, total, mode, crack_extent, m_non_finite);
}

} // namespace kerf
