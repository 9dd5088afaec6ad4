#pragma once
// DiscreteEdgeCuttingModel: the cutting force of paper 000 §3.1 (Shape Forming by Cutting and
// Deforming Operations) on a blade edge discretised into K independent points, with collision
// through the voxel model of §3.3.

#include "meshes/blade_shape.hpp"
#include "realtime/edge/background_cut.hpp"
#include "realtime/edge/collision_voxels.hpp"
#include "realtime/tool_model.hpp"

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace kerf {

/// Material of one region as the discrete edge sees it, per unit length of edge; each of the K
/// points represents ΔL = L / K of edge and takes these times ΔL.
struct EdgeMaterial {
  /// k' [N/m per m of edge = Pa]: stiffness coefficient of paper 000 §3.1 per unit edge length.
  double stiffness_per_length = 0.0;
  /// F_s' [N/m]: the shear force per unit edge length the material bears before it is destroyed
  /// (the cutting resistance's limit, paper 000 §3.1).
  double shear_limit_per_length = 0.0;
  /// b' [N s/m^2]: viscous drag per unit edge length, f = -b' ΔL v (paper 000 §3.1).
  double drag_per_length = 0.0;
};

/// The blade and body as the edge model sees them (SI units).
struct DiscreteEdgeSetup {
  /// The blade (meshes/blade_shape.hpp): its edge e = edge_direction, L = edge_length > 0, and
  /// cutting_direction, the direction of entry of a point that enters at rest; the edge is a line,
  /// its wedge (wedge_angle, thickness) is not used.
  BladeShape blade;
  int point_count = 0;                                           ///< K >= 1 discrete edges
  std::vector<EdgeMaterial> materials; ///< one per region of the collision voxels (layers)
  /// Coulomb friction coefficient μ of the edge sliding along its own axis (non-destructive);
  /// 0 when the scene does not declare friction.
  double friction_coefficient = 0.0;
  /// A point that re-enters the body within this distance of the mouth of the cut it made
  /// continues in that cut (deformation-2) instead of starting on a fresh surface [m] >= 0.
  double channel_capture_width = 0.0;
};

/// Paper 000 §3.1: the cutting edge as K discrete points p_i = c + s_i e (s_i the midpoints of K
/// equal pieces of the edge), each independent of the others. Each point i holds
/// - its present position p_i (where the edge meets the deformed object) and
/// - its relaxed colliding point r_i (where it meets the object when the deformation is relaxed):
///   set to the surface point where p_i entered a marked voxel (§3.3), found by bisection on the
///   segment of the last step.
/// With the disparity d = p_i - r_i split into its part along the edge d_a = (d·e) e and across
/// it d_n = d - d_a (the edge is a line, omni-directional across its axis, §3.1):
/// - elastic force f_i = -k (p_i - r_i), k = k' ΔL (the stiffness coefficient);
/// - cutting resistance: when k |d_n| > F_s = F_s' ΔL the material is destroyed and r_i advances
///   along d_n until k |d_n| = F_s (the force is capped at the shear limit);
/// - friction (non-destructive): when k |d_a| > μ k |d_n| the relaxed point slides along e until
///   equality (Coulomb stick-slip of the edge along its axis);
/// - viscous drag f = -b v, b = b' ΔL, while p_i is in a marked voxel.
/// A point that moves back behind its relaxed point (d·n <= 0, n the direction it came in) is
/// slack: no elastic force, only drag. Modes (paper 001's names): cutting when a point destroyed
/// material this step; deformation-1 when points touch material they have not cut; deformation-2
/// when all touching points are inside a cut they made (pressing on its front or retreating);
/// no-contact when no point is in a marked voxel. crack_extent is the deepest cut along n.
/// The force returned is the sum over points of the force of the body on the edge.
class DiscreteEdgeCuttingModel final : public ToolModel {
public:
  /// Throws std::invalid_argument on out-of-range parameters or a material count that does not
  /// cover the voxels' regions.
  DiscreteEdgeCuttingModel(CollisionVoxels voxels, DiscreteEdgeSetup setup);

  [[nodiscard]] std::string_view name() const override { return "edge"; }
  [[nodiscard]] int tool_count() const override { return 1; }
  void reset() override;
  void step(std::span<const ToolState> tools, double dt, std::span<ForceSample> forces) noexcept override;

  /// One discrete edge's state (paper 000 §3.1).
  struct Point {
    bool in_contact = false;   ///< p is in a marked voxel
    bool has_cut = false;      ///< material was destroyed along this point's path
    Eigen::Vector3d present = Eigen::Vector3d::Zero();  ///< p_i [m]
    Eigen::Vector3d relaxed = Eigen::Vector3d::Zero();  ///< r_i [m]
    Eigen::Vector3d entry = Eigen::Vector3d::Zero();    ///< surface point of first contact [m]
    Eigen::Vector3d inward = Eigen::Vector3d::Zero();   ///< n, unit direction of entry
    double depth = 0.0;        ///< (r_i - entry)·n reached by cutting [m]
    Eigen::Vector3d force = Eigen::Vector3d::Zero();    ///< force of the body on this point [N]
    bool cutting = false;      ///< destroyed material in the last step
    int region = -1;
  };
  [[nodiscard]] const std::vector<Point>& points() const { return m_points; }
  /// Stiffness coefficient k = k' ΔL [N/m], shear limit F_s = F_s' ΔL [N] and drag b = b' ΔL
  /// [N s/m] of one point in region `region`.
  [[nodiscard]] double point_stiffness(int region = 0) const;
  [[nodiscard]] double point_shear_limit(int region = 0) const;
  [[nodiscard]] double point_drag(int region = 0) const;
  [[nodiscard]] const CollisionVoxels& voxels() const { return m_voxels; }
  [[nodiscard]] const DiscreteEdgeSetup& setup() const { return m_setup; }
  [[nodiscard]] long non_finite_count() const { return m_non_finite; }

  /// Paper 000 §3.2 driven by the edge itself: `step` records the trajectory of the edge where
  /// it destroys material and hands each pass to `cut`'s worker thread (BackgroundCut: no
  /// allocation, lock or wait on the servo thread). A pass opens at the first sample in which a
  /// point cuts, with the edge's entry (the mean over cutting points of e_i - s_i e, e_i each
  /// point's entry on the surface); while points cut it records the crack front, the mean of
  /// r_i - s_i e over the points in contact that have cut (their relaxed points: where material
  /// was destroyed), each time it has moved `record_spacing` [m] > 0 from the last position; it
  /// closes when no point is in a marked voxel any more, with the last front and, when the edge
  /// went on through the body (its centre ahead of the front along the direction of entry), the
  /// edge's centre itself, and is handed over.
  void attach_geometric_cut(std::unique_ptr<BackgroundCut> cut, double record_spacing);
  /// The attached cut, or null.
  [[nodiscard]] BackgroundCut* geometric_cut() const { return m_cut.get(); }
  /// Not realtime: closes and hands over a pass still open (the trajectory ended inside the
  /// body) and waits until the worker has cut.
  void finish_geometric_cut();

private:
  /// The surface point between `outside` (unmarked) and `inside` (marked), by bisection on the
  /// voxel marks (60 halvings: far below a voxel).
  [[nodiscard]] Eigen::Vector3d entry_point(const Eigen::Vector3d& outside, const Eigen::Vector3d& inside) const noexcept;
  void update_point(Point& point, const Eigen::Vector3d& p, const Eigen::Vector3d& velocity, bool have_previous) noexcept;
  /// The trajectory recording of attach_geometric_cut, once per step.
  void record_pass(const Eigen::Vector3d& centre, bool any_contact, int cut_points, const Eigen::Vector3d& entry,
                   const Eigen::Vector3d& front, const Eigen::Vector3d& inward) noexcept;
  void close_pass(const Eigen::Vector3d& centre) noexcept;

  CollisionVoxels m_voxels;
  DiscreteEdgeSetup m_setup;
  double m_piece_length = 0.0; ///< ΔL [m]
  std::vector<Point> m_points; ///< sized once
  bool m_have_previous = false;
  long m_non_finite = 0;
  std::unique_ptr<BackgroundCut> m_cut;
  double m_record_spacing = 0.0;
  bool m_pass_open = false;
  Eigen::Vector3d m_pass_inward = Eigen::Vector3d::Zero();
  Eigen::Vector3d m_last_front = Eigen::Vector3d::Zero();
};

} // namespace kerf
