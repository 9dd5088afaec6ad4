#pragma once
// FiniteStrainSolver: kerf's offline ground truth — quasi-static, total-Lagrangian finite-strain
// elasticity on the scene's tetrahedra (FE_SimplexP of degree 1 or 2, simplex quadrature, MappingFE;
// deal.II 9.4), Newton–Raphson with a backtracking line search, Dirichlet supports, dead-load
// tractions and a rigid tool in penalty contact. In the spirit of deal.II's step-44 and the code
// gallery's "Quasi-Static Finite-Strain Compressible Elasticity", written for tetrahedra.
//
// Under `mpirun -np N` (N > 1) the solver is distributed: the mesh is split over the N processes
// (parallel::fullydistributed::Triangulation), PETSc MPI vectors and matrix, MUMPS or CG + GAMG;
// every member function is then collective (all processes call it, in the same order) and
// returns the same global values on every process unless its comment says otherwise. Started
// on its own, the program solves serially (deal.II vectors, UMFPACK) without initialising MPI.
//
// This header is plain data + pimpl: it includes no deal.II or PETSc, so the rest of kerf compiles
// without them (deal.II is included only by the solver's own sources in this folder:
// finite_strain_solver.cpp, solver/ and tangent_solver.cpp; mpi_processes.cpp includes PETSc).

#include "meshes/material_law.hpp"
#include "meshes/tet_mesh.hpp"
#include "reference/cohesive/cohesive_law.hpp"
#include "reference/rigid_tool.hpp"

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace kerf::reference {

/// Which hyperelastic law a region uses (one class each in reference/material/): the shared
/// MaterialLaw (meshes/material_law.hpp) under the reference's name.
using LawKind = ::kerf::MaterialLaw;

/// The material of one gmsh physical volume.
struct MaterialRegion {
  std::string volume_group = "body"; ///< TetMesh volume group name
  LawKind law = LawKind::neo_hookean;
  double youngs_modulus = 0.0; ///< E [Pa] > 0
  double poisson_ratio = 0.0;  ///< ν in (-1, 0.5)
  /// ρ [kg/m^3] in the reference configuration: the consistent mass of the dynamic step
  /// (SolverSettings::dynamic; must then be > 0), unused by the quasi-static solve.
  double density = 0.0;
  /// Kelvin–Voigt viscosity η [Pa s] >= 0 (the scene's `damping`): with SolverSettings::dynamic a
  /// viscous stress S_v = (η/E) ℂ₀ : Ė on the Green–Lagrange strain rate joins the elastic one
  /// (reference/material/kelvin_voigt.hpp; every mode's damping ratio ζ = ωη/(2E)); the
  /// quasi-static solve has no rate and ignores it.
  double damping = 0.0;
};

/// A displacement condition on a named TetMesh surface group.
struct DisplacementBoundary {
  enum class Kind {
    bonded,    ///< u = 0 (all components)
    sliding,   ///< u·n = 0 on a plane surface normal to a coordinate axis (n = ±e_k)
    prescribed ///< u_k = g_k(X, load factor) for the components marked in `components`
  };
  std::string surface;
  Kind kind = Kind::bonded;
  /// prescribed: the displacement [m] at reference point X [m] and load factor in [0, 1].
  std::function<Eigen::Vector3d(const Eigen::Vector3d& X, double load)> displacement;
  std::array<bool, 3> components{true, true, true}; ///< prescribed: which components are fixed
};

/// An elastic foundation (a Robin condition) on a named TetMesh surface group: the surface is held
/// by a compliant layer to an anchor that moves by the prescribed displacement d(X, load factor).
/// The layer puts the traction t = k (d − u) per unit reference area on the body (energy
/// ½ k ∫ |u − d|² dA), linear in u: its tangent is k times the surface "mass" matrix ∫ N_a N_b dA
/// on each component. A stylus that grasps the surface through an adhesive layer of finite
/// stiffness (docs/scenes.md "Grasp"); k → ∞ is the rigid tie (a prescribed DisplacementBoundary).
struct ElasticFoundation {
  std::string surface;
  double stiffness = 0.0; ///< k [N/m^3] > 0: traction per unit reference area per metre of stretch
  /// The anchor's displacement [m] at reference point X [m] and load factor in [0, 1].
  std::function<Eigen::Vector3d(const Eigen::Vector3d& X, double load)> displacement;
  /// The layer's stiffness at reference point X as a fraction of `stiffness`, in [0, 1]; absent:
  /// uniform (1). A profile that falls to zero at the surface's rim keeps the traction continuous
  /// there (a uniform layer ends in a traction step at the rim, which concentrates the stress).
  std::function<double(const Eigen::Vector3d& X)> profile;

  /// The profile of a grasped disc's layer: stiffest at the disc's centre c, ending at its rim,
  /// k(X)/k = max(0, 1 − |X − c|²/a²) for a disc of radius a (docs/scenes.md, "Grasp").
  static std::function<double(const Eigen::Vector3d& X)> tapered_disc(const Eigen::Vector3d& centre, double radius) {
    return [centre, radius](const Eigen::Vector3d& X) {
      return std::max(0.0, 1.0 - (X - centre).squaredNorm() / (radius * radius));
    };
  }
};

/// A dead-load traction: a uniform traction per unit reference area on a named surface whose
/// resultant is `load factor × total_force` [N], direction fixed in space (as in the code gallery's
/// Cook's membrane).
struct TractionBoundary {
  std::string surface;
  Eigen::Vector3d total_force = Eigen::Vector3d::Zero(); ///< [N] at load factor 1
};

/// A cohesive interface along a crack path (Reference II): the mesh has been split along the crack
/// (meshes/crack_split.hpp) so that its two sides are the surface groups `plus_surface` and
/// `minus_surface`. The solver pairs their coincident faces by position (also after global
/// refinement) and joins them with the bilinear law of reference/cohesive/cohesive_law.hpp,
/// integrated at the face quadrature points of the + side: the interface element of Ortiz &
/// Pandolfi 1999 (§2), with the opening Δ = x⁺ − x⁻ interpolated by each side's own shape functions.
/// The normal is the reference one (n from − into +): the interface is geometrically linear, which
/// holds while the crack faces rotate little (the blade and tearing scenes; say so where it matters).
struct CohesiveInterfaceSpec {
  std::string plus_surface;  ///< e.g. "cut_plane+"
  std::string minus_surface; ///< e.g. "cut_plane-"
  CohesiveLawParameters law;
};

/// The boundary-value problem: mesh (metres), materials, supports, loads, tool.
struct FiniteStrainProblem {
  TetMesh mesh;
  std::vector<MaterialRegion> materials; ///< first matching region wins; every tet needs one
  std::vector<DisplacementBoundary> displacement_boundaries;
  std::vector<TractionBoundary> tractions;
  std::vector<ElasticFoundation> foundations; ///< compliant grasps (elastic foundations)
  std::optional<RigidToolShape> tool;    ///< rigid tool in frictionless penalty contact
  std::optional<CohesiveInterfaceSpec> cohesive; ///< crack path held by a cohesive law
};

/// Linear solver for each Newton step.
enum class LinearSolverChoice {
  automatic, ///< direct up to SolverSettings::direct_dof_limit DOFs or a factor of direct_factor_limit entries, iterative above
  direct,    ///< UMFPACK (deal.II SparseDirectUMFPACK) on an optimised BLAS; distributed: MUMPS
  iterative  ///< PETSc CG + GAMG with the rigid-body near null space; unpreconditioned-norm stop
};

/// Newton's line search along the step du from u (newton_raphson.cpp).
enum class LineSearch {
  /// Backtracking α = 1, ½, … (6 tries) until the free residual's norm decreases,
  /// |R(u + α du)| <= (1 − 10⁻⁴ α) |R(u)|.
  residual_norm,
  /// The energy's directional derivative s(α) = du · R(u + α du) (Matthies & Strang 1979, the line
  /// search of their BFGS; FEBio's): α is accepted when |s(α)| <= 0.9 |s(0)|, else the next α is
  /// the secant root α s(0) / (s(0) − s(α)), kept within [α/10, α/2] (6 tries). For a load with a
  /// potential (hyperelasticity, dead loads) the full Newton step is taken far from equilibrium
  /// where the residual's norm would cut it, though |R| may grow on that step.
  energy
};

/// The load of one equilibrium solve.
struct LoadState {
  double load_factor = 0.0;                               ///< scales tractions and prescribed u
  Eigen::Vector3d tool_position = Eigen::Vector3d::Zero(); ///< tool reference point [m]
  double time = 0.0; ///< [s] trajectory time; its increment drives the cohesive viscous term
};

/// Discretisation and solver settings (validated by the solver's constructor).
struct SolverSettings {
  int degree = 1;        ///< FE_SimplexP degree, 1 or 2
  int refinements = 0;   ///< global refinements of the mesh (each splits a tetrahedron into 8)
  LinearSolverChoice linear_solver = LinearSolverChoice::automatic;
  std::size_t direct_dof_limit = 60000; ///< automatic: direct up to this many DOFs
  /// automatic, serial, above direct_dof_limit: direct while CHOLMOD's analysis of the tangent's
  /// pattern predicts at most this many entries in the Cholesky factor (8 bytes each; UMFPACK's
  /// LU, which takes an indefinite tangent, needs several times that), else iterative; 0: never.
  double direct_factor_limit = 1e8;
  double relative_tolerance = 1e-9;     ///< Newton: |R_free| <= rel × (|f_int| + |f_ext|) + abs (newton_raphson.cpp: or a stall within 10× that)
  double absolute_tolerance = 1e-12;    ///< [N]
  int max_newton_iterations = 25;
  LineSearch line_search = LineSearch::residual_norm;
  double iterative_tolerance = 1e-10;   ///< CG: true (unpreconditioned) residual relative to |b|
  /// Contact penalty ε_N [Pa/m]; 0 = automatic, 50 E_max / h_min (h_min the shortest edge after
  /// refinement), i.e. a penetration of 2% of an element under a stress of E.
  double contact_penalty = 0.0;
  /// Blade edge pass (blade_edge_contact.hpp): line penalty ε_L [N/m²]; 0 = automatic, ε_N h_min
  /// (= 50 E_max with the automatic ε_N).
  double edge_line_penalty = 0.0;
  /// Blade edge pass: edge point spacing [m]; 0 = automatic, h_min / 4.
  double edge_point_spacing = 0.0;
  /// Newton's start: the last two converged states extrapolated linearly along the trajectory
  /// (tool travel, else load factor, else time for a rate-dependent problem), u = u₁ + s (u₁ − u₀),
  /// 0 <= s <= 2; from u₁ again if Newton fails from there. The equilibrium found is the same to
  /// the Newton tolerance, not to the bit: the predictor's history is not part of `state()`, so a
  /// run resumed from a checkpoint would differ from the uninterrupted one in the last digits.
  /// Off by default for that reason.
  bool extrapolate_initial_guess = false;
  /// Quasi-Newton between tangents (serial direct solver): steps with the last factorised tangent
  /// and the limited-memory BFGS updates of the steps since (Matthies & Strang 1979), a full
  /// Newton step (tangent assembled and factorised) first in every solve, when a Dirichlet
  /// increment is pending, and after a step that reduced |R| by less than half. Converges to the same tolerance as full Newton. Problems
  /// with a tool in contact or a cohesive interface use full Newton (their tangent changes abruptly).
  /// Serial only; the distributed and the iterative solvers take full Newton steps.
  bool quasi_newton = true;
  /// Launched by mpirun with N > 1 processes: distribute the mesh over them (true), or solve the
  /// whole problem on this process alone (false, e.g. a serial comparison inside an MPI job).
  bool distribute = true;
  /// Fault injection (issue 10, docs/reliability.md; empty in every real run): called before the
  /// assembly of each Newton iteration with the load being solved and the iteration (0-based);
  /// when it returns true, that iteration's assembled residual is made NaN, as an overflowing
  /// material or contact term would make it. `solve` must take it for failure (state restored,
  /// converged false), never for convergence, so the load path cuts back or stops.
  std::function<bool(const LoadState& load, int newton_iteration)> residual_fault;
  /// Dynamic (inertial) step instead of the quasi-static one: implicit Newmark average acceleration
  /// (Newmark 1959, β = 1/4, γ = 1/2; Hughes, The Finite Element Method, §9.1: the trapezoidal rule,
  /// unconditionally stable, no numerical dissipation) with the consistent mass M_ab = ∫ ρ N_a N_b dV
  /// of FE_SimplexP (cell matrices computed once). Each solve finds u_{n+1} with
  ///   M a_{n+1} + f_int(u_{n+1}) = f_ext,   a_{n+1} = 4/h² (u_{n+1} − u_n) − 4/h v_n − a_n,
  ///   v_{n+1} = v_n + h/2 (a_n + a_{n+1}),   h = LoadState::time − the last converged time,
  /// Newton's tangent gaining 4 M/h². A solve at the same time as the last one (h = 0, e.g. the
  /// first sample) is quasi-static and leaves v and a unchanged; the body starts at rest (v = a = 0).
  /// Reactions (and the tool forces of tied styluses) include the inertia of the driven nodes.
  /// Distributed too (u_n, v_n, a_n gathered on every process when a step is committed). Every
  /// material region needs a density > 0.
  /// A region's `damping` η > 0 adds the Kelvin–Voigt viscous stress (MaterialRegion::damping), its
  /// velocity v_{n+1} = 2/h (u_{n+1} − u_n) − v_n (γ/(βh) = 2/h in Newton's tangent).
  bool dynamic = false;
};

/// The cohesive interface after a converged solve (all zero without one). Energies per the whole
/// interface; areas in the reference configuration.
struct CohesiveSummary {
  double failed_area = 0.0;        ///< area whose points have failed (κ >= δ_f) [m^2]
  double damaged_area = 0.0;       ///< area whose points are past the peak (κ > δ_0) [m^2]
  double stored_energy = 0.0;      ///< recoverable interface energy ∫ φ_e dA [J]
  double dissipated_energy = 0.0;  ///< cohesive dissipation ∫ φ_d(κ) dA, total so far [J]
  double viscous_dissipation = 0.0; ///< ∫∫ η |Δ̇|² dA dt, total so far [J]
  /// Dynamic step only (0 otherwise): the work the interface's tractions (without the viscous
  /// part) did in the time integration, Σ_steps ∫ ½ (t_n + t_{n+1})·(Δ_{n+1} − Δ_n) dA [J], the
  /// trapezoidal rule that the Newmark average-acceleration energy identity books. It equals
  /// stored_energy + dissipated_energy when the law is piecewise linear within every step; when a
  /// point crosses a kink of the bilinear envelope within one step (peak or failure, above all a
  /// ligament that opens past δ_f in one step), the difference is the time integration's error
  /// at the kink, which shrinks with the time step.
  double trapezoid_work = 0.0;
  /// Dynamic step only: this step's share of the kinks' error, the trapezoid work of the interface
  /// tractions over the step minus the step's change of stored_energy + dissipated_energy [J]
  ///   e = Σ_points w [½ (t_n + t_{n+1})·(Δ_{n+1} − Δ_n) − Δ(φ_e + φ_d)],
  /// zero when every point stays on one linear piece of the law within the step. The load path's
  /// interface energy control (LoadPathSettings) rejects and halves a step whose |e| is too large.
  double step_time_integration_error = 0.0;
  double step_dissipation = 0.0; ///< dynamic step only: the step's increase of dissipated_energy [J]
  double max_damage = 0.0;         ///< largest 1 − K(κ)/K_0 over the points
};

/// Where a solver's time went, summed over its solves since construction: this process's wall
/// clock [s]. The parts do not overlap; the rest of a solve (line-search vector updates, norms,
/// constraints, the commit of a converged step) is the difference to its whole time.
struct SolverTimings {
  /// Residual and tangent assembly: the cells, the tool contact (flanks and edge pass), the
  /// foundations and the cohesive interface (the communication inside excluded).
  double assembly_seconds = 0.0;
  /// The linear solver's set-up: factorisations (CHOLMOD/UMFPACK with their analyses, MUMPS) or
  /// the preconditioner's (GAMG); communication inside MUMPS and GAMG included.
  double factorization_seconds = 0.0;
  /// Forward and back substitutions, or the Krylov iterations.
  double solve_seconds = 0.0;
  /// Distributed: the ghost values' exchange, the assembled matrix's and vectors' exchange
  /// (compress), the reductions of norms, tallies and the edge pass's boundary displacements —
  /// waiting for the other processes (load imbalance) included. 0 on one process.
  double communication_seconds = 0.0;
};

/// The reaction at one displacement boundary: the force the body puts on that support.
struct BoundaryReaction {
  std::string surface;                               ///< the DisplacementBoundary's surface group
  Eigen::Vector3d force = Eigen::Vector3d::Zero();   ///< body on support [N]: −Σ R_a over its DOFs
};

/// What one equilibrium solve did and found.
struct EquilibriumReport {
  bool converged = false;
  int newton_iterations = 0;
  std::vector<double> residual_history; ///< |R_free| [N] before each Newton step
  Eigen::Vector3d tool_force = Eigen::Vector3d::Zero();       ///< contact resultant: body on tool [N]
  Eigen::Vector3d support_reaction = Eigen::Vector3d::Zero(); ///< body on its supports [N]
  Eigen::Vector3d traction_resultant = Eigen::Vector3d::Zero(); ///< applied tractions on the body [N]
  /// One entry per FiniteStrainProblem::displacement_boundaries, in that order. A DOF on two
  /// boundaries counts for the first bonded/prescribed one (else the first sliding one), so the
  /// entries sum to `support_reaction`.
  std::vector<BoundaryReaction> boundary_reactions;
  /// One entry per FiniteStrainProblem::foundations, in that order: the force of the body on the
  /// foundation's anchor, −∫ k (d − u) dA [N] (the same sign as a reaction: body on its holder).
  std::vector<Eigen::Vector3d> foundation_forces;
  /// Energy stored in the elastic foundations, ½ k ∫ |u − d|² dA summed over them [J].
  double foundation_energy = 0.0;
  /// Global balance of the body: traction_resultant − tool_force − support_reaction − Σ
  /// foundation_forces [N]; zero at equilibrium up to the free-DOF residual (Newton's third law:
  /// the body is at rest).
  Eigen::Vector3d force_imbalance = Eigen::Vector3d::Zero();
  CohesiveSummary cohesive; ///< the interface after this solve (converged solves only)
  int contact_points = 0;    ///< boundary quadrature points inside the tool
  double contact_area = 0.0; ///< reference area of those points' weights [m^2]
  double max_contact_pressure = 0.0; ///< [Pa]
  int edge_contact_points = 0;       ///< blade edge points inside the body (blade_edge_contact.hpp)
  double edge_contact_length = 0.0;  ///< edge length in contact [m]
  double max_edge_line_load = 0.0;   ///< largest edge line load ε_L d [N/m]
  /// Energy stored in the tool's penalty contact [J]: ∫ ½ ε_N p² dA over the flank points plus
  /// Σ ½ ε_L w d² over the edge points (the potentials whose derivatives are the contact forces).
  double contact_energy = 0.0;
  /// Kinetic energy ½ vᵀ M v [J] after this solve (0 for the quasi-static step).
  double kinetic_energy = 0.0;
  /// Energy dissipated by the Kelvin–Voigt damping so far [J] (dynamic step with a region's
  /// `damping` > 0, else 0): Σ_steps ½ (f_v,n + f_v,n+1)·(u_{n+1} − u_n) over all DOFs, f_v the
  /// viscous nodal forces — the trapezoid rule that the Newmark energy identity books for them.
  double damping_dissipation = 0.0;
  double assembly_seconds = 0.0;
  double linear_solve_seconds = 0.0;
  int linear_iterations = 0; ///< iterative solver: total CG iterations
  int factorizations = 0;    ///< tangents assembled and factorised (the rest were quasi-Newton steps)
  std::string failure;       ///< why it did not converge (empty if converged)
};

/// The finite-strain reference solver (see file comment). Holds the current displacement state;
/// `solve` moves it to equilibrium under a new load, or leaves it unchanged on failure.
class FiniteStrainSolver {
public:
  /// Builds the triangulation from `problem.mesh` (volume groups -> material_id, surface groups
  /// -> boundary_id by name), the finite element space and the supports. Throws
  /// std::invalid_argument naming the field on bad input (unknown group, a tet without material,
  /// a sliding surface that is not axis-aligned, degree not 1 or 2).
  FiniteStrainSolver(const FiniteStrainProblem& problem, const SolverSettings& settings);
  ~FiniteStrainSolver();
  FiniteStrainSolver(const FiniteStrainSolver&) = delete;
  FiniteStrainSolver& operator=(const FiniteStrainSolver&) = delete;

  /// Newton–Raphson from the current state to equilibrium under `load`. On success the state is
  /// the new equilibrium; on failure (no convergence in max iterations, an inverted element, a
  /// non-finite residual) the state is restored and report.converged is false.
  EquilibriumReport solve(const LoadState& load);

  [[nodiscard]] std::size_t dof_count() const;
  [[nodiscard]] std::size_t cell_count() const;
  /// "cholmod/umfpack" (serial direct, sparse_direct.hpp), "mumps" (distributed direct) or
  /// "petsc-cg-gamg": what `solve` uses.
  [[nodiscard]] std::string linear_solver_name() const;
  /// Why `linear_solver_name()` (LinearSolverChoice::automatic: the DOF count against
  /// direct_dof_limit, CHOLMOD's predicted factor against direct_factor_limit — on one process or
  /// gathered from all — and, when GAMG did not converge on a system, that the direct solver took
  /// over from there and why), e.g. "direct: 63498 DOFs > direct_dof_limit 60000; predicted
  /// Cholesky factor 2.9e+07 entries <= direct_factor_limit 1e+08".
  [[nodiscard]] std::string linear_solver_reason() const;
  /// The contact penalty in use [Pa/m].
  [[nodiscard]] double contact_penalty() const;
  /// The number of MPI processes the mesh is distributed over (1: serial).
  [[nodiscard]] int process_count() const;
  /// Cohesive interface: its quadrature points (0 without one) and how far the failed part
  /// reaches along `direction` (unit) beyond the interface's first point along it [m] — the crack
  /// depth c of paper 001 Fig. 3 when `direction` is the cutting direction; 0 if nothing failed.
  /// Both of the whole interface; crack_extent is collective when distributed.
  [[nodiscard]] std::size_t cohesive_point_count() const;
  [[nodiscard]] double crack_extent(const Eigen::Vector3d& direction) const;

  /// Displacement [m] at reference point X (evaluated in the tetrahedron containing X). Throws
  /// std::out_of_range if X lies outside the mesh.
  [[nodiscard]] Eigen::Vector3d displacement_at(const Eigen::Vector3d& X) const;
  /// Cauchy stress [Pa] at every cell quadrature point of the current state (distributed: of this
  /// process's locally owned cells only).
  [[nodiscard]] std::vector<Eigen::Matrix3d> quadrature_cauchy_stresses() const;
  /// Stored elastic energy of the body ∫ ψ(F) dV over the reference volume [J] (for energy
  /// balances: external work = strain energy + interface energy + dissipation).
  [[nodiscard]] double strain_energy() const;
  /// Largest displacement magnitude over the DOFs [m].
  [[nodiscard]] double max_displacement() const;
  /// Kinetic energy ½ vᵀ M v [J] of the last converged state (0 without SolverSettings::dynamic).
  [[nodiscard]] double kinetic_energy() const;
  /// Kelvin–Voigt dissipation so far [J] (EquilibriumReport::damping_dissipation; 0 undamped).
  [[nodiscard]] double damping_dissipation() const;
  /// Where this process's solve time went so far (SolverTimings).
  [[nodiscard]] SolverTimings timings() const;

  /// The state for a checkpoint: the DOF values of the displacement, all of them in global DOF
  /// order on every process (distributed: gathered; the numbering depends on the process count,
  /// so a state is restored with the same number of processes), followed (with a cohesive
  /// interface) by each interface point's history (κ, previous opening), in the order of the whole
  /// interface's face pairs (the same for any process count), the last time and the viscous
  /// dissipation, and
  /// (with SolverSettings::dynamic) by the velocity and acceleration DOFs, the last time and the
  /// interface's trapezoid work (CohesiveSummary::trapezoid_work), and (dynamic with damping in
  /// some region) the Kelvin–Voigt dissipation so far. Collective when distributed.
  [[nodiscard]] std::vector<double> state() const;
  /// Restores a checkpointed state. Throws std::invalid_argument on a size mismatch.
  void set_state(const std::vector<double>& values);

  /// Writes the current fields (displacement; J, Cauchy stress, von Mises per point; contact
  /// pressure and material id per cell) with the tool at `load.tool_position` to `file`: a .vtu
  /// when serial; distributed, `file` is a .pvtu record (written by rank 0) listing one .vtu piece
  /// per process, `<stem>.<rank>.vtu` beside it, each file written atomically.
  void write_fields(const std::filesystem::path& file, const LoadState& load) const;

  struct Impl;

private:
  std::unique_ptr<Impl> m_impl;
};

} // namespace kerf::reference
