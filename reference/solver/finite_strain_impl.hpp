#pragma once
// FiniteStrainSolver::Impl, the deal.II side of the finite-strain reference (finite_strain_solver.hpp):
// its data, grouped by idea, and where each part is coded. Private to reference/; only the
// solver's own translation units include it.
//
// The solver in the order of deal.II's step-44 (one file each, in reference/solver/ unless named):
//   system_setup.cpp        triangulation from TetMesh, FE space, DOFs, Dirichlet constraints,
//                           tractions, sparsity (step-44's make_grid, system_setup, make_constraints)
//   assemble_system.cpp     total-Lagrangian residual and tangent of the hyperelastic cells, the
//                           inertia term, dead-load tractions and the tool's flank contact
//   newton_raphson.cpp      Newton–Raphson: line search, quasi-Newton (BFGS), convergence, reactions
//   newmark_dynamics.cpp    the dynamic step: consistent mass, Newmark update, Kelvin–Voigt forces
//   blade_edge_pass.cpp     the wedge tool's edge in contact (contact/blade_edge_contact.hpp)
//   cohesive_interface.cpp  the cohesive crack path: face pairs, opening, assembly, history commit
//   grasp_foundation.cpp    elastic foundations (a compliant grasp): traction k (d − u), its tangent
//   checkpoint_state.cpp    state() and set_state(): the solver's state as a vector of numbers
//   field_output.cpp        write_fields: displacement, stresses and contact pressure as .vtu
//   ../finite_strain_solver.cpp  the public class and the load-step driver (predictor, Newton)
//
// The templates on the algebra (algebra.hpp) are defined in the file of their idea and
// instantiated there explicitly for SerialAlgebra and DistributedAlgebra (see each file's end).

#include "reference/contact/blade_edge_contact.hpp"
#include "reference/finite_strain_solver.hpp"
#include "reference/material/hyperelastic_law.hpp"
#include "reference/material/kelvin_voigt.hpp"
#include "reference/solver/algebra.hpp"
#include "reference/solver/cell_matrix_scatter.hpp"
#include "reference/tangent_solver.hpp"

#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/distributed/fully_distributed_tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/vector.h>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace kerf::reference {

inline Eigen::Matrix3d to_eigen(const dealii::Tensor<2, 3>& t) {
  Eigen::Matrix3d m;
  for (unsigned i = 0; i < 3; ++i)
    for (unsigned j = 0; j < 3; ++j) m(i, j) = t[i][j];
  return m;
}
inline Eigen::Vector3d to_eigen(const dealii::Point<3>& p) { return {p[0], p[1], p[2]}; }

struct FiniteStrainSolver::Impl {
  SolverSettings settings;

  // ---- The discretisation (system_setup.cpp) ----------------------------------------------------
  std::vector<std::string> surface_names;
  dealii::Triangulation<3> tria; // the whole mesh, on every process (refined before distribution)
  bool distributed = false;      // the mesh is distributed over MPI_COMM_WORLD's processes
  int process_count = 1;
  int rank = 0;
  std::unique_ptr<dealii::parallel::fullydistributed::Triangulation<3>> distributed_tria;
  std::unique_ptr<dealii::FESystem<3>> fe;
  std::unique_ptr<dealii::MappingFE<3>> mapping;
  dealii::DoFHandler<3> dof;
  std::unique_ptr<dealii::Quadrature<3>> cell_quadrature; // the stresses and the tangent (system_setup.cpp)
  std::unique_ptr<dealii::Quadrature<3>> mass_quadrature; // the consistent mass matrix, exact for N_i N_j
  std::unique_ptr<dealii::QGaussSimplex<2>> face_quadrature;
  double h_min = 0.0; // the shortest edge of the (refined) mesh [m]
  // Per DOF 3k + c: coordinate c of node k in the reference configuration [m] (the DOFs of
  // artificial cells of a distributed mesh: 0).
  std::vector<double> reference_coordinate;

  // The reference geometry of every cell, computed once (total Lagrangian: the shape gradients
  // with respect to X and the weights JxW never change): per active cell index, the scalar
  // FE_SimplexP shape gradients [q][node][3] and JxW[q]. A cell's DOF i is component comp(i) of
  // scalar node node_of_dof[i], and Grad N_i = e_comp ⊗ gradient of that node.
  struct CellGeometry {
    unsigned nodes = 0, points = 0;
    std::vector<unsigned> node_of_dof;
    std::vector<double> gradients; // cell × points × nodes × 3
    std::vector<double> JxW;       // cell × points
    [[nodiscard]] const double* gradient(std::size_t cell, unsigned q, unsigned node) const {
      return &gradients[((cell * points + q) * nodes + node) * 3];
    }
  } geometry;

  // ---- The materials, by material_id (= index of the MaterialRegion) ----------------------------
  std::vector<std::unique_ptr<HyperelasticLaw>> laws;
  std::vector<double> youngs;
  std::vector<double> densities;           // [kg/m^3]
  std::vector<KelvinVoigtDamping> damping; // dynamic step only

  // ---- Supports and loads (system_setup.cpp) ------------------------------------------------------
  std::vector<DisplacementBoundary> boundaries;
  // Dirichlet DOFs and how to get their target value.
  struct DirichletDof {
    dealii::types::global_dof_index index;
    unsigned component;
    int boundary; // index into displacement_boundaries
    Eigen::Vector3d X;
  };
  std::vector<DirichletDof> dirichlet;
  std::vector<std::pair<int, Eigen::Vector3d>> tractions; // surface group, traction [Pa]
  std::vector<std::vector<int>> face_classes;               // boundary_id -> surface groups
  bool in_group(dealii::types::boundary_id id, int group) const {
    const auto& c = face_classes[id];
    return std::find(c.begin(), c.end(), group) != c.end();
  }
  double dirichlet_target(const DirichletDof& d, double load) const {
    const DisplacementBoundary& b = boundaries[static_cast<std::size_t>(d.boundary)];
    if (b.kind != DisplacementBoundary::Kind::prescribed) return 0.0;
    return b.displacement(d.X, load)[d.component];
  }

  // ---- Elastic foundations (grasp_foundation.cpp) -------------------------------------------------
  struct Foundation {
    int group = -1;         // surface group
    double stiffness = 0.0; // k [N/m^3]
    std::function<Eigen::Vector3d(const Eigen::Vector3d& X, double load)> displacement;
    std::function<double(const Eigen::Vector3d& X)> profile; // k(X) / k; absent: 1
  };
  std::vector<Foundation> foundations;

  // ---- The linear algebra (algebra.hpp) and the linear solver (tangent_solver.hpp) ---------------
  SerialAlgebra serial;
  CellMatrixScatter cell_scatter; // serial: the places of each cell's entries in serial.K
  // Only when distributed: PETSc objects need PETSc (and MPI) initialised, which a serial run never does.
  std::unique_ptr<DistributedAlgebra> parallel;
  std::unique_ptr<TangentSolver> linear;

  /// Calls f with the algebra in use (the distributed one when the mesh is distributed).
  template <class F> decltype(auto) with_algebra(F&& f) { return distributed ? f(*parallel) : f(serial); }
  template <class F> decltype(auto) with_algebra(F&& f) const {
    return distributed ? f(static_cast<const DistributedAlgebra&>(*parallel)) : f(serial);
  }
  /// Sums over the processes (in place) when distributed.
  void sum(std::span<double> values) const {
    if (distributed && !values.empty()) {
      const ScopedTimer timer(timings.communication_seconds);
      dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(values.data(), values.size()), parallel->comm,
                                  dealii::ArrayView<double>(values.data(), values.size()));
    }
  }
  double sum(double value) const {
    if (!distributed) return value;
    const ScopedTimer timer(timings.communication_seconds);
    return dealii::Utilities::MPI::sum(value, parallel->comm);
  }
  double max(double value) const {
    if (!distributed) return value;
    const ScopedTimer timer(timings.communication_seconds);
    return dealii::Utilities::MPI::max(value, parallel->comm);
  }
  double min(double value) const { return -max(-value); }
  /// All DOF values of the distributed vector `v` on every process (collective).
  [[nodiscard]] dealii::Vector<double> gathered(const dealii::PETScWrappers::MPI::Vector& v) const;
  // Where the solves' time went (SolverTimings): the assembly without the communication inside
  // it, and the communication outside the ghost exchange (DistributedAlgebra::exchange_seconds).
  mutable SolverTimings timings;
  /// |r| over the free DOFs (the Dirichlet entries masked out).
  template <class VectorType> double free_norm(const VectorType& r, const VectorType& mask) const {
    VectorType copy = r;
    copy.scale(mask);
    return copy.l2_norm();
  }

  // ---- The rigid tool in penalty contact (assemble_system.cpp: flanks; blade_edge_pass.cpp: edge) -
  std::optional<RigidToolShape> tool;
  double penalty = 0.0;

  // Blade edge pass (contact/blade_edge_contact.hpp), the second contact pass of a wedge tool: the
  // boundary facets of the whole body as flat triangles on compact node numbers (a P2 face split
  // into four at its edge midpoints). Every process holds all of them and supplies the
  // displacements of the nodes it is the first process to hold; each searches its share of the
  // edge points against all the facets, the terms found are shared, and each process assembles
  // those on the facets of its own cells.
  struct BladeEdgeBoundary {
    std::vector<BoundaryFacet> facets;                     // compact node numbers, outward
    std::vector<char> facet_here;                          // this process assembles its terms
    std::vector<dealii::types::global_dof_index> node_of;  // compact -> global node k (DOFs 3k + c)
    std::vector<Eigen::Vector3d> positions;                // compact -> reference position [m]
    std::vector<char> node_here;                           // this process supplies its displacement
    BladeEdgeContactSettings settings;
    mutable std::vector<double> displacement;              // 3 per compact node, per assembly
  };
  std::optional<BladeEdgeBoundary> blade_edge;

  // ---- The cohesive interface, Reference II (cohesive_interface.cpp) ------------------------------
  // Coincident face pairs of the split crack path, with each side's shape values cached at the
  // + face's quadrature points (the reference configuration does not change), and one history per
  // quadrature point.
  struct CohesivePair {
    std::size_t index = 0; // the pair's place among the whole interface's pairs (build_cohesive)
    std::vector<dealii::types::global_dof_index> dofs; // the + cell's n DOFs, then the − cell's n
    std::vector<std::vector<double>> plus_values;      // [q][i]: N_i of the + cell (component comp[i])
    std::vector<std::vector<double>> minus_values;     // [q][j]: N_j of the − cell
    std::vector<double> weights;                       // reference area weights JxW
    std::vector<Eigen::Vector3d> points;               // reference positions
    std::array<Eigen::Vector3d, 3> vertices;           // the face's reference vertices
    Eigen::Vector3d normal;                            // n, from − into + (reference)
  };
  // Distributed, each process keeps the pairs whose + cell it owns (the interface elements are
  // owned with the cells that carry them); the − cell may be another process's, and the DOFs of
  // these pairs join the ghost values this process imports (DistributedAlgebra::relevant).
  std::optional<CohesiveLawParameters> cohesive_law;
  std::vector<CohesivePair> cohesive_pairs; // this process's pairs, in the order of `index`
  std::size_t cohesive_pair_total = 0;      // the pairs of the whole interface (all processes)
  std::vector<dealii::types::global_dof_index> cohesive_dofs; // the DOFs of this process's pairs, sorted
  // The faces of the crack path, by active cell index × 4 + face: the unit direction into each
  // face's own material (+n on the + side, −n on the − side), which the wedge contact needs
  // (rigid_tool.hpp, tool_contact's `side`).
  std::map<std::size_t, Eigen::Vector3d> crack_face_sides;
  Eigen::Vector3d crack_side(const dealii::DoFHandler<3>::active_cell_iterator& cell, unsigned f) const {
    if (crack_face_sides.empty()) return Eigen::Vector3d::Zero();
    const auto it = crack_face_sides.find(4 * cell->active_cell_index() + f);
    return it == crack_face_sides.end() ? Eigen::Vector3d::Zero() : it->second;
  }
  std::vector<CohesiveState> cohesive_states; // this process's pairs, pair-major, then quadrature point
  std::vector<unsigned> cell_components;      // component of each local DOF of a cell
  double cohesive_viscous_dissipation = 0.0; // of the whole interface (summed over the processes)
  double cohesive_trapezoid_work = 0.0; // dynamic step only: CohesiveSummary::trapezoid_work (whole interface)

  // ---- The dynamic step (newmark_dynamics.cpp) ------------------------------------------------------
  // Dynamic step (SolverSettings::dynamic): Newmark average acceleration with the
  // consistent mass. Each cell's scalar mass matrix m_ij = ∫ ρ N_i N_j dV over its scalar shape
  // functions (nodes × nodes, the same for the three components) is computed once in build (for
  // this process's cells). The committed state is u_n, v_n, a_n at `committed_time`, all DOFs on
  // every process (distributed: gathered when a step is committed); `step` is h of the solve under
  // way (0: quasi-static, no inertia).
  struct Dynamics {
    std::vector<std::vector<double>> cell_mass; // by active cell index: nodes × nodes, row-major
    std::vector<unsigned> node_of_dof;          // a cell's local DOF -> its scalar node (0 .. nodes-1)
    unsigned nodes = 0;                         // scalar nodes per cell
    dealii::Vector<double> u, v, a;             // u_n, v_n, a_n (all DOFs, global order, every process)
    double step = 0.0;                          // h [s] of the current solve
    double kinetic_energy = 0.0;                // ½ v_nᵀ M v_n [J]
    // Kelvin–Voigt damping (some region's retardation time > 0): the viscous nodal forces
    // f_v(u_n, v_n) of the committed state and the dissipation Σ ½ (f_v,n + f_v,n+1)·Δu so far.
    bool damped = false;
    dealii::Vector<double> viscous_force;
    double damping_dissipation = 0.0;           // [J]
  };
  std::optional<Dynamics> dynamics;

  // ---- The load step (finite_strain_solver.cpp, newton_raphson.cpp) -------------------------------
  double committed_time = 0.0; // LoadState::time of the last converged solve
  // The predictor (SolverSettings::extrapolate_initial_guess): the last two converged loads. The
  // states are la.u (at `load_last`) and la.u_previous (at `load_before`); `history` counts the
  // known ones (0, 1 or 2), reset by set_state.
  int history = 0;
  LoadState load_last, load_before;
  bool cohesive_secant = false; // Newton fallback: the secant interface tangent (cohesive_law.hpp)
  bool poison_residual = false; // fault injection: SolverSettings::residual_fault chose this assembly
  bool fault_fired = false; // the fault injection poisoned an assembly of the solve under way

  // ---- Result of one assembly (assemble_system.cpp) ---------------------------------------------
  template <class VectorType> struct Assembly {
    VectorType residual; // f_int − f_ext − f_contact, all DOFs
    double internal_norm = 0.0;      // |f_int|
    double external_norm = 0.0;      // |f_ext + f_contact|
    Eigen::Vector3d contact_on_body = Eigen::Vector3d::Zero();
    Eigen::Vector3d traction_on_body = Eigen::Vector3d::Zero();
    int contact_points = 0;
    double contact_area = 0.0;
    double max_pressure = 0.0;
    int edge_points = 0;        // blade edge points inside the body
    double edge_length = 0.0;   // their share of the edge [m]
    double max_line_load = 0.0; // [N/m]
    double contact_energy = 0.0; // penalty energy stored in the tool contact (flanks and edge) [J]
    std::vector<Eigen::Vector3d> foundation_on_body; // per foundation: ∫ k (d − u) dA [N]
    double foundation_energy = 0.0;                  // ½ k ∫ |u − d|² dA over the foundations [J]
  };

  // ---- system_setup.cpp ---------------------------------------------------------------------------
  /// The discrete problem, in build's order (step-44's make_grid, system_setup, make_constraints):
  /// the materials and the triangulation, its boundary ids, refined and distributed; the finite
  /// element, the DoFs and the cells' geometry; the support points; the Dirichlet DoFs; the loads
  /// (tractions, foundations, the tool); the dynamic step and the cohesive interface; the sparsity,
  /// the vectors and the linear solver.
  void build(const FiniteStrainProblem& problem);
  /// The material laws of the problem's regions; per tet, the index of the first region holding it.
  std::vector<int> make_materials(const FiniteStrainProblem& problem);
  void make_grid(const TetMesh& mesh, const std::vector<int>& material);
  /// boundary_id = the face's class (its set of surface groups, `face_classes`).
  void set_boundary_ids(const TetMesh& mesh);
  /// Under mpirun with N > 1 processes: partitions `tria` (METIS on its cells' face graph, the
  /// cohesive interface's face pairs joined into it) and builds this process's part.
  void distribute_grid(const FiniteStrainProblem& problem);
  void setup_finite_element();
  /// Each DoF's support point (node-major: DoF 3k + c at node k); fills reference_coordinate.
  std::vector<dealii::Point<3>> support_points();
  void make_dirichlet_dofs(const FiniteStrainProblem& problem, const std::vector<dealii::Point<3>>& support);
  void setup_loads(const FiniteStrainProblem& problem);
  void setup_serial_system(std::vector<dealii::Point<3>> support);
  void setup_distributed_system(const std::vector<dealii::Point<3>>& support);
  /// The index of the mesh's surface group `name`; throws naming `what` (support, traction, …).
  [[nodiscard]] int surface_group(const std::string& name, const char* what) const;
  void build_cell_geometry();
  /// The Dirichlet constraints of the state `u`: the remaining increment target − u on every
  /// Dirichlet DOF (added to `c`, which is closed). Returns the largest |target − u| (all processes).
  template <class Algebra>
  double dirichlet_constraints(const Algebra& la, const typename Algebra::VectorType& u, const LoadState& load,
                               dealii::AffineConstraints<double>& c) const;

  // ---- assemble_system.cpp ------------------------------------------------------------------------
  template <class Algebra>
  void assemble(Algebra& la, const typename Algebra::VectorType& owned_state, const LoadState& load, bool with_matrix,
                Assembly<typename Algebra::VectorType>& out, const dealii::AffineConstraints<double>* constraints,
                typename Algebra::VectorType* rhs);
  /// The cell loop of `assemble`: this process's cells into K, rhs, f_int, f_ext and the tallies.
  template <class VectorType, class MatrixType, class Tally>
  void assemble_cells(const dealii::Vector<double>& state, const LoadState& load, bool with_matrix, Tally& out,
                      const dealii::AffineConstraints<double>* constraints, MatrixType& K, VectorType* rhs,
                      VectorType& f_int, VectorType& f_ext) const;

  // ---- newton_raphson.cpp -------------------------------------------------------------------------
  /// Newton–Raphson from the state in `la.u` (the predictor's or `start`); on failure `la.u` is
  /// set back to `start`, the last converged state.
  template <class Algebra>
  EquilibriumReport newton(Algebra& la, const LoadState& load, const typename Algebra::VectorType& start);
  /// One load's iteration: its state (the assemblies, the step, the quasi-Newton updates, the
  /// interface tangent's choice), its steps (assemble, solve the linear system, line search,
  /// accept the step) and, converged, the reactions and the commit.
  template <class Algebra> class NewtonIteration;

  // ---- newmark_dynamics.cpp -----------------------------------------------------------------------
  void build_dynamics();
  /// a_{n+1} at DOF i for the trial displacement u_i (Newmark β = 1/4: 4/h² (u − u_n) − 4/h v_n − a_n).
  [[nodiscard]] double newmark_acceleration(dealii::types::global_dof_index i, double u) const {
    const Dynamics& d = *dynamics;
    return 4.0 / (d.step * d.step) * (u - d.u[i]) - 4.0 / d.step * d.v[i] - d.a[i];
  }
  /// v_{n+1} at DOF i for the trial displacement u_i (γ = 1/2, β = 1/4: 2/h (u − u_n) − v_n).
  [[nodiscard]] double newmark_velocity(dealii::types::global_dof_index i, double u) const {
    const Dynamics& d = *dynamics;
    return 2.0 / d.step * (u - d.u[i]) - d.v[i];
  }
  /// Commits u_{n+1} (`u`): a_{n+1}, v_{n+1} = v_n + h/2 (a_n + a_{n+1}), and with damping the
  /// viscous forces at (u_{n+1}, v_{n+1}) and the step's dissipation; returns ½ vᵀ M v.
  double commit_dynamics(const dealii::Vector<double>& u);
  /// The Kelvin–Voigt nodal forces f_v,a = ∫ P_v(F, Ḟ) : (e_c ⊗ Grad N_a) dV at displacement u and
  /// velocity v (all DOFs; this process's cells' terms).
  void assemble_viscous_force(const dealii::Vector<double>& u, const dealii::Vector<double>& v,
                              dealii::Vector<double>& out) const;

  // ---- blade_edge_pass.cpp ------------------------------------------------------------------------
  void build_blade_edge();
  /// Distributed: every process's edge contact terms, in rank order (collective).
  [[nodiscard]] std::vector<EdgeContactTerm> all_terms(const std::vector<EdgeContactTerm>& mine) const;
  template <class VectorType, class MatrixType, class Tally>
  void assemble_blade_edge(const dealii::Vector<double>& state, const LoadState& load, bool with_matrix, Tally& out,
                           const dealii::AffineConstraints<double>* constraints, MatrixType& K, VectorType* rhs,
                           VectorType& f_ext) const;

  // ---- grasp_foundation.cpp -----------------------------------------------------------------------
  void build_foundations(const FiniteStrainProblem& problem);
  /// The reference area of surface group `group` [m²], summed over the processes (system_setup.cpp).
  double surface_area(int group) const;
  /// The foundations' traction k (d − u) on this process's faces into f_ext (and rhs), k ∫ N_a N_b dA
  /// into K, their force on the body and energy into `out` (this process's share).
  template <class VectorType, class MatrixType, class Tally>
  void assemble_foundations(const dealii::Vector<double>& state, const LoadState& load, bool with_matrix, Tally& out,
                            const dealii::AffineConstraints<double>* constraints, MatrixType& K, VectorType* rhs,
                            VectorType& f_ext) const;

  // ---- cohesive_interface.cpp ---------------------------------------------------------------------
  void build_cohesive(const CohesiveInterfaceSpec& spec, int plus_group, int minus_group);
  template <class VectorType>
  Eigen::Vector3d cohesive_opening(const CohesivePair& pair, std::size_t q, const VectorType& state) const;
  template <class VectorType, class MatrixType>
  void assemble_cohesive(const dealii::Vector<double>& state, const LoadState& load, bool with_matrix,
                         const dealii::AffineConstraints<double>* constraints, MatrixType& K, VectorType* rhs,
                         VectorType& f_int) const;
  /// Commits every point's history at the converged `state` (algebra.hpp's readable(): this
  /// process's pairs' DOFs) and returns the whole interface's summary (summed over the processes).
  CohesiveSummary commit_cohesive(const LoadState& load, const dealii::Vector<double>& state);
  /// The (+ cell, − cell) active cell indices on `tria` of every face pair of the split crack path,
  /// before any DOF exists (the partition joins them: distribute_grid).
  std::vector<std::pair<unsigned, unsigned>> cohesive_cell_pairs(const CohesiveInterfaceSpec& spec, int plus_group,
                                                                 int minus_group) const;
  /// Distributed: the pairs whose + cell this process owns, numbered as the serial build numbers them.
  void build_distributed_cohesive(const CohesiveInterfaceSpec& spec, int plus_group, int minus_group);
  /// Distributed: the Dirichlet DOFs among la.relevant as the whole mesh assigns them (each process
  /// sees only the supports of its own and ghost cells; a cohesive pair's − cell may be neither).
  void complete_distributed_dirichlet();

  // ---- finite_strain_solver.cpp: the load-step driver ---------------------------------------------
  template <class Algebra> EquilibriumReport solve(Algebra& la, const LoadState& load);
  /// s of the linear extrapolation u = u₁ + s (u₁ − u₀) to `load` (0: no predictor).
  [[nodiscard]] double extrapolation_factor(const LoadState& load) const;

  // ---- field_output.cpp ---------------------------------------------------------------------------
  /// The fields of the displacement `u` (locally relevant values) to `file` (see write_fields).
  template <class VectorType>
  void write_fields(const VectorType& u, const std::filesystem::path& file, const LoadState& load) const;
};

} // namespace kerf::reference
