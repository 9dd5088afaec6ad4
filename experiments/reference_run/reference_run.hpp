#pragma once
// The scene-level reference run (docs/reference.md): the scene mapped to a finite-strain problem (materials
// per region, supports, the tool as a rigid body), the chosen trajectory samples solved along a
// load path with cut-back, and the result written as profile.csv + manifest.json, fields.pvd with
// a .vtu per solved sample, a progress line per sample, and checkpoints to resume from.
//
// Includes reference/*.hpp only, which include no deal.II.

#include "formats/profile/force_profile.hpp"
#include "experiments/reference_run/reference_fracture.hpp"
#include "formats/scene/scene.hpp"
#include "meshes/tet_mesh.hpp"
#include "reference/finite_strain_solver.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace kerf {

/// What `run_reference` solves and writes.
struct ReferenceRunSettings {
  int degree = 1;      ///< FE_SimplexP degree, 1 or 2
  int refinements = 0; ///< global refinements of the scene mesh
  std::vector<std::size_t> sample_indices; ///< trajectory samples to solve, ascending; empty = every sample
  bool write_fields = true; ///< dir/fields.pvd + dir/fields/step_NNNN.vtu
  int checkpoint_every = 5; ///< write dir/checkpoint.bin after every this many solved samples (>= 1)
  bool resume = false;      ///< continue from dir/checkpoint.bin if it exists
  reference::LinearSolverChoice linear_solver = reference::LinearSolverChoice::automatic;
  /// Under `mpirun -np N` (N > 1): distribute the mesh over the N processes (true) or solve the
  /// whole problem on every process (false). See reference::SolverSettings::distribute.
  bool distribute = true;
  /// Cohesive fracture along the scene's cut_plane (Reference II; reference_fracture.hpp). `kerf
  /// reference` and studies pass `automatic` (a cutting or tearing scene with σ_c and J_c cuts);
  /// off here, so a program that builds its own settings asks for fracture explicitly.
  ReferenceFracture fracture = ReferenceFracture::off;
  /// Samples that resolve the events (adaptive sampling): with `adaptive_force_change` > 0, a
  /// solved sample whose force leaves the straight line through the two samples before it by more
  /// than that fraction of the largest force so far (or whose interaction mode differs from the
  /// previous sample's: first contact, rupture, cutting, re-contact) is undone, and the trajectory
  /// sample half way between it and the previous one is solved first —
  /// recursively, until the tool travels at most `adaptive_min_travel` [m] between the two samples.
  /// The requested samples are all solved; the inserted ones join the profile. 0: off.
  double adaptive_force_change = 0.0;
  double adaptive_min_travel = 0.05e-3;
  /// The load path follows the trajectory (reference/load_path.hpp, trajectory_vertices.hpp):
  /// besides the requested samples, every vertex of the tools' motion is a load — a sample where
  /// the motion leaves the straight line in time through its neighbouring vertices by more than
  /// this distance [m] > 0 (segment ends, dwell start and end, the turns of a recorded hand) — and
  /// between two loads the tools move along the trajectory. The default, 1 µm, keeps every corner
  /// of a scripted motion and every turn of a recorded hand larger than a micrometre.
  double vertex_tolerance = 1e-6;
  /// Viscous regularisation of the cohesive law: relaxation time τ [s] >= 0, η = σ_c τ / δ_f
  /// (add_crack_path); 0 = none. Its dissipation is booked in the manifest's energy.
  double cohesive_viscous_time = 0.0;
  /// The dynamic (inertial) step (reference::SolverSettings::dynamic: Newmark average acceleration,
  /// consistent mass from the scene's density) instead of the quasi-static one; the kinetic energy
  /// joins the manifest's energy. The time step is the spacing of the solved samples (halved by the
  /// load path's cut-backs).
  bool dynamic = false;
  /// Dynamic step: the scene's Kelvin–Voigt damping (its materials' `damping` η, the viscous
  /// stress (η/E) ℂ₀ : Ė of reference/material/kelvin_voigt.hpp), its dissipation in the manifest's
  /// energy; false leaves it out (an undamped run). The quasi-static step has no rate: unused.
  bool damping = true;
  /// Dynamic step with fracture: the load path's interface energy control
  /// (reference::LoadPathSettings): a step whose time integration error at the cohesive law's kinks
  /// exceeds interface_error_relative × its cohesive dissipation + interface_error_floor × J_c A
  /// (A the crack path's area) is rejected and re-solved in halves. Both 0: off.
  double interface_error_relative = 0.005;
  double interface_error_floor = 1e-5;
  /// Fault injection for tests (docs/reliability.md): passed to the solver as
  /// reference::SolverSettings::residual_fault (a NaN in the chosen Newton iterations' residual).
  std::function<bool(const reference::LoadState& load, int newton_iteration)> residual_fault;
};

/// How the scene's tool is coupled to the body in the reference.
struct ReferenceToolCoupling {
  enum class Kind {
    penalty, ///< frictionless penalty contact with the rigid tool (a blade, or a pressing sphere)
    tied     ///< the disc the stylus grasps moves with it (paper 000 §2.1: "the vertices at the stylus
             ///< tip fixed to the stylus"): a sphere with a grasp radius (Tool::grasp_radius)
  };
  Kind kind = Kind::penalty;
  Eigen::Vector3d contact_point = Eigen::Vector3d::Zero(); ///< tied: the body point first touched [m]
  std::vector<int> tied_triangles; ///< tied: rows of the grasp surface group (scene_mesh.hpp) tied to the stylus
  std::size_t tied_nodes = 0;      ///< tied: distinct mesh nodes of those triangles
  int boundary = -1; ///< tied rigidly: index of its tie in FiniteStrainProblem::displacement_boundaries
  /// tied through a compliant layer (Tool::grasp_stiffness): k [N/m^3] (0: rigid), and the index of
  /// its elastic foundation in FiniteStrainProblem::foundations (−1: rigid).
  double grasp_stiffness = 0.0;
  int foundation = -1;
};

/// One scene tool in the reference: how it is coupled, and its reference point at each sample.
struct ReferenceTool {
  std::string name;
  ReferenceToolCoupling coupling;
  std::vector<Eigen::Vector3d> positions; ///< [m], one per trajectory sample
};

/// The scene as the reference's boundary-value problem, and how its tool is coupled.
struct ReferenceProblem {
  reference::FiniteStrainProblem problem;
  std::vector<ReferenceTool> tools; ///< the scene's tools, in scene order
  std::vector<double> times;        ///< the sample times [s], shared by every tool
};

/// Maps the scene to the reference problem: materials per region (layers first, then `body`,
/// with the scene's law), bonded/sliding supports, and the tool: a blade as a wedge, a sphere in
/// penalty contact, or — a sphere whose start touches the body and whose trajectory never moves
/// towards it (clay_pull) — tied: the `top` triangles whose three nodes lie within the sphere
/// radius of the first contact point (if none, those with at least one such node) get the
/// prescribed displacement u = p(t) − p(0), the tool displacement since contact, or, with a
/// Tool::grasp_stiffness k, an elastic foundation t = k (d − u) towards d = p(t) − p(0) (a
/// compliant grasp; reference::ElasticFoundation). Several tools
/// (clay_tear: two hands pulling) are coupled only as tied styluses, each with its own tie group
/// `stylus_tie_<name>`. Throws std::invalid_argument for several tools of which one is not a tied
/// stylus, tools on different time lines, or a tied tool without a `top` surface. The load factor
/// of sample k is t_k / T (T the trajectory duration).
ReferenceProblem reference_problem(const Scene& scene, const TetMesh& mesh);

/// What a reference run solved: its profile, and why its load path stopped before the trajectory's
/// end (empty: it reached the end).
struct ReferenceResult {
  ReferenceResult() = default;
  /// A run that reached the end is its profile (implicit: a study's stand-in reference returns one).
  ReferenceResult(ForceProfile p, std::string why_stopped = {}) // NOLINT(google-explicit-constructor)
      : profile(std::move(p)), stopped(std::move(why_stopped)) {}
  ForceProfile profile;
  std::string stopped;
  [[nodiscard]] bool complete() const { return stopped.empty(); }
};

/// Runs the reference on the scene (see file comment) and returns the profile: one row per tool per
/// solved sample — the requested samples, every vertex of the motion (ReferenceRunSettings::
/// vertex_tolerance) and the samples adaptive sampling inserts, each a load of the path — (t, tool position, force of the body on the tool, mode no-contact when the tool force is
/// zero (tied) / no contact point (penalty) else deformation-1, crack_extent 0, cost_s = solve
/// seconds). The tool force of a tied tool is the reaction on the tied nodes (a compliant grasp:
/// the force of the body on its layer, −∫ k (d − u) dA). If the load path
/// stops (cut-backs exhausted), returns the profile up to the last converged sample with the stop
/// message (ReferenceResult::stopped), and the manifest records it (`stopped`, `partial`: true).
/// The manifest's `solver.load_path` counts the loads (requested, vertices, inserted) and each
/// sample record says why it is a load (`load`). Writes dir/profile.csv, dir/manifest.json, fields and
/// checkpoints; prints a progress line per sample on stderr. Throws std::invalid_argument on bad
/// settings, std::runtime_error on an unreadable or mismatched checkpoint (another scene, degree,
/// refinement, sample set or process count).
///
/// Under `mpirun -np N`: collective (every process calls it and gets the same profile); rank 0
/// alone writes profile.csv, manifest.json, checkpoint.bin and fields.pvd and prints the progress
/// (with `distribute` false the call is this process's own, and it writes);
/// distributed fields are fields/step_NNNN.pvtu with one .vtu piece per process.
ReferenceResult run_reference(const Scene& scene, const TetMesh& mesh, const ReferenceRunSettings& settings,
                              const std::filesystem::path& dir);

} // namespace kerf
