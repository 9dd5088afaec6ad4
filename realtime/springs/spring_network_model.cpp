#include "realtime/springs/spring_network_model.hpp"

#include "meshes/surface_mesh.hpp"
#include "realtime/springs/compliant_grasp.hpp"
#include "realtime/springs/symplectic_euler.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kerf {

std::string_view to_string(SpringIntegrator integrator) {
  switch (integrator) {
  case SpringIntegrator::symplectic_euler: return "explicit";
  case SpringIntegrator::implicit_euler: return "implicit";
  case SpringIntegrator::quasi_static: return "static";
  case SpringIntegrator::linearly_implicit_euler: return "linear-implicit";
  }
  return "explicit";
}

std::optional<SpringIntegrator> spring_integrator_from_string(std::string_view name) {
  if (name == "explicit") return SpringIntegrator::symplectic_euler;
  if (name == "implicit") return SpringIntegrator::implicit_euler;
  if (name == "static") return SpringIntegrator::quasi_static;
  if (name == "linear-implicit") return SpringIntegrator::linearly_implicit_euler;
  return std::nullopt;
}

namespace {

/// Safety factor on the computed explicit limit (the limit is for the linearised network).
constexpr double explicit_safety = 0.9;
/// Relative Newton tolerance of the implicit and quasi-static integrators (NewtonStepper): the
/// residual's max-norm <= 10⁻⁵ k₁ h, the force of an edge spring stretched by 10⁻⁵ of its length
/// (4·10⁻⁶ N on the clay scenes' 2.5 mm cells, against stylus forces of 0.1-10 N). At 10⁻⁷ (the
/// previous value) the 1 ms implicit step took two or three kept-factor iterations where one
/// now suffices (experiments/benchmarks/bench_springs.cpp; docs/spring-network.md §2).
constexpr double newton_tolerance = 1e-5;
/// Sub-steps beyond this in one sample are reported as over budget.
constexpr int max_substeps = 100000;

/// Nodes of `net` within `tolerance` of a triangle of `group`: distance to the triangle's plane
/// within tolerance and the projection inside the triangle's box grown by the tolerance.
std::vector<bool> nodes_on_surface(const SpringNetwork& net, const TetMesh& mesh, const SurfaceGroup& group,
                                   double tolerance) {
  std::vector<bool> on(static_cast<std::size_t>(net.node_count), false);
  for (int t = 0; t < group.triangles.rows(); ++t) {
    const Eigen::Vector3d a = mesh.nodes.row(group.triangles(t, 0)).transpose();
    const Eigen::Vector3d b = mesh.nodes.row(group.triangles(t, 1)).transpose();
    const Eigen::Vector3d c = mesh.nodes.row(group.triangles(t, 2)).transpose();
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    const Eigen::Vector3d lo = a.cwiseMin(b).cwiseMin(c).array() - tolerance;
    const Eigen::Vector3d hi = a.cwiseMax(b).cwiseMax(c).array() + tolerance;
    for (int p = 0; p < net.node_count; ++p) {
      const Eigen::Vector3d q = net.rest.col(p);
      if (std::abs((q - a).dot(n)) <= tolerance && (q.array() >= lo.array()).all() && (q.array() <= hi.array()).all())
        on[static_cast<std::size_t>(p)] = true;
    }
  }
  return on;
}

/// Point-in-body against the tetrahedra themselves, bucketed on the block's grid grown by one
/// cell on each side (the only region the construction asks about).
class BodyContainment {
public:
  BodyContainment(const TetMesh& mesh, const NetworkBlock& block) : m_mesh(mesh), m_block(block) {
    m_dims = block.cells + Eigen::Vector3i::Constant(2);
    m_buckets.resize(static_cast<std::size_t>(m_dims.prod()));
    for (int t = 0; t < mesh.tets.rows(); ++t) {
      Eigen::Vector3d lo = mesh.nodes.row(mesh.tets(t, 0)).transpose(), hi = lo;
      for (int k = 1; k < 4; ++k) {
        lo = lo.cwiseMin(mesh.nodes.row(mesh.tets(t, k)).transpose());
        hi = hi.cwiseMax(mesh.nodes.row(mesh.tets(t, k)).transpose());
      }
      const Eigen::Vector3i a = bucket(lo), b = bucket(hi);
      if ((b.array() < 0).any() || (a.array() >= m_dims.array()).any()) continue;
      const Eigen::Vector3i a0 = a.cwiseMax(0), b0 = b.cwiseMin(m_dims - Eigen::Vector3i::Ones());
      for (int k = a0.z(); k <= b0.z(); ++k)
        for (int j = a0.y(); j <= b0.y(); ++j)
          for (int i = a0.x(); i <= b0.x(); ++i) m_buckets[static_cast<std::size_t>(i + m_dims.x() * (j + m_dims.y() * k))].push_back(t);
    }
  }
  /// True if p lies in a tetrahedron (barycentric coordinates >= −1e-12).
  bool contains(const Eigen::Vector3d& p) const {
    const Eigen::Vector3i g = bucket(p);
    if ((g.array() < 0).any() || (g.array() >= m_dims.array()).any()) return false;
    for (int t : m_buckets[static_cast<std::size_t>(g.x() + m_dims.x() * (g.y() + m_dims.y() * g.z()))]) {
      const Eigen::Vector3d a = m_mesh.nodes.row(m_mesh.tets(t, 0)).transpose();
      Eigen::Matrix3d T;
      for (int k = 0; k < 3; ++k) T.col(k) = m_mesh.nodes.row(m_mesh.tets(t, k + 1)).transpose() - a;
      const Eigen::Vector3d l = T.lu().solve(p - a);
      if (l.minCoeff() >= -1e-12 && l.sum() <= 1.0 + 1e-12) return true;
    }
    return false;
  }

private:
  Eigen::Vector3i bucket(const Eigen::Vector3d& p) const {
    return ((p - m_block.origin) / m_block.cell_size).array().floor().cast<int>() + 1;
  }
  const TetMesh& m_mesh;
  NetworkBlock m_block;
  Eigen::Vector3i m_dims;
  std::vector<std::vector<int>> m_buckets;
};

/// The coordinate axis a sliding support's triangles are normal to; throws if they are not.
int support_axis(const TetMesh& mesh, const SurfaceGroup& group) {
  Eigen::Vector3d weight = Eigen::Vector3d::Zero();
  for (int t = 0; t < group.triangles.rows(); ++t) {
    const Eigen::Vector3d a = mesh.nodes.row(group.triangles(t, 0)).transpose();
    const Eigen::Vector3d b = mesh.nodes.row(group.triangles(t, 1)).transpose();
    const Eigen::Vector3d c = mesh.nodes.row(group.triangles(t, 2)).transpose();
    const Eigen::Vector3d n = (b - a).cross(c - a);
    weight += n.cwiseAbs();
  }
  int axis = 0;
  weight.maxCoeff(&axis);
  if (weight[axis] < 0.999 * weight.sum())
    throw std::invalid_argument("springs: sliding support \"" + group.name +
                                "\" is not normal to a coordinate axis (only axis-aligned sliding supports are represented)");
  return axis;
}


/// The point of the body's surface nearest each stylus's start, and the surface's normal there.
struct StylusContacts {
  std::vector<Eigen::Vector3d> point, normal;
};

StylusContacts stylus_contacts(const SurfaceQuery& body, const std::vector<SpringStylus>& styluses) {
  StylusContacts contacts;
  for (const SpringStylus& t : styluses) {
    const SurfaceQuery::Closest closest = body.closest_point(t.start);
    contacts.point.push_back(closest.point);
    contacts.normal.push_back(closest.normal);
  }
  return contacts;
}

/// The block of s.cells³ cells of side h around the contact points, inside the body's box where
/// it fits: h = s.cell_size, or automatic, the larger of the box's smallest side and the tools'
/// reach (the contacts' spread, twice; a blade's edge span within the box) over s.cells.
NetworkBlock block_around_contacts(const TetMesh& mesh, const SpringNetworkSetup& s, const std::vector<Eigen::Vector3d>& contact) {
  const Eigen::Vector3d box_lo = mesh.nodes.colwise().minCoeff().transpose();
  const Eigen::Vector3d box_hi = mesh.nodes.colwise().maxCoeff().transpose();
  const Eigen::Vector3d extent = box_hi - box_lo;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& c : contact) centre += c / static_cast<double>(contact.size());
  double spread = 0.0;
  for (const auto& a : contact)
    for (const auto& b : contact) spread = std::max(spread, (a - b).norm());
  // A blade's reach: its edge's span within the body's box.
  double reach = 2.0 * spread;
  for (const SpringStylus& t : s.styluses)
    if (t.blade) reach = std::max(reach, std::min(t.blade->edge_length, extent.dot(t.blade->edge_direction.cwiseAbs())));
  const double h = s.cell_size > 0.0 ? s.cell_size : std::max(extent.minCoeff(), reach) / s.cells;
  const double side = h * s.cells;
  NetworkBlock block;
  block.cell_size = h;
  block.cells = Eigen::Vector3i::Constant(s.cells);
  for (int i = 0; i < 3; ++i)
    block.origin[i] = side >= extent[i] ? box_lo[i] : std::clamp(centre[i] - 0.5 * side, box_lo[i], box_hi[i] - side);
  return block;
}

/// Pruning: the cells mostly inside the body, at least five of their centre and eight inner
/// points (at a quarter of the cell from each corner) inside a tetrahedron.
std::vector<bool> cells_inside_body(const BodyContainment& inside_body, const NetworkBlock& block) {
  const int cells = block.cells.x();
  const double h = block.cell_size;
  std::vector<bool> keep(static_cast<std::size_t>(block.cells.prod()), false);
  for (int k = 0; k < cells; ++k)
    for (int j = 0; j < cells; ++j)
      for (int i = 0; i < cells; ++i) {
        const Eigen::Vector3d lo = block.origin + h * Eigen::Vector3d(i, j, k);
        int inside = inside_body.contains(lo + Eigen::Vector3d::Constant(0.5 * h)) ? 1 : 0;
        for (int a = 0; a < 8; ++a)
          inside += inside_body.contains(lo + h * Eigen::Vector3d(0.25 + 0.5 * (a & 1), 0.25 + 0.5 * ((a >> 1) & 1), 0.25 + 0.5 * ((a >> 2) & 1))) ? 1 : 0;
        keep[static_cast<std::size_t>(i + cells * (j + cells * k))] = inside >= 5;
      }
  return keep;
}

/// Supports: the nodes within h/4 of a support surface are fixed (a sliding support: along the
/// axis its triangles are normal to).
void constrain_supports(SpringNetwork& net, const TetMesh& mesh, const std::vector<SpringSupport>& supports, double h) {
  for (const SpringSupport& support : supports) {
    const SurfaceGroup* group = mesh.find_surface_group(support.surface);
    if (!group) throw std::invalid_argument("springs: support surface \"" + support.surface + "\" is not in the mesh");
    const std::uint8_t bits = support.sliding ? static_cast<std::uint8_t>(1u << support_axis(mesh, *group)) : static_cast<std::uint8_t>(fix_all);
    const std::vector<bool> on = nodes_on_surface(net, mesh, *group, 0.25 * h);
    for (int p = 0; p < net.node_count; ++p)
      if (on[static_cast<std::size_t>(p)]) net.constraint[static_cast<std::size_t>(p)] |= bits;
  }
}

/// The block's faces inside the body: a node on a face of the block is fixed when the point
/// h/2 outside the block from it lies in the body (the network is cut out of it there).
void fix_faces_inside_body(SpringNetwork& net, const BodyContainment& inside_body, const NetworkBlock& block) {
  const double h = block.cell_size;
  const int cells = block.cells.x();
  for (int p = 0; p < net.node_count; ++p) {
    const Eigen::Vector3d grid = (net.rest.col(p) - block.origin) / h;
    for (int i = 0; i < 3; ++i) {
      const double sign = std::abs(grid[i]) < 1e-9 ? -1.0 : std::abs(grid[i] - cells) < 1e-9 ? 1.0 : 0.0;
      if (sign != 0.0 && inside_body.contains(net.rest.col(p) + 0.5 * h * sign * Eigen::Vector3d::Unit(i)))
        net.constraint[static_cast<std::size_t>(p)] = fix_all;
    }
  }
}

/// A compliant grasp of stylus `tool`: the layer on the disc around the contact point, lumped
/// onto anchors that start at their nodes (d − u = 0 at rest).
void anchor_grasp_layer(SpringNetwork& net, const GraspLayer& layer, int tool, std::vector<int>& anchor_tool) {
  const LumpedGraspLayer lumped = lump_grasp_layer(net, layer);
  for (std::size_t i = 0; i < lumped.node.size(); ++i) {
    net.anchors.node.push_back(lumped.node[i]);
    net.anchors.stiffness.push_back(lumped.stiffness[i]);
    anchor_tool.push_back(tool);
  }
}

/// A blade (stylus `tool`): the nodes under the edge, within its span and h/2 of its plane,
/// ahead of it along the cutting direction c; the first layer the edge meets is attached, each
/// with its gap g ≥ 0 along c.
void attach_under_blade(const SpringNetwork& net, const SpringStylus& stylus, int tool, double h, std::vector<int>& attached_to,
                        std::vector<double>& gap) {
  const Eigen::Vector3d& e = stylus.blade->edge_direction;
  const Eigen::Vector3d& c = stylus.blade->cutting_direction;
  const Eigen::Vector3d lateral = c.cross(e);
  const double tolerance = 1e-9 * h;
  std::vector<int> under;
  double first = INFINITY;
  for (int p = 0; p < net.node_count; ++p) {
    const Eigen::Vector3d u = net.rest.col(p) - stylus.start;
    if (std::abs(u.dot(e)) <= 0.5 * stylus.blade->edge_length + tolerance && std::abs(u.dot(lateral)) <= 0.5 * h + tolerance &&
        u.dot(c) >= -tolerance) {
      under.push_back(p);
      first = std::min(first, u.dot(c));
    }
  }
  // The first layer the edge meets.
  for (int p : under)
    if (const double g = (net.rest.col(p) - stylus.start).dot(c); g <= first + 0.5 * h) {
      attached_to[static_cast<std::size_t>(p)] = tool;
      gap[static_cast<std::size_t>(p)] = std::max(g, 0.0);
    }
  if (under.empty()) throw std::invalid_argument("springs: no network node lies under the blade's edge");
}

/// A rigid stylus tip (stylus `tool`): the nodes not yet attached within `radius` of its start,
/// or the nearest one if none is.
void attach_under_tip(const SpringNetwork& net, const SpringStylus& stylus, int tool, double radius, std::vector<int>& attached_to) {
  int nearest = -1;
  double nearest_distance = INFINITY;
  int count = 0;
  for (int p = 0; p < net.node_count; ++p) {
    if (attached_to[static_cast<std::size_t>(p)] >= 0) continue;
    const double d = (net.rest.col(p) - stylus.start).norm();
    if (d < nearest_distance) nearest_distance = d, nearest = p;
    if (d <= radius) {
      attached_to[static_cast<std::size_t>(p)] = tool;
      ++count;
    }
  }
  if (count == 0 && nearest >= 0) attached_to[static_cast<std::size_t>(nearest)] = tool;
}

} // namespace

SpringNetworkModel::SpringNetworkModel(const TetMesh& mesh, SpringNetworkSetup setup) : m_setup(std::move(setup)) {
  const SpringNetworkSetup& s = m_setup;
  if (s.styluses.empty() || s.styluses.size() > 2)
    throw std::invalid_argument("springs: needs one or two styluses, got " + std::to_string(s.styluses.size()));
  for (const SpringStylus& t : s.styluses) {
    if (!(t.grasp_stiffness >= 0.0)) throw std::invalid_argument("springs: a stylus's grasp stiffness must be >= 0 N/m^3 (0: rigid)");
    if (t.grasp_stiffness > 0.0 && (t.blade || !(t.grasp_disc_radius > 0.0)))
      throw std::invalid_argument("springs: a compliant grasp (grasp stiffness > 0) needs a stylus with a grasp disc radius > 0 m");
  }
  for (const SpringStylus& t : s.styluses)
    if (t.blade) {
      if (s.styluses.size() != 1) throw std::invalid_argument("springs: a blade is taken alone (one tool)");
      const BladeShape& b = *t.blade;
      if (!(b.edge_length > 0.0)) throw std::invalid_argument("springs: the blade's edge length must be > 0 m");
      if (std::abs(b.edge_direction.norm() - 1.0) > 1e-9 || std::abs(b.cutting_direction.norm() - 1.0) > 1e-9 ||
          std::abs(b.edge_direction.dot(b.cutting_direction)) > 1e-9)
        throw std::invalid_argument("springs: the blade's edge and cutting directions must be orthogonal unit vectors");
    }
  if (s.cells < 1) throw std::invalid_argument("springs: cells per block side must be >= 1, got " + std::to_string(s.cells));
  if (!(s.cell_size >= 0.0)) throw std::invalid_argument("springs: cell size must be >= 0 (0: automatic)");
  if (!(s.damping >= 0.0)) throw std::invalid_argument("springs: damping must be >= 0 Pa s");
  if (!(s.grasp_radius >= 0.0)) throw std::invalid_argument("springs: grasp radius must be >= 0 m (0: automatic)");
  if (s.tearing && !(s.tensile_limit > 0.0)) throw std::invalid_argument("springs: tearing needs a tensile limit > 0 Pa");
  if (mesh.tets.rows() == 0) throw std::invalid_argument("springs: the mesh has no tetrahedra");
  build(mesh);
  reset();
}

void SpringNetworkModel::build(const TetMesh& mesh) {
  const SpringNetworkSetup& s = m_setup;
  // 1. The block around the contact points.
  const StylusContacts contacts = stylus_contacts(SurfaceQuery(boundary_surface(mesh)), s.styluses);
  const NetworkBlock block = block_around_contacts(mesh, s, contacts.point);
  const double h = block.cell_size;

  // 2. Pruning: keep the cells mostly inside the body (point-in-tetrahedron on the mesh).
  const BodyContainment inside_body(mesh, block);
  const std::vector<bool> keep = cells_inside_body(inside_body, block);
  const bool volume = s.volume_term && s.poisson_ratio >= 0.25;
  m_identification = identify_cell_stiffness(s.youngs_modulus, s.poisson_ratio, h, volume);
  if (!(s.density > 0.0)) throw std::invalid_argument("springs: density must be > 0 kg/m^3");
  SpringNetwork net = build_spring_network(block, keep, m_identification.stiffness, s.density, s.damping / s.youngs_modulus);

  // 3. Supports, and the block's faces inside the body.
  constrain_supports(net, mesh, s.supports, h);
  fix_faces_inside_body(net, inside_body, block);

  // 4. Nodes under each stylus tip are attached to it.
  attach_to_styluses(net, contacts.point, contacts.normal, h);

  m_initial = std::move(net);
  m_omega_max = highest_angular_frequency(m_initial);
  m_stability_limit = symplectic_euler_stability_limit(m_omega_max, m_initial.damping_time);
  m_lattice = LatticeForces(m_initial);
  m_gershgorin_work.assign(static_cast<std::size_t>(m_initial.node_capacity()), 0.0);
  m_gershgorin_rest = gershgorin_frequency_bound(m_initial, m_initial.rest, m_gershgorin_work);
}

void SpringNetworkModel::attach_to_styluses(SpringNetwork& net, const std::vector<Eigen::Vector3d>& contact,
                                            const std::vector<Eigen::Vector3d>& contact_normal, double h) {
  const SpringNetworkSetup& s = m_setup;
  m_attached_to.assign(static_cast<std::size_t>(net.node_capacity()), -1);
  m_gap.assign(static_cast<std::size_t>(net.node_capacity()), 0.0);
  m_anchor_tool.clear();
  net.anchors = NodeAnchors{};
  for (int t = 0; t < static_cast<int>(s.styluses.size()); ++t) {
    const SpringStylus& stylus = s.styluses[static_cast<std::size_t>(t)];
    if (stylus.grasp_stiffness > 0.0)
      anchor_grasp_layer(net,
                         GraspLayer{contact[static_cast<std::size_t>(t)], contact_normal[static_cast<std::size_t>(t)], stylus.grasp_disc_radius,
                                    stylus.grasp_stiffness},
                         t, m_anchor_tool);
    else if (stylus.blade)
      attach_under_blade(net, stylus, t, h, m_attached_to, m_gap);
    else
      attach_under_tip(net, stylus, t, s.grasp_radius > 0.0 ? s.grasp_radius : stylus.radius + 0.5 * h, m_attached_to);
  }
  for (int p = 0; p < net.node_count; ++p)
    if (m_attached_to[static_cast<std::size_t>(p)] >= 0) net.constraint[static_cast<std::size_t>(p)] = fix_all;
  m_attached.clear();
  for (int p = 0; p < net.node_count; ++p)
    if (m_attached_to[static_cast<std::size_t>(p)] >= 0) m_attached.push_back(p);
  m_tool_cells.clear();
  for (int cell = 0; cell < net.cell_count(); ++cell)
    for (const int p : net.cell_nodes[static_cast<std::size_t>(cell)])
      if (m_attached_to[static_cast<std::size_t>(p)] >= 0) {
        m_tool_cells.push_back(cell);
        break;
      }
  net.anchors.position.resize(3, net.anchors.count());
  for (int i = 0; i < net.anchors.count(); ++i) net.anchors.position.col(i) = net.rest.col(net.anchors.node[static_cast<std::size_t>(i)]);
  net.anchors.velocity.setZero(3, net.anchors.count());
  m_excluded.assign(static_cast<std::size_t>(net.node_capacity()), 0);
  for (int p = 0; p < net.node_count; ++p) m_excluded[static_cast<std::size_t>(p)] = m_attached_to[static_cast<std::size_t>(p)] >= 0;
  for (const int p : net.anchors.node) m_excluded[static_cast<std::size_t>(p)] = 1; // anchored nodes are not split
}

int SpringNetworkModel::attached_nodes(int stylus) const {
  return static_cast<int>(std::count(m_attached_to.begin(), m_attached_to.end(), stylus));
}

int SpringNetworkModel::anchored_nodes(int stylus) const {
  return static_cast<int>(std::count(m_anchor_tool.begin(), m_anchor_tool.end(), stylus));
}

double SpringNetworkModel::anchor_stiffness(int stylus) const {
  double sum = 0.0;
  for (std::size_t i = 0; i < m_anchor_tool.size(); ++i)
    if (m_anchor_tool[i] == stylus) sum += m_initial.anchors.stiffness[i];
  return sum;
}

void SpringNetworkModel::reset() {
  m_net = m_initial;
  const int cap = m_net.node_capacity();
  m_x = m_net.rest;
  m_v.setZero(3, cap);
  m_f.setZero(3, cap);
  m_last_tool.assign(m_setup.styluses.size(), Eigen::Vector3d::Zero());
  m_started = false;
  m_tears = 0;
  m_factorisations = 0;
  m_last_substeps = 0;
  m_piece_parent.assign(static_cast<std::size_t>(cap), 0);
  m_piece_label.assign(static_cast<std::size_t>(m_net.cell_count()), 0);
  m_pieces = network_pieces(m_net, m_piece_parent, m_piece_label);
  m_refreshes = 0;
  m_most_take_up_corrections = 0;
  m_held = 0;
  m_unconverged = 0;
  m_newton.reset();
  if (m_setup.integrator == SpringIntegrator::implicit_euler)
    m_newton = std::make_unique<NewtonStepper>(m_net, NewtonStepper::Mode::implicit_euler, 8, newton_tolerance, m_setup.tearing,
                                               m_setup.refresh);
  else if (m_setup.integrator == SpringIntegrator::quasi_static)
    m_newton = std::make_unique<NewtonStepper>(m_net, NewtonStepper::Mode::quasi_static, 30, newton_tolerance, m_setup.tearing);
  else if (m_setup.integrator == SpringIntegrator::linearly_implicit_euler)
    m_newton = std::make_unique<NewtonStepper>(m_net, NewtonStepper::Mode::linearly_implicit_euler, 1, newton_tolerance,
                                               m_setup.tearing, m_setup.refresh);
  // The servo integrators' first factor, here rather than in the first step.
  if (m_newton && m_setup.integrator != SpringIntegrator::quasi_static && !(m_setup.expected_dt > 0.0 && m_newton->prime(m_net, m_x, m_setup.expected_dt)))
    throw std::runtime_error("springs: the network's matrix at rest did not factorise");
  m_tearing = m_setup.tearing ? std::make_unique<VertexTearing>(m_net, m_setup.tensile_limit) : nullptr;
}

// Attached node target: rest + (tool position − stylus start), at fraction s of the sample.
void SpringNetworkModel::place_attached(std::span<const ToolState> tools, double s, double dt) noexcept {
  const bool quasi_static = m_setup.integrator == SpringIntegrator::quasi_static;
  for (const int p : m_attached) {
    const int t = m_attached_to[static_cast<std::size_t>(p)];
    const Eigen::Vector3d& from = m_last_tool[static_cast<std::size_t>(t)];
    const Eigen::Vector3d& to = tools[static_cast<std::size_t>(t)].position;
    const SpringStylus& tool = m_setup.styluses[static_cast<std::size_t>(t)];
    if (tool.blade) {
      // x = X + c max(0, (p − p₀)·c − g): the node stays until the edge reaches it.
      const Eigen::Vector3d& c = tool.blade->cutting_direction;
      const double gap = m_gap[static_cast<std::size_t>(p)];
      const auto push = [&](const Eigen::Vector3d& at) { return std::max(0.0, (at - tool.start).dot(c) - gap); };
      m_x.col(p) = m_net.rest.col(p) + push(from + s * (to - from)) * c;
      m_v.col(p) = (push(to) - push(from)) / dt * c;
      continue;
    }
    const Eigen::Vector3d target = m_net.rest.col(p) + (from + s * (to - from)) - tool.start;
    m_v.col(p) = (to - from) / dt;
    m_x.col(p) = target;
  }
  // A compliant grasp's anchors: a_p = X_p + d, d the stylus's displacement since its start.
  NodeAnchors& anchors = m_net.anchors;
  for (int i = 0; i < anchors.count(); ++i) {
    const int t = m_anchor_tool[static_cast<std::size_t>(i)];
    const Eigen::Vector3d& from = m_last_tool[static_cast<std::size_t>(t)];
    const Eigen::Vector3d& to = tools[static_cast<std::size_t>(t)].position;
    anchors.position.col(i) =
        m_net.rest.col(anchors.node[static_cast<std::size_t>(i)]) + (from + s * (to - from)) - m_setup.styluses[static_cast<std::size_t>(t)].start;
    // Quasi-static equilibrium has no rates (the forces are taken at zero velocity).
    anchors.velocity.col(i) = quasi_static ? Eigen::Vector3d::Zero() : Eigen::Vector3d((to - from) / dt);
  }
}

bool SpringNetworkModel::advance_explicit(std::span<const ToolState> tools, double dt) noexcept {
  bool over_budget = false;
  // The rest-state limit, shortened when the deformed tangent's Gershgorin bound has grown
  // (crushed springs, stretched cells): h_crit √(G_rest / G_now).
  const bool on_lattice = m_lattice.applies(m_net);
  const double g_now = on_lattice ? m_lattice.gershgorin_bound(m_net, m_x) : gershgorin_frequency_bound(m_net, m_x, m_gershgorin_work);
  const double limit = m_stability_limit * std::sqrt(std::min(1.0, m_gershgorin_rest / std::max(g_now, 1e-300)));
  const double ratio = dt / (explicit_safety * limit);
  int substeps = std::isfinite(ratio) ? static_cast<int>(std::ceil(ratio)) : 1;
  if (substeps > max_substeps) substeps = max_substeps, over_budget = true;
  substeps = std::max(substeps, 1);
  const double h = dt / substeps;
  if (on_lattice) {
    // Untorn: the state stays in the lattice's arrays across the sub-steps.
    m_lattice.gather(m_x, m_v);
    for (int k = 1; k <= substeps; ++k) {
      place_attached(tools, static_cast<double>(k) / substeps, dt);
      for (const int p : m_attached) m_lattice.place(p, m_x.col(p), m_v.col(p));
      m_lattice.substep(m_net, h, m_setup.single_precision_forces ? LatticeForces::ForcePrecision::single_precision
                                                                  : LatticeForces::ForcePrecision::double_precision);
    }
    m_lattice.scatter(m_x, m_v);
  } else {
    for (int k = 1; k <= substeps; ++k) {
      place_attached(tools, static_cast<double>(k) / substeps, dt);
      symplectic_euler_step(m_net, m_x, m_v, h, m_lattice, m_f);
    }
  }
  m_last_substeps = substeps;
  return over_budget;
}

bool SpringNetworkModel::advance_implicit(std::span<const ToolState> tools, double dt) noexcept {
  place_attached(tools, 1.0, dt);
  const NewtonReport report = m_newton->advance(m_net, m_x, m_v, dt);
  m_last_substeps = report.iterations;
  m_factorisations += report.factorisations;
  m_refreshes += report.refreshes;
  m_most_take_up_corrections = std::max(m_most_take_up_corrections, report.take_up_corrections);
  m_held += report.held ? 1 : 0;
  return !report.converged;
}

void SpringNetworkModel::stylus_forces(std::span<ForceSample> forces, bool over_budget) noexcept {
  // The force on each stylus: the sum of the internal forces on its attached nodes at the end
  // of the sample. The Newton stepper's last residual evaluation already holds them; the
  // explicit and the linearly implicit steps evaluate none at the end state, so there the
  // forces of the cells holding attached nodes (every spring and volume term acting on such a
  // node) are summed alone, instead of the whole network's.
  const bool from_newton = m_newton && m_setup.integrator != SpringIntegrator::linearly_implicit_euler;
  if (from_newton) m_f.leftCols(m_net.node_count) = m_newton->forces().leftCols(m_net.node_count);
  for (ForceSample& f : forces) f = ForceSample{Eigen::Vector3d::Zero(), InteractionMode::deformation_1, 0.0, over_budget};
  if (!from_newton) {
    Eigen::Matrix<double, 3, 8> xc, vc, fc;
    for (const int cell : m_tool_cells) {
      const auto& nodes = m_net.cell_nodes[static_cast<std::size_t>(cell)];
      for (int a = 0; a < 8; ++a) {
        xc.col(a) = m_x.col(nodes[static_cast<std::size_t>(a)]);
        vc.col(a) = m_v.col(nodes[static_cast<std::size_t>(a)]);
      }
      cell_forces(m_net, cell, xc, vc, fc);
      for (int a = 0; a < 8; ++a)
        if (const int t = m_attached_to[static_cast<std::size_t>(nodes[static_cast<std::size_t>(a)])]; t >= 0)
          forces[static_cast<std::size_t>(t)].force += fc.col(a);
    }
  } else {
    for (int p = 0; p < m_net.node_count; ++p)
      if (const int t = m_attached_to[static_cast<std::size_t>(p)]; t >= 0) forces[static_cast<std::size_t>(t)].force += m_f.col(p);
  }

  // A compliant grasp: the anchors' forces on the stylus, −[K (a − x) + τ K (ȧ − v)] each (the
  // force the body exerts through the layer, as the attached nodes' internal forces above).
  const NodeAnchors& anchors = m_net.anchors;
  const double tau = m_net.damping_time;
  for (int i = 0; i < anchors.count(); ++i) {
    const int p = anchors.node[static_cast<std::size_t>(i)];
    const double K = anchors.stiffness[static_cast<std::size_t>(i)];
    forces[static_cast<std::size_t>(m_anchor_tool[static_cast<std::size_t>(i)])].force -=
        K * ((anchors.position.col(i) - m_x.col(p)) + tau * (anchors.velocity.col(i) - m_v.col(p)));
  }
}

void SpringNetworkModel::tear_overstressed(std::span<ForceSample> forces) noexcept {
  if (!m_tearing->tear(m_net, m_x, m_v, m_excluded)) return;
  ++m_tears;
  // The tear-ready pattern takes the split without a new analysis (allocation-free); a split
  // it cannot take (none is expected: each vertex splits once) re-analyses, which allocates.
  if (m_newton && !m_newton->retopologise(m_net, m_x)) m_newton->rebuild(m_net);
  const int pieces = network_pieces(m_net, m_piece_parent, m_piece_label);
  if (pieces > m_pieces)
    for (ForceSample& f : forces) f.mode = InteractionMode::rupture;
  m_pieces = pieces;
}

void SpringNetworkModel::step(std::span<const ToolState> tools, double dt, std::span<ForceSample> forces) noexcept {
  const int n_tools = tool_count();
  if (static_cast<int>(tools.size()) != n_tools || forces.size() != tools.size() || !(dt > 0.0)) {
    for (ForceSample& f : forces) f = ForceSample{Eigen::Vector3d::Zero(), InteractionMode::no_contact, 0.0, true};
    return;
  }
  if (!m_started) {
    for (int t = 0; t < n_tools; ++t) m_last_tool[static_cast<std::size_t>(t)] = tools[static_cast<std::size_t>(t)].position;
    m_started = true;
  }
  const bool over_budget =
      m_setup.integrator == SpringIntegrator::symplectic_euler ? advance_explicit(tools, dt) : advance_implicit(tools, dt);
  for (int t = 0; t < n_tools; ++t) m_last_tool[static_cast<std::size_t>(t)] = tools[static_cast<std::size_t>(t)].position;

  const bool finite = m_x.leftCols(m_net.node_count).allFinite();
  stylus_forces(forces, over_budget);
  if (m_tearing && finite) tear_overstressed(forces);
  for (ForceSample& f : forces)
    if (!finite || !f.force.allFinite()) {
      f.force.setZero();
      f.over_budget = true;
    }
  if (n_tools > 0 && forces[0].over_budget) ++m_unconverged;
}

} // namespace kerf
