#include "realtime/fracture/fracture_cutting_model.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace kerf {

namespace {

double integer_power(double base, int exponent) {
  double result = 1.0;
  for (int k = 0; k < exponent; ++k) result *= base;
  return result;
}

void require(bool condition, const std::string& what) {
  if (!condition) throw std::invalid_argument("fracture model: " + what);
}

/// Contact lengths below this are "no contact" [m] (a picometre: far below any mesh size, far
/// above the clipping tolerance of SegmentLengthInBody).
constexpr double contact_threshold = 1e-12;

} // namespace

FractureCuttingModel::FractureCuttingModel(const TetMesh& mesh, FractureCuttingSetup setup)
    : m_setup(std::move(setup)), m_length(mesh, m_setup.regions) {
  const FractureResponseParameters& r = m_setup.response;
  require(std::abs(m_setup.blade.edge_direction.norm() - 1.0) < 1e-9, "edge direction must be a unit vector");
  require(std::abs(m_setup.blade.cutting_direction.norm() - 1.0) < 1e-9, "cutting direction must be a unit vector");
  require(std::abs(m_setup.blade.edge_direction.dot(m_setup.blade.cutting_direction)) < 1e-6,
          "cutting direction must be orthogonal to the edge");
  require(m_setup.blade.edge_length > 0.0 && std::isfinite(m_setup.blade.edge_length), "edge length must be positive");
  require(r.rupture_force_per_length > 0.0 && std::isfinite(r.rupture_force_per_length), "f_r must be positive");
  require(r.rupture_deflection > 0.0 && std::isfinite(r.rupture_deflection), "δ_r must be positive");
  require(r.crack_deflection > 0.0 && std::isfinite(r.crack_deflection), "δ_c must be positive");
  require(r.deformation_1_exponent >= 1 && r.deformation_1_exponent <= 3, "i must be 1, 2 or 3");
  require(r.deformation_2_exponent >= 1 && r.deformation_2_exponent <= 3, "j must be 1, 2 or 3");
  require(r.lateral_stiffness >= 0.0 && std::isfinite(r.lateral_stiffness), "lateral stiffness must be >= 0");
  require(m_setup.crack_capture_width >= 0.0, "crack capture width must be >= 0");
  require(static_cast<int>(m_setup.fracture_toughness.size()) == m_length.region_count(),
          "one fracture toughness per region is needed");
  for (double jc : m_setup.fracture_toughness) require(jc > 0.0 && std::isfinite(jc), "J_c must be positive");

  m_lateral_direction = m_setup.blade.edge_direction.cross(m_setup.blade.cutting_direction).normalized();
  m_lengths.assign(static_cast<std::size_t>(m_length.region_count()), 0.0);
  if (m_setup.cutting_axis_point) {
    require(m_setup.cutting_axis_point->allFinite(), "the cutting axis point must be finite");
    // The axis over the body's extent along it, and one edge length beyond either side.
    const Eigen::Vector3d& e = m_setup.blade.cutting_direction;
    double lo = INFINITY, hi = -INFINITY;
    for (Eigen::Index n = 0; n < mesh.nodes.rows(); ++n) {
      const double s = (mesh.nodes.row(n).transpose() - *m_setup.cutting_axis_point).dot(e);
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
    const double margin = m_setup.blade.edge_length;
    m_axis = ContactLengthTable(m_length, *m_setup.cutting_axis_point, e, 0.5 * m_setup.blade.edge_length * m_setup.blade.edge_direction,
                                lo - margin, hi + margin);
  }
  if (m_setup.friction) {
    require(m_setup.friction_coefficient >= 0.0, "friction coefficient must be >= 0");
    m_friction_x.emplace(r.presliding_stiffness, r.presliding_stick_ratio);
    m_friction_y.emplace(r.presliding_stiffness, r.presliding_stick_ratio);
  }
}

void FractureCuttingModel::reset() {
  m_frame_known = false;
  m_state = State::state_1;
  m_origin.setZero();
  m_crack_extent = 0.0;
  m_have_previous = false;
  m_contact_length_total = 0.0;
  if (m_friction_x) m_friction_x->reset();
  if (m_friction_y) m_friction_y->reset();
}

double FractureCuttingModel::f1(double deflection) const {
  const FractureResponseParameters& r = m_setup.response;
  return r.rupture_force_per_length * integer_power(deflection / r.rupture_deflection, r.deformation_1_exponent);
}

double FractureCuttingModel::f2_over_toughness(double deflection) const {
  const FractureResponseParameters& r = m_setup.response;
  return integer_power(deflection / r.crack_deflection, r.deformation_2_exponent);
}

double FractureCuttingModel::measure(const Eigen::Vector3d& p) {
  // On the cutting axis: l(x) as tabulated at construction.
  if (!m_axis.empty())
    if (const double s = m_axis.parameter(p); std::isfinite(s)) return m_axis.lengths(s, m_lengths);
  const Eigen::Vector3d half = 0.5 * m_setup.blade.edge_length * m_setup.blade.edge_direction;
  return m_length.lengths(p - half, p + half, m_lengths);
}

double FractureCuttingModel::entry_depth(const Eigen::Vector3d& p, double hint) {
  const Eigen::Vector3d& e_x = m_setup.blade.cutting_direction;
  // Bracket: at s = 0 the edge is in contact; find s_hi where it is not (doubling, bounded).
  double s_lo = 0.0;
  double s_hi = std::max(hint, 1e-6);
  int doublings = 0;
  while (measure(p - s_hi * e_x) > contact_threshold && doublings < 40) {
    s_lo = s_hi;
    s_hi *= 2.0;
    ++doublings;
  }
  // Bisection to a picometre or 80 halvings, whichever first: the frame origin then sits on
  // the surface to far below any deflection that matters.
  for (int k = 0; k < 80 && s_hi - s_lo > 1e-12; ++k) {
    const double mid = 0.5 * (s_lo + s_hi);
    if (measure(p - mid * e_x) > contact_threshold) s_lo = mid;
    else s_hi = mid;
  }
  return s_hi;
}

void FractureCuttingModel::step(std::span<const ToolState> tools, double /*dt*/, std::span<ForceSample> forces) noexcept {
  ForceSample& out = forces[0];
  out = ForceSample{};
  const Eigen::Vector3d p = tools[0].position;
  if (!finite_input(p, m_non_finite)) return;
  const Eigen::Vector3d& e_x = m_setup.blade.cutting_direction;
  const Eigen::Vector3d& e_y = m_lateral_direction;
  const Eigen::Vector3d motion = m_have_previous ? Eigen::Vector3d(p - m_previous_position) : Eigen::Vector3d::Zero();
  m_previous_position = p;
  m_have_previous = true;

  m_contact_length_total = measure(p);
  out.crack_extent = m_crack_extent;

  if (!m_frame_known) {
    if (m_contact_length_total <= contact_threshold) { // Fig. 11: no frame, no collision
      if (m_friction_x) m_friction_x->reset();
      if (m_friction_y) m_friction_y->reset();
      return;
    }
    // Collision. Inside an existing crack (same blade plane, past the crack mouth)? Fig. 5:
    // contact inside a crack begins a deformation mode in state 2.
    const Eigen::Vector3d r = p - m_origin;
    if (m_crack_extent > 0.0 && std::abs(r.dot(e_y)) <= m_setup.crack_capture_width && r.dot(e_x) >= 0.0) {
      m_state = State::state_2;
    } else { // DefineCuttingFrame(ToolPosition, LocalSurfaceNormal), a fresh crack
      m_origin = p - entry_depth(p, std::max(0.0, motion.dot(e_x))) * e_x;
      m_crack_extent = 0.0;
      m_state = State::state_1;
    }
    m_frame_known = true;
    m_contact_length_total = measure(p); // entry_depth reused the scratch lengths
  }

  const Eigen::Vector3d r = p - m_origin;
  const double x = r.dot(e_x);
  const double y = r.dot(e_y);
  if (x < 0.0) { // left the body: forget the frame, keep the crack
    m_frame_known = false;
    if (m_friction_x) m_friction_x->reset();
    if (m_friction_y) m_friction_y->reset();
    out.crack_extent = m_crack_extent;
    return;
  }

  // l(x) and sum_k J_c,k l_k(x) at the edge's current position.
  const double l = m_contact_length_total;
  double toughness_length = 0.0;
  for (std::size_t k = 0; k < m_lengths.size(); ++k) toughness_length += m_setup.fracture_toughness[k] * m_lengths[k];

  const FractureResponseParameters& resp = m_setup.response;
  const double mu = m_setup.friction_coefficient;
  double fx = 0.0; // resistance along the cutting axis (opposes advance)
  double fy = 0.0; // force on the tool along e_y
  InteractionMode mode = InteractionMode::no_contact;

  if (m_state == State::state_1) {
    if (x < resp.rupture_deflection) {
      // Deformation, state 1: f_t = l f1(δ), δ = x (Eq. 7); friction across the surface.
      mode = InteractionMode::deformation_1;
      fx = l * f1(x);
      if (m_friction_y) fy = m_friction_y->update(motion.dot(e_y), std::abs(fx), mu);
    } else {
      // Rupture (§4.2, Eq. 11): the crack opens to c = x - δ_c at once and the interaction
      // continues in state 2 at the cutting force J_c l (Eq. 10).
      mode = InteractionMode::rupture;
      m_crack_extent = x - resp.crack_deflection;
      m_state = State::state_2;
      fy = -resp.lateral_stiffness * y;
      fx = toughness_length;
      if (m_friction_y) m_friction_y->reset();
      if (m_friction_x) fx -= m_friction_x->update(motion.dot(e_x), std::abs(fy), mu);
    }
  } else {
    fy = -resp.lateral_stiffness * y; // bilateral wall: the crack holds the blade in its plane
    const double delta = x - m_crack_extent;
    if (delta < 0.0) {
      mode = InteractionMode::no_contact; // inside the crack, short of its front
    } else if (delta < resp.crack_deflection) {
      // Deformation, state 2: f_t = l f2(δ) (Eq. 8), per layer f2_k = J_c,k (δ/δ_c)^j.
      mode = InteractionMode::deformation_2;
      fx = toughness_length * f2_over_toughness(delta);
    } else {
      // Cutting: the front advances with the tool, f_t = J_c l (Eq. 10).
      mode = InteractionMode::cutting;
      m_crack_extent = x - resp.crack_deflection;
      fx = toughness_length;
    }
    if (m_friction_x) fx -= m_friction_x->update(motion.dot(e_x), std::abs(fy), mu);
  }

  write_sample(out, -fx * e_x + fy * e_y, mode, m_crack_extent, m_non_finite);
}

} // namespace kerf
