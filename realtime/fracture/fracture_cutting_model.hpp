#pragma once
// FractureCuttingModel: haptic rendering of a sharp cut by the energy balance of paper 001
// (Mahvash & Hayward, "Haptic Rendering of Cutting: A Fracture Mechanics Approach"), §4 and the
// algorithm of its Fig. 11, with the contact length l(x) measured on the scene's mesh.

#include "meshes/blade_shape.hpp"
#include "meshes/tet_mesh.hpp"
#include "realtime/fracture/contact_length.hpp"
#include "realtime/fracture/fracture_response.hpp"
#include "realtime/fracture/presliding_friction.hpp"
#include "realtime/tool_model.hpp"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace kerf {

/// The blade and body as the fracture model sees them (SI units).
struct FractureCuttingSetup {
  /// The blade (meshes/blade_shape.hpp): its edge (edge_direction, edge_length) and
  /// cutting_direction, the fixed cutting axis e_x; paper 001's blade is sharp, its wedge
  /// (wedge_angle, thickness) is not used.
  BladeShape blade;
  /// Regions of a layered body (volume group names) and the toughness J_c of each [J/m^2];
  /// one unnamed region (the whole mesh) when `regions` is empty.
  std::vector<std::string> regions;
  std::vector<double> fracture_toughness;
  FractureResponseParameters response;
  /// Friction is built only when the scene declares it ("model only what a scene requires").
  bool friction = false;
  double friction_coefficient = 0.0;
  /// A new contact within this lateral distance of an existing crack's plane re-enters that
  /// crack (paper 001 Fig. 5: contact inside a crack starts in deformation state 2) [m].
  double crack_capture_width = 0.0;
  /// A point of the fixed cutting axis the edge's midpoint travels on (a scene's trajectory
  /// start): l(x) along that axis is computed once, at construction (ContactLengthTable), and
  /// every position on the axis reads it instead of clipping the edge against the mesh; a
  /// position off the axis (a hand on the rig) is measured as before. None: always measured.
  std::optional<Eigen::Vector3d> cutting_axis_point;
};

/// Paper 001's sharp-interaction model as a state machine (Fig. 11, §4.3):
/// - first contact defines the cutting frame (origin at the entry point on the surface, x along
///   the cutting axis, y normal to the blade plane) and starts deformation state 1:
///   f_x = l(x) f1(δ), f1(δ) = f_r (δ/δ_r)^i, δ = x (Eq. 7, §6);
/// - at δ = δ_r the stored energy ruptures the body (§4.2, rupture): the crack jumps to
///   c = x - δ_c and the state becomes 2;
/// - in state 2, f_x = l f2(x - c), f2(δ) = J_c (δ/δ_c)^j, while x - c < δ_c (Eq. 8), and
///   cutting, f_x = J_c l (Eq. 10) with c = x - δ_c, when the tool pushes further;
/// - no contact for x < c (inside the crack) or x < 0 (out of the body); the crack is kept, and
///   a later contact in its plane re-enters it in state 2 (Fig. 5);
/// - a bilateral lateral wall f_y = -k_lat y once a crack holds the blade (Fig. 11), and
///   Hayward–Armstrong pre-sliding friction along x (normal load |f_y|) and, in state 1, along
///   y (normal load f_x) when the scene declares friction;
/// - a layered body (§6) sums the layers: l J_c becomes sum_k l_k J_c,k, l f1 becomes
///   f1 sum_k l_k (both layers share f1, §6), and f2 uses each layer's J_c.
/// The force returned is the force of the body on the blade: -f_x e_x + f_y e_y.
class FractureCuttingModel final : public ToolModel {
public:
  /// Builds the contact-length index on `mesh` (may allocate and take time). Throws
  /// std::invalid_argument on out-of-range parameters, MeshError on missing regions.
  FractureCuttingModel(const TetMesh& mesh, FractureCuttingSetup setup);
  // The contact-length table measures through this object's own SegmentLengthInBody.
  FractureCuttingModel(const FractureCuttingModel&) = delete;
  FractureCuttingModel& operator=(const FractureCuttingModel&) = delete;

  [[nodiscard]] std::string_view name() const override { return "fracture"; }
  [[nodiscard]] int tool_count() const override { return 1; }
  void reset() override;
  void step(std::span<const ToolState> tools, double dt, std::span<ForceSample> forces) noexcept override;

  /// Contact length l(x) of the last step, summed over regions [m].
  [[nodiscard]] double contact_length() const { return m_contact_length_total; }
  /// The cutting frame's origin and axes (valid once contact was made).
  [[nodiscard]] const Eigen::Vector3d& frame_origin() const { return m_origin; }
  /// Steps whose force came out non-finite and was replaced by zero (should stay 0).
  [[nodiscard]] long non_finite_count() const { return m_non_finite; }
  [[nodiscard]] const FractureCuttingSetup& setup() const { return m_setup; }

  /// f1(δ) = f_r (δ/δ_r)^i [N/m], deformation state 1 per unit contact length (paper 001 §6).
  [[nodiscard]] double f1(double deflection) const;
  /// (δ/δ_c)^j: f2 of paper 001 §6 divided by J_c, so that f2_k(δ) = J_c,k * this.
  [[nodiscard]] double f2_over_toughness(double deflection) const;

private:
  enum class State { state_1, state_2 };

  /// Distance back along the cutting axis from `p` to where the edge first touched the body
  /// (bisection on the contact length), used to put the frame origin on the surface.
  double entry_depth(const Eigen::Vector3d& p, double hint);
  double measure(const Eigen::Vector3d& p);

  FractureCuttingSetup m_setup;
  Eigen::Vector3d m_lateral_direction; ///< e_y = edge x cutting direction
  SegmentLengthInBody m_length;
  ContactLengthTable m_axis;           ///< l(x) along the cutting axis (empty without one)
  std::vector<double> m_lengths;       ///< per region, sized once
  std::optional<PreslidingFriction> m_friction_x;
  std::optional<PreslidingFriction> m_friction_y;

  // State of the interaction.
  bool m_frame_known = false;
  State m_state = State::state_1;
  Eigen::Vector3d m_origin = Eigen::Vector3d::Zero();
  double m_crack_extent = 0.0;         ///< c [m], along e_x from the origin
  bool m_have_previous = false;
  Eigen::Vector3d m_previous_position = Eigen::Vector3d::Zero();
  double m_contact_length_total = 0.0;
  long m_non_finite = 0;
};

} // namespace kerf
