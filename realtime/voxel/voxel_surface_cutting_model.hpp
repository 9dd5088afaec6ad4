#pragma once
// VoxelSurfaceCuttingModel: the cutting simulation of paper 002 ("Force Profile Study of Virtual
// Cutting", §2.3–2.4): the body's surface as triangles, a voxel grid built only locally around
// the contact of the cutting stick, surface points and polygon vertices advanced whenever the
// force exceeds the critical force of the depth or the cutting direction, and the two
// resistances of §2.4 (depth cutting stiffness, clip friction force), each switchable.

#include "meshes/aabb_tree.hpp"
#include "meshes/surface_mesh.hpp"
#include "realtime/tool_model.hpp"
#include "realtime/voxel/local_voxel_grid.hpp"

#include <Eigen/Core>

#include <array>

namespace kerf {

/// Parameters of the voxel/polygon cutting model (SI units). Paper 002 Table 1 gives the
/// sponge values; how its printed units become these is the builder's business
/// (experiments/models/voxel_builder.cpp, docs/models.md section voxel).
struct VoxelCuttingSetup {
  double tool_radius = 0.0;            ///< cutting-stick tip radius r [m] > 0 (also Cw of Eq. 1)
  double contact_stiffness = 0.0;      ///< elastic coefficient k_e [N/m] > 0, also E of the DCS
  /// Damping coefficient λ of the contact, per unit penetration [N s/m²] >= 0 (Table 1's unit):
  /// the normal force's viscous part λ δ_d dδ_d/dt (Hunt & Crossley), zero at zero penetration.
  double damping = 0.0;
  double friction_coefficient = 0.0;   ///< μ >= 0: Coulomb friction on the surface and M of Eq. 1
  double critical_force_depth = 0.0;   ///< depth-direction critical force [N] > 0 (Table 1)
  double critical_force_cutting = 0.0; ///< cutting-direction critical force [N] > 0 (Table 1)
  double advance_length = 0.0;         ///< advance per elimination, = voxel edge [m] > 0 (Table 1)
  std::array<int, 3> grid{10, 20, 20}; ///< local grid cells {depth, u, v} (paper 002 §4)
  bool friction = true;                ///< Coulomb friction on the surface (scene phenomenon "friction")
  bool depth_cutting_stiffness = true; ///< DCS of §2.4 on/off (paper 002 Figs. 6–7 cases c, d)
  bool clip_friction = true;           ///< CFF of Eq. (1) on/off (case d)
  double clip_modulus = 0.0;           ///< E of Eq. (1) [Pa] > 0 when clip_friction
  /// Tangential speed below which the direction of friction, DCS and CFF is linearised,
  /// F = -F0 v_t / sqrt(|v_t|^2 + v_s^2) [m/s] > 0 (a regularised Coulomb law; modelling choice).
  double regularisation_speed = 1e-5;
  /// Most polygon triangles the grid's neighbourhood may hold; more sets ForceSample::over_budget.
  int triangle_capacity = 8192;
  /// The stick's centre relative to the tool's reference point [m]: zero when the tool is the
  /// cutting stick itself (a sphere); for a knife, the stick sits at the knife's point (the
  /// builder's mapping, docs/models.md, voxel, "A knife"). Tools only translate, so the offset is
  /// fixed.
  Eigen::Vector3d centre_offset = Eigen::Vector3d::Zero();
};

/// Paper 002's model for one cutting stick (a sphere tip of radius r):
/// - no grid until the stick touches the polygon surface (its centre within r of it); then a
///   LocalVoxelGrid of `grid` cells of edge `advance_length` is placed around the tip in the
///   contact frame (depth axis = inward surface normal at first contact), its columns' surface
///   points cast from the polygon; it is re-centred (overlap kept) when the tip nears its border,
///   and released when the stick leaves the body (centre farther than r + 2 cells outside);
/// - depth direction: the tip point (centre + r depth axis) below its column's surface point by
///   δ_d feels F_n = k_e δ_d + λ δ_d dδ_d/dt (>= 0) out of the body (a spring and, as Table 1's
///   N s/m² says, a damper per unit penetration: Hunt & Crossley, "Coefficient of restitution
///   interpreted as damping in vibroimpact", J. Appl. Mech. 42(2), 1975, with exponent 1 — a
///   normal force that is continuous where the contact begins and ends); when k_e δ_d exceeds
///   the depth critical force the surface point advances by one advance length (§2.3 step 3);
/// - cutting direction c (the direction of the tangential velocity, once the tool has moved
///   along the surface in the episode; the last one while it stands): the stick's leading point
///   (centre + r c) inside a neighbouring column whose surface point lies above the tip is
///   pressed δ_c into that column's wall and feels F_c = k_e δ_c along -c; when F_c exceeds the
///   cutting critical force that column is eliminated down to the tip (the front advances one
///   advance length), with the columns between the tip and the leading point when the stick is
///   wider than a column (r > advance length, a knife's Cw); the critical comparisons use the
///   elastic forces only;
/// - Coulomb friction μ F_n against the tangential velocity;
/// - while cutting, DCS F = 0.066 E d (E = k_e, d = tip depth below the first-contact tangent
///   plane) and CFF Fh of Eq. (1) (Cw = r, dz = d, Cl = cut length: the tip's distance in the
///   tangent plane from where the front first advanced, plus one advance length), both against
///   the tangential velocity, each only if switched on;
/// - every lowered column moves the polygon vertices in its footprint with it, so a later
///   contact (a new grid) finds the cut.
/// Modes: no-contact (no elastic contact, not cutting); deformation-1 (contact before the first
/// advance of the episode); cutting (moving deeper or along the surface, with an advance within
/// the last 1.5 advance lengths of tool travel); deformation-2 (contact after a cut without
/// advancing).
/// ForceSample::crack_extent is the cut length Cl of the current (or last) episode [m].
class VoxelSurfaceCuttingModel final : public ToolModel {
public:
  /// Builds the surface query and triangle index of `surface` (closed, outward) and the grid
  /// storage. Throws std::invalid_argument naming the bad parameter.
  VoxelSurfaceCuttingModel(SurfaceMesh surface, VoxelCuttingSetup setup);

  [[nodiscard]] std::string_view name() const override { return "voxel"; }
  [[nodiscard]] int tool_count() const override { return 1; }
  /// No contact, no grid, the polygon back to its original vertices.
  void reset() override;
  void step(std::span<const ToolState> tools, double dt, std::span<ForceSample> forces) noexcept override;

  [[nodiscard]] const VoxelCuttingSetup& setup() const { return m_setup; }
  /// The local grid (placed only during a contact episode).
  [[nodiscard]] const LocalVoxelGrid& grid() const { return m_grid; }
  [[nodiscard]] bool in_contact_episode() const { return m_episode; }
  /// Bytes held by the voxel structure: fixed by the grid's cell counts and triangle capacity,
  /// independent of the body's size.
  [[nodiscard]] std::size_t voxel_memory_bytes() const { return m_grid.memory_bytes(); }
  /// The polygon as cut so far (#V x 3; triangles as given).
  [[nodiscard]] const Eigen::MatrixXd& polygon_vertices() const { return m_vertices; }
  /// Cl of the current (or last) contact episode [m] (0 before its first cutting advance).
  [[nodiscard]] double cut_length() const { return m_cut_length; }
  /// Advances since construction or reset, in the depth and the cutting direction.
  [[nodiscard]] long depth_advances() const { return m_depth_advances; }
  [[nodiscard]] long cut_advances() const { return m_total_cut_advances; }
  /// Elastic forces of the last step before any advance it made [N] (k_e δ_d, k_e δ_c).
  [[nodiscard]] double last_depth_elastic_force() const { return m_last_depth_force; }
  [[nodiscard]] double last_cutting_elastic_force() const { return m_last_cutting_force; }
  /// Tip depth below the first-contact tangent plane of the last step [m] (d of DCS and CFF).
  [[nodiscard]] double last_depth() const { return m_last_depth; }
  /// Steps whose input or force was non-finite (the force was then zero); should stay 0.
  [[nodiscard]] long non_finite_count() const { return m_non_finite; }

private:
  void start_episode(const Eigen::Vector3d& centre, const SurfaceQuery::Closest& contact) noexcept;
  void place_grid_around(const Eigen::Vector3d& tip_local, bool keep_overlap) noexcept;
  /// The steps of `step` (paper 002 §2.3): the grid re-centred near its border; the depth
  /// direction's surface point pressed and advanced (F_n into normal_force); the cutting
  /// direction's column wall pressed and the front advanced (the wall's force into wall_force);
  /// each returns whether it advanced. The sample's interaction mode.
  void keep_tip_inside_grid(const Eigen::Vector3d& tip) noexcept;
  bool press_surface_point(const Eigen::Vector3d& tip, int i, int j, const Eigen::Vector3d& velocity,
                           double& normal_force) noexcept;
  bool press_column_wall(const Eigen::Vector3d& tip, int i, int j, double& wall_force) noexcept;
  [[nodiscard]] InteractionMode interaction_mode(bool contact, bool forward) const noexcept;

  VoxelCuttingSetup m_setup;
  SurfaceQuery m_query;             ///< the body as built: first contact, leaving the body
  Eigen::MatrixXd m_original;       ///< polygon vertices as built
  Eigen::MatrixXd m_vertices;       ///< polygon vertices as cut
  AabbTree m_tree;                  ///< one box per triangle, as built
  double m_slack = 0.0;             ///< largest vertex displacement so far [m]
  LocalVoxelGrid m_grid;

  // Contact episode.
  bool m_episode = false;
  VoxelFrame m_frame;               ///< the episode's contact frame
  bool m_grid_incomplete = false;
  Eigen::Vector3d m_cut_direction = Eigen::Vector3d::UnitX();
  bool m_have_cut_direction = false; ///< the tool moved along the surface in this episode
  long m_episode_advances = 0;
  long m_episode_cut_advances = 0;
  Eigen::Vector2d m_cut_start = Eigen::Vector2d::Zero(); ///< tip (a, b) at the first cutting advance
  double m_cut_length = 0.0;        ///< Cl of the episode (or the last one) [m]
  double m_travel = 0.0;            ///< tool path length in the episode [m]
  double m_travel_at_advance = 0.0; ///< m_travel at the last advance [m]
  Eigen::Vector3d m_previous_position = Eigen::Vector3d::Zero();

  long m_depth_advances = 0;
  long m_total_cut_advances = 0;
  double m_last_depth_force = 0.0;
  double m_last_cutting_force = 0.0;
  double m_last_depth = 0.0;
  long m_non_finite = 0;
};

} // namespace kerf
