#include "realtime/voxel/voxel_surface_cutting_model.hpp"

#include "realtime/voxel/cutting_resistance.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace kerf {

namespace {

void require(bool condition, const std::string& what) {
  if (!condition) throw std::invalid_argument("voxel model: " + what);
}

bool positive(double x) { return x > 0.0 && std::isfinite(x); }
bool non_negative(double x) { return x >= 0.0 && std::isfinite(x); }

const VoxelCuttingSetup& checked(const VoxelCuttingSetup& s) {
  require(positive(s.tool_radius), "tool radius must be positive");
  require(positive(s.contact_stiffness), "contact stiffness (elastic coefficient) must be positive");
  require(non_negative(s.damping), "damping must be >= 0");
  require(non_negative(s.friction_coefficient), "friction coefficient must be >= 0");
  require(positive(s.critical_force_depth), "critical force (depth direction) must be positive");
  require(positive(s.critical_force_cutting), "critical force (cutting direction) must be positive");
  require(positive(s.advance_length), "advance length must be positive");
  require(positive(s.regularisation_speed), "regularisation speed must be positive");
  require(!s.clip_friction || positive(s.clip_modulus), "clip friction needs a positive modulus E");
  require(s.centre_offset.allFinite(), "the stick's centre offset must be finite");
  return s;
}

const SurfaceMesh& checked(const SurfaceMesh& s) {
  require(s.vertices.cols() == 3 && s.triangles.cols() == 3 && s.triangles.rows() > 0,
          "the surface needs #V x 3 vertices and at least one triangle");
  require(s.vertices.allFinite(), "the surface has non-finite vertices");
  require(s.triangles.minCoeff() >= 0 && s.triangles.maxCoeff() < s.vertices.rows(),
          "the surface's triangles index outside its vertices");
  return s;
}

std::vector<Eigen::AlignedBox3d> triangle_boxes(const SurfaceMesh& s) {
  std::vector<Eigen::AlignedBox3d> boxes(static_cast<std::size_t>(s.triangles.rows()));
  for (Eigen::Index f = 0; f < s.triangles.rows(); ++f)
    for (int c = 0; c < 3; ++c) boxes[static_cast<std::size_t>(f)].extend(s.vertices.row(s.triangles(f, c)).transpose());
  return boxes;
}

} // namespace

VoxelSurfaceCuttingModel::VoxelSurfaceCuttingModel(SurfaceMesh surface, VoxelCuttingSetup setup)
    : m_setup(checked(setup)),
      m_query(checked(surface)),
      m_original(m_query.surface().vertices),
      m_vertices(m_original),
      m_tree(triangle_boxes(m_query.surface())),
      m_grid(m_setup.grid, m_setup.advance_length, m_setup.triangle_capacity) {}

void VoxelSurfaceCuttingModel::reset() {
  m_vertices = m_original;
  m_slack = 0.0;
  m_episode = false;
  m_grid_incomplete = false;
  m_cut_direction = Eigen::Vector3d::UnitX();
  m_episode_advances = m_episode_cut_advances = 0;
  m_travel = m_travel_at_advance = 0.0;
  m_cut_length = 0.0;
  m_depth_advances = m_total_cut_advances = 0;
  m_last_depth_force = m_last_cutting_force = m_last_depth = 0.0;
}

void VoxelSurfaceCuttingModel::place_grid_around(const Eigen::Vector3d& tip_local, bool keep_overlap) noexcept {
  const int column_u = m_grid.cell_index(tip_local.y()) - m_grid.u_cells() / 2;
  const int column_v = m_grid.cell_index(tip_local.z()) - m_grid.v_cells() / 2;
  const int layer_top = m_grid.cell_index(tip_local.x()) - m_grid.depth_cells() / 2;
  m_grid_incomplete = !m_grid.place(m_frame, column_u, column_v, layer_top, m_vertices,
                                    m_query.surface().triangles, m_tree, m_slack, keep_overlap);
}

void VoxelSurfaceCuttingModel::start_episode(const Eigen::Vector3d& centre, const SurfaceQuery::Closest& contact) noexcept {
  // The contact frame (paper 002 §2.3 step 2): depth into the body along the inward normal;
  // u along the world x axis projected onto the tangent plane (y if x is nearly normal).
  VoxelFrame frame;
  frame.origin = contact.point;
  frame.depth_axis = -contact.normal;
  Eigen::Vector3d u = Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitX().dot(frame.depth_axis) * frame.depth_axis;
  if (u.norm() < 0.5) u = Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitY().dot(frame.depth_axis) * frame.depth_axis;
  frame.u_axis = u.normalized();
  frame.v_axis = frame.depth_axis.cross(frame.u_axis);
  m_frame = frame;
  m_episode = true;
  m_episode_advances = m_episode_cut_advances = 0;
  m_cut_length = 0.0;
  m_travel = m_travel_at_advance = 0.0;
  m_previous_position = centre;
  m_cut_direction = frame.u_axis;
  m_have_cut_direction = false;
  place_grid_around(frame.local(centre + m_setup.tool_radius * frame.depth_axis), false);
}

void VoxelSurfaceCuttingModel::keep_tip_inside_grid(const Eigen::Vector3d& tip) noexcept {
  // Keep the tip well inside the grid: re-centre (keeping the overlap) near its border.
  const int margin_lateral = std::max(1, std::min(m_grid.u_cells(), m_grid.v_cells()) / 4);
  const int layer = m_grid.cell_index(tip.x()) - m_grid.layer_top();
  int i = 0, j = 0;
  const bool inside = m_grid.column_at(tip.y(), tip.z(), i, j);
  const bool lateral_ok = inside && i >= margin_lateral && i < m_grid.u_cells() - margin_lateral &&
                          j >= margin_lateral && j < m_grid.v_cells() - margin_lateral;
  const bool depth_ok = layer >= 1 && layer <= m_grid.depth_cells() - 2;
  if (!lateral_ok || (!depth_ok && m_grid.depth_cells() >= 3)) place_grid_around(tip, true);
}

bool VoxelSurfaceCuttingModel::press_surface_point(const Eigen::Vector3d& tip, int i, int j, const Eigen::Vector3d& velocity,
                                                   double& normal_force) noexcept {
  const VoxelCuttingSetup& s = m_setup;
  bool advanced = false;
  // Depth direction (§2.3 step 3): the tip below its column's surface point by δ_d.
  double delta_d = tip.x() - m_grid.surface_depth(i, j);
  if (delta_d > 0.0) {
    m_last_depth_force = s.contact_stiffness * delta_d;
    if (m_last_depth_force > s.critical_force_depth) { // advance the surface point
      m_slack = std::max(m_slack, m_grid.lower(i, j, m_grid.surface_depth(i, j) + s.advance_length, m_vertices, m_original));
      ++m_depth_advances;
      advanced = true;
      delta_d = tip.x() - m_grid.surface_depth(i, j);
    }
    // F_n = k_e δ_d + λ δ_d dδ_d/dt, never pulling the stick in. The damper acts per unit
    // penetration, so F_n is continuous where the contact begins and ends: an advance that
    // leaves the tip above the new surface point drops the elastic part (at most the critical
    // force plus one sample's increment), and the damping with it only as far as δ_d falls.
    if (delta_d > 0.0)
      normal_force = std::max(0.0, delta_d * (s.contact_stiffness + s.damping * velocity.dot(m_frame.depth_axis)));
  }
  return advanced;
}

bool VoxelSurfaceCuttingModel::press_column_wall(const Eigen::Vector3d& tip, int i, int j, double& wall_force) noexcept {
  const VoxelCuttingSetup& s = m_setup;
  const double h = s.advance_length;
  const double r = s.tool_radius;
  const Eigen::Vector3d& c = m_cut_direction;
  const double c_a = c.dot(m_frame.u_axis), c_b = c.dot(m_frame.v_axis);
  // Cutting direction: the leading point of the stick inside a neighbouring column whose
  // material reaches above the tip is pressed δ_c into that column's wall.
  int i2 = 0, j2 = 0;
  const double lead_a = tip.y() + r * c_a, lead_b = tip.z() + r * c_b;
  if (!(m_have_cut_direction && m_grid.column_at(lead_a, lead_b, i2, j2) && (i2 != i || j2 != j) &&
        m_grid.surface_depth(i2, j2) < tip.x()))
    return false;
  // δ_c: distance from the leading point back along -c to where it entered the column.
  double delta_c = h;
  if (c_a > 1e-12) delta_c = std::min(delta_c, (lead_a - m_grid.a_lower(i2)) / c_a);
  if (c_a < -1e-12) delta_c = std::min(delta_c, (m_grid.a_lower(i2) + h - lead_a) / -c_a);
  if (c_b > 1e-12) delta_c = std::min(delta_c, (lead_b - m_grid.b_lower(j2)) / c_b);
  if (c_b < -1e-12) delta_c = std::min(delta_c, (m_grid.b_lower(j2) + h - lead_b) / -c_b);
  delta_c = std::max(0.0, delta_c);
  m_last_cutting_force = s.contact_stiffness * delta_c;
  if (!(m_last_cutting_force > s.critical_force_cutting)) {
    wall_force = m_last_cutting_force;
    return false;
  }
  // The front advances one column.
  m_slack = std::max(m_slack, m_grid.lower(i2, j2, tip.x(), m_vertices, m_original));
  // A stick wider than a column (r > h: a knife's Cw, docs/models.md, voxel) also clears the
  // columns between its tip and its leading point, which it sweeps on its way: each one
  // whose material reaches above the tip, sampled every half column along c.
  for (double along = 0.5 * h; along < r; along += 0.5 * h) {
    int i3 = 0, j3 = 0;
    if (m_grid.column_at(tip.y() + along * c_a, tip.z() + along * c_b, i3, j3) && (i3 != i || j3 != j) &&
        (i3 != i2 || j3 != j2) && m_grid.surface_depth(i3, j3) < tip.x())
      m_slack = std::max(m_slack, m_grid.lower(i3, j3, tip.x(), m_vertices, m_original));
  }
  if (m_episode_cut_advances++ == 0) m_cut_start = Eigen::Vector2d(tip.y(), tip.z());
  ++m_total_cut_advances;
  return true;
}

InteractionMode VoxelSurfaceCuttingModel::interaction_mode(bool contact, bool forward) const noexcept {
  // Modes (docs/models.md, voxel): deformation-1 before the episode's first advance, cutting
  // while the front keeps up with the moving tool, deformation-2 when pressing without cutting.
  // The front advances once per advance length of travel in steady cutting; 1.5 advance
  // lengths without one is no longer cutting.
  InteractionMode mode = InteractionMode::no_contact;
  if (m_episode_advances == 0) mode = contact ? InteractionMode::deformation_1 : InteractionMode::no_contact;
  else if (forward && m_travel - m_travel_at_advance < 1.5 * m_setup.advance_length) mode = InteractionMode::cutting;
  else if (contact) mode = InteractionMode::deformation_2;
  return mode;
}

void VoxelSurfaceCuttingModel::step(std::span<const ToolState> tools, double /*dt*/, std::span<ForceSample> forces) noexcept {
  ForceSample& out = forces[0];
  out = ForceSample{};
  const VoxelCuttingSetup& s = m_setup;
  const double h = s.advance_length;
  const double r = s.tool_radius;
  const Eigen::Vector3d p = tools[0].position + s.centre_offset; // the stick's centre
  const Eigen::Vector3d velocity = tools[0].velocity.allFinite() ? tools[0].velocity : Eigen::Vector3d::Zero();
  out.crack_extent = m_cut_length;
  m_last_depth_force = m_last_cutting_force = 0.0;
  if (!finite_input(p, m_non_finite)) return;

  // Contact with the body as built: starts an episode (and its grid), or ends one.
  const SurfaceQuery::Closest closest = m_query.closest_point(p);
  if (!m_episode) {
    if (closest.signed_distance >= r) return; // no contact, no grid
    start_episode(p, closest);
  } else if (closest.signed_distance > r + 2.0 * h) {
    m_episode = false; // left the body: the grid goes, the cut stays in the polygon
    return;
  }

  const Eigen::Vector3d& e_d = m_frame.depth_axis;
  const Eigen::Vector3d tip = m_frame.local(p + r * e_d); // (w, a, b) of the stick's tip point
  m_travel += (p - m_previous_position).norm();
  m_previous_position = p;
  keep_tip_inside_grid(tip);
  out.over_budget = m_grid_incomplete;

  // Tangential velocity, the cutting direction, and the regularised direction of resistances.
  const Eigen::Vector3d v_t = velocity - velocity.dot(e_d) * e_d;
  const double speed_t = v_t.norm();
  if (speed_t > s.regularisation_speed) {
    m_cut_direction = v_t / speed_t;
    m_have_cut_direction = true;
  }
  const Eigen::Vector3d resist = -v_t / std::sqrt(speed_t * speed_t + s.regularisation_speed * s.regularisation_speed);

  bool advanced = false;
  double normal_force = 0.0;
  double wall_force = 0.0;
  int i = 0, j = 0;
  if (m_grid.column_at(tip.y(), tip.z(), i, j)) {
    advanced = press_surface_point(tip, i, j, velocity, normal_force);
    if (press_column_wall(tip, i, j, wall_force)) advanced = true;
  }
  if (advanced) {
    ++m_episode_advances;
    m_travel_at_advance = m_travel;
  }
  // Cl: the cut's length in the tangent plane, from the tip where the front first advanced
  // (one advance length long then) to the tip now.
  if (m_episode_cut_advances > 0) m_cut_length = (Eigen::Vector2d(tip.y(), tip.z()) - m_cut_start).norm() + h;

  // Moving forward: deeper, or along the surface.
  const bool contact = normal_force > 0.0 || wall_force > 0.0;
  const bool forward = velocity.dot(e_d) > s.regularisation_speed || speed_t > s.regularisation_speed;
  const InteractionMode mode = interaction_mode(contact, forward);

  m_last_depth = tip.x();
  Eigen::Vector3d force = -normal_force * e_d - wall_force * m_cut_direction;
  if (s.friction) force += s.friction_coefficient * normal_force * resist; // Coulomb, regularised
  if (mode == InteractionMode::cutting) {
    // §2.4: the buried edge's resistances, against the tangential motion.
    if (s.depth_cutting_stiffness) force += depth_cutting_stiffness_force(s.contact_stiffness, tip.x()) * resist;
    if (s.clip_friction) {
      force += clip_friction_force(s.friction_coefficient, s.clip_modulus, r, tip.x(), m_cut_length) * resist;
    }
  }
  write_sample(out, force, mode, m_cut_length, m_non_finite);
}

} // namespace kerf
