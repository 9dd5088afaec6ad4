#pragma once
// SpringNetworkModel: paper 000 §2 as a ToolModel — a coarse cubic spring network built around
// the styluses, pruned to the body, fixed where the body is supported, with the nodes under each
// stylus tip attached to it; stepped by a selectable integrator; torn past the tensile limit.

#include "meshes/blade_shape.hpp"
#include "meshes/tet_mesh.hpp"
#include "realtime/springs/newton_stepper.hpp"
#include "realtime/springs/spring_network.hpp"
#include "realtime/springs/vertex_tearing.hpp"
#include "realtime/tool_model.hpp"

#include <Eigen/Core>

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace kerf {

/// How the network is advanced per sample.
enum class SpringIntegrator {
  symplectic_euler, ///< explicit, sub-stepped under the computed stability limit
  implicit_euler,   ///< backward Euler by Newton with a kept sparse LDLᵀ factorisation
  quasi_static,     ///< static equilibrium per sample (for comparison with the reference)
  /// linearly implicit Euler (Baraff & Witkin 1998): backward Euler's Newton iteration taken
  /// once per sample from the predictor, with the kept factorisation, no residual check
  linearly_implicit_euler
};
/// "explicit", "implicit", "static", "linear-implicit".
std::string_view to_string(SpringIntegrator integrator);
std::optional<SpringIntegrator> spring_integrator_from_string(std::string_view name);

/// A supported surface of the body (a physical surface of the mesh): bonded fixes the network
/// nodes on it, sliding fixes only the axis of its normal (which must be a coordinate axis).
struct SpringSupport {
  std::string surface;
  bool sliding = false;
};

/// A tool: a stylus, its tip centre at the first sample [m] and tip radius [m]; or, with
/// `blade`, a blade whose edge midpoint is at `start` at the first sample (radius unused): its
/// edge (edge_direction, cutting_direction, edge_length; the wedge is not used) presses the
/// network, the deformation phase of a cutting scene (paper 001's deformation before rupture).
/// The network does not cut: past the rupture point its response is the uncut body's.
/// A stylus with `grasp_stiffness` k > 0 grasps compliantly (docs/spring-network.md §3,
/// "Compliant grasp"; the scene's grasp_stiffness and grasp_radius): the disc of radius
/// `grasp_disc_radius` a on the face the tip touches, centred at the contact point, is held to
/// the tip by an elastic layer of stiffness per area k(r) = k (1 − r²/a²), lumped onto the
/// network's nodes on that face as anchor springs (lump_grasp_layer); otherwise the nodes within
/// SpringNetworkSetup::grasp_radius are attached rigidly.
struct SpringStylus {
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  double radius = 0.0;
  std::optional<BladeShape> blade = std::nullopt;
  double grasp_stiffness = 0.0;   ///< k [N/m³]; 0: the rigid grasp
  double grasp_disc_radius = 0.0; ///< a [m] > 0 with grasp_stiffness
};

/// Everything the model is built from (SI units).
struct SpringNetworkSetup {
  double youngs_modulus = 0.0;  ///< E [Pa]
  double poisson_ratio = 0.0;   ///< ν
  double density = 0.0;         ///< ρ [kg/m^3]
  double damping = 0.0;         ///< Kelvin–Voigt viscosity η [Pa s]
  bool volume_term = true;      ///< per-cell volume term (represents ν >= 1/4; off below)
  int cells = 8;                ///< N: cells per side of the block (>= 1)
  double cell_size = 0.0;       ///< h [m]; 0: the block side over N (see the constructor)
  SpringIntegrator integrator = SpringIntegrator::symplectic_euler;
  /// Symplectic Euler's force loops in single precision while the network is untorn
  /// (LatticeForces::ForcePrecision; positions and velocities stay double): 1.6 x faster at 8³,
  /// clay_pull's profile within 1.4·10⁻⁷ of its peak of the double loops' (docs/spring-network.md §6).
  bool single_precision_forces = true;
  bool tearing = false;
  double tensile_limit = 0.0;   ///< σ_max [Pa] > 0 when tearing
  /// Grasp radius [m] of the rigid grasp: network nodes within it of a stylus tip centre are
  /// attached to the stylus; 0: the tip radius plus half a cell, r + h/2. Not used by a stylus
  /// that grasps compliantly (SpringStylus::grasp_stiffness).
  double grasp_radius = 0.0;
  std::vector<SpringSupport> supports;
  std::vector<SpringStylus> styluses; ///< one or two
  /// Implicit Euler: how a factor refreshed off the servo thread is taken up (NewtonStepper; the
  /// default adopts it a fixed number of samples after asking, so that a run is reproducible).
  FactorRefreshPolicy refresh;
  /// The sample period the implicit integrators' first factor is computed for [s] (at reset, off
  /// the servo's path; another dt refreshes it). 1 ms: the servo's usual 1 kHz.
  double expected_dt = 1e-3;
};

/// The model. Construction (allocates):
/// 1. block: the styluses' contact points (closest body-surface points to the tip centres) give
///    its centre c; its side S = N h, with h given or h = max(smallest body extent, 2 x the
///    styluses' spread) / N; per axis it is placed at c − S/2 shifted into the body's bounding box
///    (or at the box's lower side when S exceeds the box).
/// 2. pruning: a cell is kept when at least 5 of 9 sample points (its centre and the 8 points at
///    quarter positions) lie inside the body (SurfaceQuery::contains on the mesh's boundary).
/// 3. supports: nodes within h/4 of a support surface are fixed (bonded) or fixed along its normal
///    (sliding); nodes on the block's outer faces where the body continues outside the block are
///    fixed (the material beyond the network is taken as rigid).
/// 4. styluses: nodes within the grasp radius (r + h/2 unless given) of a tip centre (at least the
///    nearest one) are attached to it
///    and move with it (paper 000 §2.1: "the vertices at the stylus tip is fixed to the stylus").
///    A stylus that grasps compliantly attaches none: the nodes of the face it touches whose
///    shape functions meet its disc get anchors (lump_grasp_layer) that move with it, a_p =
///    X_p + (p(t) − p(0)), and stay free.
///    A blade (one tool alone): the nodes under its edge — within the edge's span, within h/2 of
///    the plane of the edge and the cutting direction, in the first layer the edge meets (gap g
///    along the cutting direction c within h/2 of the smallest) — are attached; each stays put
///    until the edge reaches it and is then pushed along c: x = X + c max(0, (p − p₀)·c − g).
///    For a blade the block side covers the edge's span in the body, h = max(smallest extent,
///    that span) / N.
/// `step`: attached nodes and anchors follow the stylus; the network is advanced by dt with the
/// integrator; the force on each stylus is the sum of the internal forces on its attached nodes
/// (the force the body exerts on them), or for a compliant grasp the sum of its anchors' forces
/// on the stylus, −Σ [K_p (a_p − x_p) + τ K_p (ȧ_p − v_p)]; mode is
/// deformation-1, and rupture on the sample in which a tear separates the network into more
/// pieces. A tear under the implicit or quasi-static integrator re-analyses the sparse pattern
/// (the one allocation `step` may make, once per tear); the explicit integrator tears without.
class SpringNetworkModel : public ToolModel {
public:
  SpringNetworkModel(const TetMesh& mesh, SpringNetworkSetup setup);

  [[nodiscard]] std::string_view name() const override { return "springs"; }
  [[nodiscard]] int tool_count() const override { return static_cast<int>(m_setup.styluses.size()); }
  void reset() override;
  /// The implicit integrators' refresh policy (SpringNetworkSetup::refresh); takes effect now (a reset).
  void set_refresh_policy(FactorRefreshPolicy policy) {
    m_setup.refresh = policy;
    reset();
  }
  void step(std::span<const ToolState> tools, double dt, std::span<ForceSample> forces) noexcept override;

  /// The network as it is now (cells re-pointed by tears) and its node positions [m].
  [[nodiscard]] const SpringNetwork& network() const { return m_net; }
  [[nodiscard]] const Eigen::Matrix3Xd& positions() const { return m_x; }
  /// What the constructor identified and computed.
  [[nodiscard]] const CellIdentification& identification() const { return m_identification; }
  [[nodiscard]] double stability_limit() const { return m_stability_limit; } ///< explicit h_crit [s]
  [[nodiscard]] int last_substeps() const { return m_last_substeps; }
  [[nodiscard]] int tears() const { return m_tears; }     ///< vertex splits so far
  /// Numeric factorisations made on the stepping thread in `step` since reset(): the linearly
  /// implicit and quasi-static integrators' refreshes, and implicit Euler's rare fallbacks (a
  /// split the pattern could not take, more splits pending than its correction holds); its
  /// other factors are computed at reset and off the servo thread.
  [[nodiscard]] long factorisations() const { return m_factorisations; }
  /// Fresh factors the implicit integrator adopted from its worker since reset().
  [[nodiscard]] long refreshes() const { return m_refreshes; }
  /// The most splits the implicit integrator corrected a collected factor for in one step since
  /// reset() (FactorRefreshPolicy::corrections_per_call bounds it).
  [[nodiscard]] int most_take_up_corrections() const { return m_most_take_up_corrections; }
  /// Samples since reset() in which the implicit integrator accepted no step and held the
  /// network's free nodes where they were, at rest (NewtonReport::held); counted among the
  /// unconverged samples too.
  [[nodiscard]] long held_samples() const { return m_held; }
  /// Samples since reset() that did not converge (or exceeded the explicit sub-step bound): the
  /// samples reported over budget.
  [[nodiscard]] long unconverged_samples() const { return m_unconverged; }
  [[nodiscard]] int pieces() const { return m_pieces; }   ///< connected pieces of the network
  [[nodiscard]] int attached_nodes(int stylus) const;
  /// A compliant grasp's anchored nodes of `stylus` and the sum of their stiffnesses Σ K_p [N/m].
  [[nodiscard]] int anchored_nodes(int stylus) const;
  [[nodiscard]] double anchor_stiffness(int stylus) const;

private:
  void build(const TetMesh& mesh);
  /// Step 4 of `build`: the nodes under each stylus attached to it (a compliant grasp: its
  /// anchors), fixed, and the lists that follow from them (attached nodes, tool cells, nodes
  /// never split).
  void attach_to_styluses(SpringNetwork& net, const std::vector<Eigen::Vector3d>& contact,
                          const std::vector<Eigen::Vector3d>& contact_normal, double h);
  /// The steps of `step`: the attached nodes and anchors at fraction s of the sample; the
  /// network advanced by dt under the explicit integrator's sub-steps or the Newton stepper
  /// (each returns whether the sample is over budget); the force on each stylus; a tear.
  void place_attached(std::span<const ToolState> tools, double s, double dt) noexcept;
  bool advance_explicit(std::span<const ToolState> tools, double dt) noexcept;
  bool advance_implicit(std::span<const ToolState> tools, double dt) noexcept;
  void stylus_forces(std::span<ForceSample> forces, bool over_budget) noexcept;
  void tear_overstressed(std::span<ForceSample> forces) noexcept;

  SpringNetworkSetup m_setup;
  CellIdentification m_identification;
  SpringNetwork m_initial, m_net;
  std::vector<int> m_attached_to;        ///< per node: stylus index or -1
  std::vector<int> m_attached;           ///< the nodes attached to a stylus, in node order (never split)
  /// The cells with an attached corner (attached nodes are never split, so the cells holding
  /// them stay the same): the explicit and linearly implicit integrators sum their forces on
  /// the tools.
  std::vector<int> m_tool_cells;
  std::vector<double> m_gap;             ///< per node attached to a blade: its gap g [m]
  std::vector<int> m_anchor_tool;        ///< per anchor (m_net.anchors): the stylus it moves with
  std::vector<std::uint8_t> m_excluded;  ///< per node: not torn (attached)
  Eigen::Matrix3Xd m_x, m_v, m_f;
  std::vector<Eigen::Vector3d> m_last_tool;
  bool m_started = false;
  double m_omega_max = 0.0;
  double m_stability_limit = 0.0;
  double m_gershgorin_rest = 0.0;    ///< Gershgorin bound at rest [1/s²]
  std::vector<double> m_gershgorin_work;
  int m_last_substeps = 0;
  int m_tears = 0;
  long m_factorisations = 0;
  long m_refreshes = 0;
  int m_most_take_up_corrections = 0;
  long m_held = 0;
  long m_unconverged = 0;
  int m_pieces = 1;
  LatticeForces m_lattice;               ///< the explicit integrator's force loops
  std::unique_ptr<NewtonStepper> m_newton;
  std::unique_ptr<VertexTearing> m_tearing;
  std::vector<int> m_piece_parent, m_piece_label;
};

} // namespace kerf
