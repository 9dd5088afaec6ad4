// The deal.II side of the finite-strain reference (finite_strain_solver.hpp): triangulation from
// TetMesh, FE space, total-Lagrangian assembly, penalty contact, Newton with line search, output.
//
// One Newton, line search and assembly for two linear algebras: SerialAlgebra (deal.II Vector and
// SparseMatrix, UMFPACK or PETSc CG on this process alone) and DistributedAlgebra (the mesh
// distributed over the MPI processes as a parallel::fullydistributed::Triangulation, PETSc MPI
// vectors and matrix, MUMPS or CG + GAMG on MPI_COMM_WORLD). Each process assembles its locally
// owned cells; norms, contact resultants and reactions are summed over the processes.

#include "reference/finite_strain_solver.hpp"

#include "reference/contact/blade_edge_contact.hpp"
#include "reference/material/decoupled_neo_hookean.hpp"
#include "reference/material/finite_strain_error.hpp"
#include "reference/material/kelvin_voigt.hpp"
#include "reference/material/neo_hookean.hpp"
#include "reference/material/st_venant_kirchhoff.hpp"
#include "reference/mpi_processes.hpp"
#include "reference/tangent_solver.hpp"
#include "meshes/atomic_file.hpp"

#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/distributed/fully_distributed_tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria.h>
#include <deal.II/grid/tria_description.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/data_postprocessor.h>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <climits>
#include <map>
#include <span>
#include <stdexcept>
#include <type_traits>

namespace kerf::reference {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

Eigen::Matrix3d to_eigen(const dealii::Tensor<2, 3>& t) {
  Eigen::Matrix3d m;
  for (unsigned i = 0; i < 3; ++i)
    for (unsigned j = 0; j < 3; ++j) m(i, j) = t[i][j];
  return m;
}
Eigen::Vector3d to_eigen(const dealii::Point<3>& p) { return {p[0], p[1], p[2]}; }

/// Every process's `values`, in rank order (MPI_Allgatherv; collective on `comm`).
std::vector<std::vector<double>> all_gather(MPI_Comm comm, const std::vector<double>& values) {
  int size = 0;
  MPI_Comm_size(comm, &size);
  int count = static_cast<int>(values.size());
  std::vector<int> counts(static_cast<std::size_t>(size)), offsets(static_cast<std::size_t>(size) + 1, 0);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (std::size_t r = 0; r < counts.size(); ++r) offsets[r + 1] = offsets[r] + counts[r];
  std::vector<double> all(static_cast<std::size_t>(offsets.back()));
  MPI_Allgatherv(values.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, comm);
  std::vector<std::vector<double>> out;
  for (std::size_t r = 0; r < counts.size(); ++r)
    out.emplace_back(all.begin() + offsets[r], all.begin() + offsets[r + 1]);
  return out;
}

std::unique_ptr<HyperelasticLaw> make_law(const MaterialRegion& region) {
  const LameParameters lame = lame_parameters(region.youngs_modulus, region.poisson_ratio);
  switch (region.law) {
  case LawKind::neo_hookean: return std::make_unique<NeoHookean>(lame.mu, lame.lambda);
  case LawKind::decoupled_neo_hookean:
    // κ = λ + 2μ/3 (code gallery: 2μ(1+ν) / (3(1−2ν)))
    return std::make_unique<DecoupledNeoHookean>(lame.mu, lame.lambda + 2.0 * lame.mu / 3.0);
  case LawKind::st_venant_kirchhoff: return std::make_unique<StVenantKirchhoff>(lame.mu, lame.lambda);
  }
  throw std::invalid_argument("finite strain solver: unknown material law");
}

/// The linear algebra of one process alone: deal.II's serial vector and sparse matrix.
struct SerialAlgebra {
  using VectorType = dealii::Vector<double>;
  using MatrixType = dealii::SparseMatrix<double>;
  std::size_t n = 0;
  dealii::SparsityPattern pattern;
  MatrixType K;
  VectorType u;          ///< the displacement DOFs
  VectorType u_previous; ///< the converged state before the last one (the predictor's u₀)
  VectorType free_mask;  ///< 1 on free DOFs, 0 on Dirichlet DOFs
  void reinit(VectorType& v) const { v.reinit(n); }
  /// The vector with the values every cell of this process reads: itself.
  const VectorType& ghosted(const VectorType& v) const { return v; }
  [[nodiscard]] bool owns(dealii::types::global_dof_index) const { return true; }
  void prepare(dealii::AffineConstraints<double>&) const {}
};

/// The linear algebra of the distributed mesh: PETSc MPI vectors and matrix over the locally
/// owned DOFs of this process, ghosted copies for the locally relevant ones.
struct DistributedAlgebra {
  using VectorType = dealii::PETScWrappers::MPI::Vector;
  using MatrixType = dealii::PETScWrappers::MPI::SparseMatrix;
  MPI_Comm comm = MPI_COMM_WORLD;
  dealii::IndexSet owned, relevant;
  MatrixType K;
  VectorType u;
  VectorType u_previous; ///< the converged state before the last one (the predictor's u₀)
  VectorType free_mask;
  mutable VectorType ghost; ///< locally relevant values of the last vector passed to ghosted()
  void reinit(VectorType& v) const { v.reinit(owned, comm); }
  /// `v` (locally owned values) with the ghost values of the locally relevant DOFs (collective).
  const VectorType& ghosted(const VectorType& v) const {
    ghost = v;
    return ghost;
  }
  [[nodiscard]] bool owns(dealii::types::global_dof_index i) const { return owned.is_element(i); }
  void prepare(dealii::AffineConstraints<double>& c) const { c.reinit(relevant); }
};

} // namespace

struct FiniteStrainSolver::Impl {
  SolverSettings settings;
  std::vector<std::string> surface_names;
  dealii::Triangulation<3> tria; // the whole mesh, on every process (refined before distribution)
  bool distributed = false;      // the mesh is distributed over MPI_COMM_WORLD's processes
  int process_count = 1;
  int rank = 0;
  std::unique_ptr<dealii::parallel::fullydistributed::Triangulation<3>> distributed_tria;
  std::unique_ptr<dealii::FESystem<3>> fe;
  std::unique_ptr<dealii::MappingFE<3>> mapping;
  dealii::DoFHandler<3> dof;
  std::unique_ptr<dealii::QGaussSimplex<3>> cell_quadrature;
  std::unique_ptr<dealii::QGaussSimplex<2>> face_quadrature;
  std::vector<std::unique_ptr<HyperelasticLaw>> laws; // by material_id
  std::vector<double> youngs; // by material_id
  std::vector<double> densities; // by material_id [kg/m^3]
  std::vector<KelvinVoigtDamping> damping; // by material_id (dynamic step only)

  // Dynamic step (SolverSettings::dynamic; serial only): Newmark average acceleration with the
  // consistent mass. Each cell's scalar mass matrix m_ij = ∫ ρ N_i N_j dV over its scalar shape
  // functions (nodes × nodes, the same for the three components) is computed once in build. The
  // committed state is u_n, v_n, a_n at `committed_time`; `step` is h of the solve under way
  // (0: quasi-static, no inertia).
  struct Dynamics {
    std::vector<std::vector<double>> cell_mass; // by active cell index: nodes × nodes, row-major
    std::vector<unsigned> node_of_dof;          // a cell's local DOF -> its scalar node (0 .. nodes-1)
    unsigned nodes = 0;                         // scalar nodes per cell
    dealii::Vector<double> u, v, a;             // u_n, v_n, a_n (all DOFs, global order)
    double step = 0.0;                          // h [s] of the current solve
    double kinetic_energy = 0.0;                // ½ v_nᵀ M v_n [J]
    // Kelvin–Voigt damping (some region's retardation time > 0): the viscous nodal forces
    // f_v(u_n, v_n) of the committed state and the dissipation Σ ½ (f_v,n + f_v,n+1)·Δu so far.
    bool damped = false;
    dealii::Vector<double> viscous_force;
    double damping_dissipation = 0.0;           // [J]
  };
  std::optional<Dynamics> dynamics;
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
  /// velocity v (all DOFs, serial).
  void assemble_viscous_force(const dealii::Vector<double>& u, const dealii::Vector<double>& v,
                              dealii::Vector<double>& out) const;

  // Dirichlet DOFs and how to get their target value.
  struct DirichletDof {
    dealii::types::global_dof_index index;
    unsigned component;
    int boundary; // index into displacement_boundaries
    Eigen::Vector3d X;
  };
  std::vector<DirichletDof> dirichlet;

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
  void build_cell_geometry();
  std::vector<DisplacementBoundary> boundaries;
  std::vector<std::pair<int, Eigen::Vector3d>> tractions; // surface group, traction [Pa]
  std::vector<std::vector<int>> face_classes;               // boundary_id -> surface groups
  bool in_group(dealii::types::boundary_id id, int group) const {
    const auto& c = face_classes[id];
    return std::find(c.begin(), c.end(), group) != c.end();
  }
  std::optional<RigidToolShape> tool;
  double penalty = 0.0;
  double h_min = 0.0; // the shortest edge of the (refined) mesh [m]

  // Blade edge pass (contact/blade_edge_contact.hpp), the second contact pass of a wedge tool: the
  // boundary facets of the whole body as flat triangles on compact node numbers (a P2 face split
  // into four at its edge midpoints). Every process holds all of them and evaluates the same
  // contact; each assembles only the terms on the facets of its own cells, and supplies the
  // displacements of the nodes it is the first process to hold.
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
  void build_blade_edge();
  template <class VectorType, class MatrixType, class Tally>
  void assemble_blade_edge(const VectorType& state, const LoadState& load, bool with_matrix, Tally& out,
                           const dealii::AffineConstraints<double>* constraints, MatrixType& K, VectorType* rhs,
                           VectorType& f_ext) const;

  SerialAlgebra serial;
  // Only when distributed: PETSc objects need PETSc (and MPI) initialised, which a serial run never does.
  std::unique_ptr<DistributedAlgebra> parallel;

  // Cohesive interface (Reference II): coincident face pairs of the split crack path, with each
  // side's shape values cached at the + face's quadrature points (the reference configuration
  // does not change), and one history per quadrature point.
  struct CohesivePair {
    std::vector<dealii::types::global_dof_index> dofs; // the + cell's n DOFs, then the − cell's n
    std::vector<std::vector<double>> plus_values;      // [q][i]: N_i of the + cell (component comp[i])
    std::vector<std::vector<double>> minus_values;     // [q][j]: N_j of the − cell
    std::vector<double> weights;                       // reference area weights JxW
    std::vector<Eigen::Vector3d> points;               // reference positions
    std::array<Eigen::Vector3d, 3> vertices;           // the face's reference vertices
    Eigen::Vector3d normal;                            // n, from − into + (reference)
  };
  std::optional<CohesiveLawParameters> cohesive_law;
  std::vector<CohesivePair> cohesive_pairs;
  // The faces of the crack path, by active cell index × 4 + face: the unit direction into each
  // face's own material (+n on the + side, −n on the − side), which the wedge contact needs
  // (rigid_tool.hpp, tool_contact's `side`).
  std::map<std::size_t, Eigen::Vector3d> crack_face_sides;
  Eigen::Vector3d crack_side(const dealii::DoFHandler<3>::active_cell_iterator& cell, unsigned f) const {
    if (crack_face_sides.empty()) return Eigen::Vector3d::Zero();
    const auto it = crack_face_sides.find(4 * cell->active_cell_index() + f);
    return it == crack_face_sides.end() ? Eigen::Vector3d::Zero() : it->second;
  }
  std::vector<CohesiveState> cohesive_states; // pair-major, then quadrature point
  std::vector<unsigned> cell_components;      // component of each local DOF of a cell
  double cohesive_viscous_dissipation = 0.0;
  double cohesive_trapezoid_work = 0.0; // dynamic step only: CohesiveSummary::trapezoid_work
  double committed_time = 0.0;
  bool cohesive_secant = false; // Newton fallback: the secant interface tangent (cohesive_law.hpp)
  bool poison_residual = false; // fault injection: SolverSettings::residual_fault chose this assembly
  void build_cohesive(const CohesiveInterfaceSpec& spec, int plus_group, int minus_group);
  template <class VectorType>
  Eigen::Vector3d cohesive_opening(const CohesivePair& pair, std::size_t q, const VectorType& state) const;
  template <class VectorType, class MatrixType>
  void assemble_cohesive(const VectorType& state, const LoadState& load, bool with_matrix,
                         const dealii::AffineConstraints<double>* constraints, MatrixType& K, VectorType* rhs,
                         VectorType& f_int) const;
  CohesiveSummary commit_cohesive(const LoadState& load);
  std::unique_ptr<TangentSolver> linear;

  /// Calls f with the algebra in use (the distributed one when the mesh is distributed).
  template <class F> decltype(auto) with_algebra(F&& f) { return distributed ? f(*parallel) : f(serial); }
  template <class F> decltype(auto) with_algebra(F&& f) const {
    return distributed ? f(static_cast<const DistributedAlgebra&>(*parallel)) : f(serial);
  }

  /// Sums over the processes (in place) when distributed.
  void sum(std::span<double> values) const {
    if (distributed && !values.empty())
      dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(values.data(), values.size()), parallel->comm,
                                  dealii::ArrayView<double>(values.data(), values.size()));
  }
  double sum(double value) const { return distributed ? dealii::Utilities::MPI::sum(value, parallel->comm) : value; }
  double max(double value) const { return distributed ? dealii::Utilities::MPI::max(value, parallel->comm) : value; }

  // Result of one assembly.
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
  };

  double dirichlet_target(const DirichletDof& d, double load) const {
    const DisplacementBoundary& b = boundaries[static_cast<std::size_t>(d.boundary)];
    if (b.kind != DisplacementBoundary::Kind::prescribed) return 0.0;
    return b.displacement(d.X, load)[d.component];
  }

  void build(const FiniteStrainProblem& problem);
  template <class Algebra>
  void assemble(Algebra& la, const typename Algebra::VectorType& owned_state, const LoadState& load, bool with_matrix,
                Assembly<typename Algebra::VectorType>& out, const dealii::AffineConstraints<double>* constraints,
                typename Algebra::VectorType* rhs);
  /// The cell loop of `assemble`: this process's cells into K, rhs, f_int, f_ext and the tallies.
  template <class VectorType, class MatrixType, class Tally>
  void assemble_cells(const VectorType& state, const LoadState& load, bool with_matrix, Tally& out,
                      const dealii::AffineConstraints<double>* constraints, MatrixType& K, VectorType* rhs,
                      VectorType& f_int, VectorType& f_ext) const;
  template <class Algebra> EquilibriumReport solve(Algebra& la, const LoadState& load);
  /// Newton–Raphson from the state in `la.u` (the predictor's or `start`); on failure `la.u` is
  /// set back to `start`, the last converged state.
  template <class Algebra>
  EquilibriumReport newton(Algebra& la, const LoadState& load, const typename Algebra::VectorType& start);
  /// The Dirichlet constraints of the state `u`: the remaining increment target − u on every
  /// Dirichlet DOF (added to `c`, which is closed). Returns the largest |target − u| (all processes).
  template <class Algebra>
  double dirichlet_constraints(const Algebra& la, const typename Algebra::VectorType& u, const LoadState& load,
                               dealii::AffineConstraints<double>& c) const;

  // The predictor (SolverSettings::extrapolate_initial_guess): the last two converged loads. The
  // states are la.u (at `load_last`) and la.u_previous (at `load_before`); `history` counts the
  // known ones (0, 1 or 2), reset by set_state.
  int history = 0;
  LoadState load_last, load_before;
  /// s of the linear extrapolation u = u₁ + s (u₁ − u₀) to `load` (0: no predictor).
  [[nodiscard]] double extrapolation_factor(const LoadState& load) const;
  bool fault_fired = false; // the fault injection poisoned an assembly of the solve under way

  /// The fields of the displacement `u` (locally relevant values) to `file` (see write_fields).
  template <class VectorType>
  void write_fields(const VectorType& u, const std::filesystem::path& file, const LoadState& load) const;
  /// |r| over the free DOFs (the Dirichlet entries masked out).
  template <class VectorType> double free_norm(const VectorType& r, const VectorType& mask) const {
    VectorType copy = r;
    copy.scale(mask);
    return copy.l2_norm();
  }
};

void FiniteStrainSolver::Impl::build(const FiniteStrainProblem& problem) {
  const TetMesh& mesh = problem.mesh;
  if (settings.degree != 1 && settings.degree != 2)
    throw std::invalid_argument("finite strain solver: degree must be 1 or 2, got " + std::to_string(settings.degree));
  if (settings.refinements < 0 || settings.refinements > 4)
    throw std::invalid_argument("finite strain solver: refinements must lie in [0, 4], got " +
                                std::to_string(settings.refinements));
  if (mesh.tets.rows() == 0) throw std::invalid_argument("finite strain solver: the mesh has no tetrahedra");
  if (problem.materials.empty()) throw std::invalid_argument("finite strain solver: no material region given");

  // Materials: material_id = index of the first region containing the tet.
  std::vector<int> material(static_cast<std::size_t>(mesh.tets.rows()), -1);
  for (std::size_t r = 0; r < problem.materials.size(); ++r) {
    const VolumeGroup* group = mesh.find_volume_group(problem.materials[r].volume_group);
    if (group == nullptr)
      throw std::invalid_argument("finite strain solver: material region '" + problem.materials[r].volume_group +
                                  "' is not a volume group of the mesh");
    for (int t : group->tets)
      if (material[static_cast<std::size_t>(t)] < 0) material[static_cast<std::size_t>(t)] = static_cast<int>(r);
    laws.push_back(make_law(problem.materials[r]));
    youngs.push_back(problem.materials[r].youngs_modulus);
    densities.push_back(problem.materials[r].density);
    damping.push_back(kelvin_voigt_damping(problem.materials[r].youngs_modulus, problem.materials[r].poisson_ratio,
                                           problem.materials[r].damping));
  }
  std::vector<dealii::Point<3>> vertices(static_cast<std::size_t>(mesh.nodes.rows()));
  for (Eigen::Index v = 0; v < mesh.nodes.rows(); ++v)
    vertices[static_cast<std::size_t>(v)] = dealii::Point<3>(mesh.nodes(v, 0), mesh.nodes(v, 1), mesh.nodes(v, 2));
  std::vector<dealii::CellData<3>> cells(static_cast<std::size_t>(mesh.tets.rows()));
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    const int m = material[static_cast<std::size_t>(t)];
    if (m < 0)
      throw std::invalid_argument("finite strain solver: tetrahedron " + std::to_string(t) +
                                  " belongs to no material region");
    auto& cell = cells[static_cast<std::size_t>(t)];
    cell.vertices.resize(4);
    for (int k = 0; k < 4; ++k) cell.vertices[static_cast<std::size_t>(k)] = static_cast<unsigned>(mesh.tets(t, k));
    // deal.II's reference tetrahedron is positively oriented: order the vertices so that
    // det[b−a, c−a, d−a] > 0 (the same element; only its vertex order changes).
    const Eigen::Vector3d a = mesh.nodes.row(mesh.tets(t, 0));
    const double volume6 = (Eigen::Vector3d(mesh.nodes.row(mesh.tets(t, 1))) - a)
                               .cross(Eigen::Vector3d(mesh.nodes.row(mesh.tets(t, 2))) - a)
                               .dot(Eigen::Vector3d(mesh.nodes.row(mesh.tets(t, 3))) - a);
    if (!(std::abs(volume6) > 0.0))
      throw std::invalid_argument("finite strain solver: tetrahedron " + std::to_string(t) + " has zero volume");
    if (volume6 < 0.0) std::swap(cell.vertices[2], cell.vertices[3]);
    cell.material_id = static_cast<dealii::types::material_id>(m);
  }
  tria.create_triangulation(vertices, cells, dealii::SubCellData());

  // Boundary ids: a face may lie in several surface groups (e.g. `xmin` and `boundary`), so the
  // id numbers the distinct sets of groups ("face classes"); 0 = in no group. Refinement passes
  // the id on to the child faces.
  std::map<std::array<unsigned, 3>, std::vector<int>> face_groups;
  for (std::size_t g = 0; g < mesh.surface_groups.size(); ++g) {
    surface_names.push_back(mesh.surface_groups[g].name);
    const Eigen::MatrixXi& tri = mesh.surface_groups[g].triangles;
    for (Eigen::Index f = 0; f < tri.rows(); ++f) {
      std::array<unsigned, 3> key{static_cast<unsigned>(tri(f, 0)), static_cast<unsigned>(tri(f, 1)),
                                  static_cast<unsigned>(tri(f, 2))};
      std::sort(key.begin(), key.end());
      face_groups[key].push_back(static_cast<int>(g));
    }
  }
  face_classes.push_back({});
  for (const auto& cell : tria.active_cell_iterators())
    for (const unsigned f : cell->face_indices()) {
      if (!cell->face(f)->at_boundary()) continue;
      std::array<unsigned, 3> key{cell->face(f)->vertex_index(0), cell->face(f)->vertex_index(1),
                                  cell->face(f)->vertex_index(2)};
      std::sort(key.begin(), key.end());
      const auto it = face_groups.find(key);
      const std::vector<int> groups = it == face_groups.end() ? std::vector<int>{} : it->second;
      auto cls = std::find(face_classes.begin(), face_classes.end(), groups);
      if (cls == face_classes.end()) cls = face_classes.insert(face_classes.end(), groups);
      cell->face(f)->set_boundary_id(static_cast<dealii::types::boundary_id>(cls - face_classes.begin()));
    }
  if (settings.refinements > 0) tria.refine_global(static_cast<unsigned>(settings.refinements));

  // Under mpirun with N > 1 processes: METIS splits the (refined) mesh into N parts and each
  // process keeps its part plus a layer of ghost cells (deal.II's tests/simplex/step-40 way;
  // a fully distributed triangulation cannot be refined afterwards).
  if (settings.distribute) {
    const MpiProcesses processes = mpi_processes();
    distributed = processes.count > 1;
    process_count = processes.count;
    rank = processes.rank;
  }
  if (distributed) {
    parallel = std::make_unique<DistributedAlgebra>();
    dealii::GridTools::partition_triangulation(static_cast<unsigned>(process_count), tria);
    const auto description =
        dealii::TriangulationDescription::Utilities::create_description_from_triangulation(tria, parallel->comm);
    distributed_tria = std::make_unique<dealii::parallel::fullydistributed::Triangulation<3>>(parallel->comm);
    distributed_tria->create_triangulation(description);
  }

  auto group_of = [&](const std::string& name, const char* what) {
    for (std::size_t g = 0; g < surface_names.size(); ++g)
      if (surface_names[g] == name) return static_cast<int>(g);
    throw std::invalid_argument(std::string("finite strain solver: ") + what + " surface '" + name +
                                "' is not a surface group of the mesh");
  };

  fe = std::make_unique<dealii::FESystem<3>>(dealii::FE_SimplexP<3>(static_cast<unsigned>(settings.degree)), 3);
  mapping = std::make_unique<dealii::MappingFE<3>>(dealii::FE_SimplexP<3>(1));
  cell_quadrature = std::make_unique<dealii::QGaussSimplex<3>>(static_cast<unsigned>(settings.degree + 1));
  face_quadrature = std::make_unique<dealii::QGaussSimplex<2>>(static_cast<unsigned>(settings.degree + 1));
  if (distributed)
    dof.reinit(*distributed_tria);
  else
    dof.reinit(tria);
  dof.distribute_dofs(*fe);
  build_cell_geometry();

  // Support points; the node-major layout (3k + component) the AMG's block size relies on.
  std::vector<dealii::Point<3>> support(dof.n_dofs());
  {
    std::vector<dealii::types::global_dof_index> local(fe->n_dofs_per_cell());
    const auto& unit_points = fe->get_unit_support_points();
    for (const auto& cell : dof.active_cell_iterators()) {
      if (cell->is_artificial()) continue; // distributed: neither owned nor ghost
      cell->get_dof_indices(local);
      for (unsigned i = 0; i < local.size(); ++i) {
        support[local[i]] = mapping->transform_unit_to_real_cell(cell, unit_points[i]);
        if (local[i] % 3 != fe->system_to_component_index(i).first)
          throw std::logic_error("finite strain solver: DOFs are not node-major (3k + component)");
      }
    }
  }

  // Dirichlet DOFs: bonded and prescribed first (they win over sliding on shared edges).
  boundaries = problem.displacement_boundaries;
  std::map<dealii::types::global_dof_index, DirichletDof> fixed;
  for (int pass = 0; pass < 2; ++pass)
    for (std::size_t b = 0; b < boundaries.size(); ++b) {
      const DisplacementBoundary& bc = boundaries[b];
      const bool sliding = bc.kind == DisplacementBoundary::Kind::sliding;
      if (sliding != (pass == 1)) continue;
      const int group = group_of(bc.surface, "support");
      std::array<bool, 3> comps{true, true, true};
      if (bc.kind == DisplacementBoundary::Kind::prescribed) {
        if (!bc.displacement)
          throw std::invalid_argument("finite strain solver: prescribed surface '" + bc.surface + "' has no displacement");
        comps = bc.components;
      }
      if (sliding) {
        // u·n = 0 with n = ±e_k: every triangle of the group must have the same axis normal.
        const SurfaceGroup* group = mesh.find_surface_group(bc.surface);
        int axis = -1;
        for (Eigen::Index f = 0; f < group->triangles.rows(); ++f) {
          const Eigen::Vector3d a = mesh.nodes.row(group->triangles(f, 0));
          const Eigen::Vector3d n = (Eigen::Vector3d(mesh.nodes.row(group->triangles(f, 1))) - a)
                                        .cross(Eigen::Vector3d(mesh.nodes.row(group->triangles(f, 2))) - a)
                                        .normalized();
          Eigen::Index k = 0;
          n.cwiseAbs().maxCoeff(&k);
          if (std::abs(std::abs(n[k]) - 1.0) > 1e-8 || (axis >= 0 && axis != k))
            throw std::invalid_argument("finite strain solver: sliding support '" + bc.surface +
                                        "' must be a plane normal to a coordinate axis");
          axis = static_cast<int>(k);
        }
        comps = {axis == 0, axis == 1, axis == 2};
      }
      std::vector<dealii::types::global_dof_index> local(fe->n_dofs_per_face());
      for (const auto& cell : dof.active_cell_iterators())
        for (const unsigned f : cell->face_indices()) {
          if (cell->is_artificial()) break;
          if (!cell->face(f)->at_boundary() || !in_group(cell->face(f)->boundary_id(), group)) continue;
          cell->face(f)->get_dof_indices(local);
          for (unsigned i = 0; i < local.size(); ++i) {
            const unsigned c = fe->face_system_to_component_index(i, f).first;
            if (!comps[c] || fixed.count(local[i]) != 0) continue;
            fixed.emplace(local[i], DirichletDof{local[i], c, static_cast<int>(b), to_eigen(support[local[i]])});
          }
        }
    }
  for (const auto& [index, d] : fixed) dirichlet.push_back(d);

  for (const TractionBoundary& t : problem.tractions) {
    const int group = group_of(t.surface, "traction");
    double area = 0.0;
    dealii::FEFaceValues<3> fv(*mapping, *fe, *face_quadrature, dealii::update_JxW_values);
    for (const auto& cell : dof.active_cell_iterators())
      for (const unsigned f : cell->face_indices())
        if (cell->is_locally_owned() && cell->face(f)->at_boundary() && in_group(cell->face(f)->boundary_id(), group)) {
          fv.reinit(cell, f);
          for (unsigned q = 0; q < fv.n_quadrature_points; ++q) area += fv.JxW(q);
        }
    area = sum(area);
    if (!(area > 0.0)) throw std::invalid_argument("finite strain solver: traction surface '" + t.surface + "' has no area");
    tractions.emplace_back(group, t.total_force / area);
  }

  // `tria` is the whole (refined) mesh on every process, so every process finds the same h_min.
  h_min = std::numeric_limits<double>::infinity();
  for (const auto& cell : tria.active_cell_iterators())
    for (unsigned l = 0; l < cell->n_lines(); ++l) h_min = std::min(h_min, cell->line(l)->diameter());

  tool = problem.tool;
  if (tool) {
    validate(*tool);
    penalty = settings.contact_penalty;
    // ε_N = 50 E_max / h_min: a pressure E costs a penetration of h_min / 50.
    if (penalty <= 0.0) penalty = 50.0 * *std::max_element(youngs.begin(), youngs.end()) / h_min;
    if (tool->kind == RigidToolShape::Kind::wedge) build_blade_edge();
  }

  if (settings.dynamic) {
    if (distributed)
      throw std::invalid_argument("finite strain solver: the dynamic step runs on one process for now "
                                  "(run without mpirun, or with -np 1)");
    for (std::size_t r = 0; r < problem.materials.size(); ++r)
      if (!(problem.materials[r].density > 0.0) || !std::isfinite(problem.materials[r].density))
        throw std::invalid_argument("finite strain solver: the dynamic step needs a density > 0 for material region '" +
                                    problem.materials[r].volume_group + "', got " +
                                    std::to_string(problem.materials[r].density) + " kg/m^3");
    build_dynamics();
  }

  if (problem.cohesive) {
    if (distributed)
      throw std::invalid_argument("finite strain solver: the cohesive interface runs on one process for now "
                                  "(run without mpirun, or with -np 1)");
    build_cohesive(*problem.cohesive, group_of(problem.cohesive->plus_surface, "cohesive"),
                   group_of(problem.cohesive->minus_surface, "cohesive"));
  }

  const bool direct = settings.linear_solver == LinearSolverChoice::direct ||
                      (settings.linear_solver == LinearSolverChoice::automatic && dof.n_dofs() <= settings.direct_dof_limit);
  const auto kind = direct ? TangentSolver::Kind::direct : TangentSolver::Kind::iterative;
  // Contact and a softening cohesive interface make the tangent indefinite: GMRES instead of CG.
  const bool spd = !tool && !cohesive_law;
  if (!distributed) {
    dealii::AffineConstraints<double> structure;
    for (const auto& d : dirichlet) structure.add_line(d.index);
    structure.close();
    dealii::DynamicSparsityPattern dsp(dof.n_dofs());
    dealii::DoFTools::make_sparsity_pattern(dof, dsp, structure, false);
    for (const CohesivePair& pair : cohesive_pairs) // the interface couples the two cells' DOFs
      for (const auto i : pair.dofs)
        for (const auto j : pair.dofs)
          if (!structure.is_constrained(i) && !structure.is_constrained(j)) dsp.add(i, j);
    serial.n = dof.n_dofs();
    serial.pattern.copy_from(dsp);
    serial.K.reinit(serial.pattern);
    serial.u.reinit(dof.n_dofs());
    serial.u_previous.reinit(dof.n_dofs());
    serial.free_mask.reinit(dof.n_dofs());
    serial.free_mask = 1.0;
    for (const auto& d : dirichlet) serial.free_mask[d.index] = 0.0;
    linear = std::make_unique<TangentSolver>(kind, std::move(support), settings.iterative_tolerance, false, spd);
    return;
  }
  // Distributed: this process's rows (locally owned DOFs) and the DOFs its cells touch
  // (locally relevant: owned and ghost cells); the sparsity rows other processes contribute to
  // are sent to their owners.
  DistributedAlgebra& la = *parallel;
  la.owned = dof.locally_owned_dofs();
  dealii::DoFTools::extract_locally_relevant_dofs(dof, la.relevant);
  if (!la.owned.is_contiguous())
    throw std::logic_error("finite strain solver: the locally owned DOFs are not one contiguous range");
  dealii::AffineConstraints<double> structure(la.relevant);
  for (const auto& d : dirichlet) structure.add_line(d.index);
  structure.close();
  dealii::DynamicSparsityPattern dsp(la.relevant);
  dealii::DoFTools::make_sparsity_pattern(dof, dsp, structure, false);
  dealii::SparsityTools::distribute_sparsity_pattern(dsp, la.owned, la.comm, la.relevant);
  la.K.reinit(la.owned, la.owned, dsp, la.comm);
  la.reinit(la.u);
  la.reinit(la.u_previous);
  la.ghost.reinit(la.owned, la.relevant, la.comm);
  la.reinit(la.free_mask);
  la.free_mask = 1.0;
  std::vector<dealii::types::global_dof_index> fixed_owned;
  for (const auto& d : dirichlet)
    if (la.owns(d.index)) fixed_owned.push_back(d.index);
  la.free_mask.set(fixed_owned, std::vector<double>(fixed_owned.size(), 0.0));
  la.free_mask.compress(dealii::VectorOperation::insert);
  std::vector<dealii::Point<3>> owned_support;
  for (const auto i : la.owned) owned_support.push_back(support[i]);
  linear = std::make_unique<TangentSolver>(kind, std::move(owned_support), settings.iterative_tolerance, true, spd);
}

template <class Algebra>
void FiniteStrainSolver::Impl::assemble(Algebra& la, const typename Algebra::VectorType& owned_state,
                                        const LoadState& load, bool with_matrix,
                                        Assembly<typename Algebra::VectorType>& out,
                                        const dealii::AffineConstraints<double>* constraints,
                                        typename Algebra::VectorType* rhs) {
  typename Algebra::VectorType f_int, f_ext;
  la.reinit(f_int);
  la.reinit(f_ext);
  la.reinit(out.residual);
  out.contact_on_body.setZero();
  out.traction_on_body.setZero();
  out.contact_points = 0;
  out.contact_area = 0.0;
  out.max_pressure = 0.0;
  out.contact_energy = 0.0;
  if (with_matrix) {
    la.K = 0.0;
    *rhs = 0.0;
  }
  // An element that fails on one process fails the assembly on every process (after the
  // collective compress), so that all of them take the same branch of Newton and line search.
  std::string failure;
  try {
    assemble_cells(la.ghosted(owned_state), load, with_matrix, out, constraints, la.K, rhs, f_int, f_ext);
  } catch (const FiniteStrainError& e) {
    failure = e.what();
  }
  out.edge_points = 0;
  out.edge_length = 0.0;
  out.max_line_load = 0.0;
  if (blade_edge) assemble_blade_edge(la.ghosted(owned_state), load, with_matrix, out, constraints, la.K, rhs, f_ext);
  if (with_matrix) {
    la.K.compress(dealii::VectorOperation::add);
    rhs->compress(dealii::VectorOperation::add);
  }
  f_int.compress(dealii::VectorOperation::add);
  f_ext.compress(dealii::VectorOperation::add);
  if (max(failure.empty() ? 0.0 : 1.0) > 0.0)
    throw FiniteStrainError(failure.empty() ? "finite strain: an element of another process failed" : failure);
  // The contact and traction tallies of every process's cells.
  std::array<double, 11> tally{out.contact_on_body.x(), out.contact_on_body.y(), out.contact_on_body.z(),
                               out.traction_on_body.x(), out.traction_on_body.y(), out.traction_on_body.z(),
                               static_cast<double>(out.contact_points), out.contact_area,
                               static_cast<double>(out.edge_points), out.edge_length, out.contact_energy};
  sum(tally);
  out.contact_on_body = Eigen::Vector3d(tally[0], tally[1], tally[2]);
  out.traction_on_body = Eigen::Vector3d(tally[3], tally[4], tally[5]);
  out.contact_points = static_cast<int>(tally[6]);
  out.contact_area = tally[7];
  out.edge_points = static_cast<int>(tally[8]);
  out.edge_length = tally[9];
  out.contact_energy = tally[10];
  out.max_pressure = max(out.max_pressure);
  out.max_line_load = max(out.max_line_load);
  out.residual = f_int;
  out.residual -= f_ext;
  out.internal_norm = f_int.l2_norm();
  out.external_norm = f_ext.l2_norm();
  if (poison_residual) out.residual *= std::numeric_limits<double>::quiet_NaN(); // fault injection (issue 10)
  if (!std::isfinite(out.residual.l2_norm())) throw FiniteStrainError("finite strain: non-finite residual");
}

template <class VectorType, class MatrixType, class Tally>
void FiniteStrainSolver::Impl::assemble_cells(const VectorType& state, const LoadState& load, bool with_matrix,
                                              Tally& out, const dealii::AffineConstraints<double>* constraints,
                                              MatrixType& K, VectorType* rhs, VectorType& f_int,
                                              VectorType& f_ext) const {
  const unsigned n = fe->n_dofs_per_cell();
  const CellGeometry& geo = geometry;
  dealii::FEFaceValues<3> ffv(*mapping, *fe, *face_quadrature,
                              dealii::update_values | dealii::update_quadrature_points | dealii::update_JxW_values);
  const dealii::FEValuesExtractors::Vector disp(0);
  std::vector<dealii::Tensor<1, 3>> face_u(face_quadrature->size());
  std::vector<double> cell_u(n);
  dealii::FullMatrix<double> cell_K(n, n);
  dealii::Vector<double> cell_int(n), cell_ext(n), cell_rhs(n);
  std::vector<dealii::types::global_dof_index> local(n);
  std::vector<unsigned> comp(n);
  for (unsigned i = 0; i < n; ++i) comp[i] = fe->system_to_component_index(i).first;
  std::vector<Eigen::Vector3d> gradN(n);
  std::vector<Eigen::Matrix<double, 9, 1>> AgradN(n);
  std::vector<double> velocity(n);

  for (const auto& cell : dof.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue; // distributed: another process assembles it
    cell->get_dof_indices(local);
    const std::size_t c_index = cell->active_cell_index();
    for (unsigned i = 0; i < n; ++i) cell_u[i] = state(local[i]);
    cell_K = 0.0;
    cell_int = 0.0;
    cell_ext = 0.0;
    const HyperelasticLaw& law = *laws[cell->material_id()];
    if (dynamics && dynamics->step > 0.0) {
      // Inertia (Newmark β = 1/4): f_a += Σ_b M_ab a_b(u), a_b = 4/h² (u_b − u_n,b) − 4/h v_n,b − a_n,b,
      // and ∂f_a/∂u_b = 4/h² M_ab. M_ab = m_ij δ(c_a, c_b), m the cell's scalar mass matrix.
      const Dynamics& d = *dynamics;
      const std::vector<double>& m = d.cell_mass[cell->active_cell_index()];
      const double c = 4.0 / (d.step * d.step);
      for (unsigned i = 0; i < n; ++i)
        for (unsigned j = 0; j < n; ++j) {
          if (comp[i] != comp[j]) continue;
          const double Mij = m[d.node_of_dof[i] * d.nodes + d.node_of_dof[j]];
          cell_int(i) += Mij * newmark_acceleration(local[j], state(local[j]));
          if (with_matrix) cell_K(i, j) += c * Mij;
        }
    }
    // Kelvin–Voigt damping (dynamic step): the Newmark velocity v_{n+1}(u) of the cell's DOFs.
    const bool damped = dynamics && dynamics->damped && dynamics->step > 0.0 &&
                        damping[cell->material_id()].retardation_time > 0.0;
    if (damped)
      for (unsigned i = 0; i < n; ++i) velocity[i] = newmark_velocity(local[i], state(local[i]));
    for (unsigned q = 0; q < geo.points; ++q) {
      for (unsigned i = 0; i < n; ++i) gradN[i] = Eigen::Map<const Eigen::Vector3d>(geo.gradient(c_index, q, geo.node_of_dof[i]));
      // F = I + Grad u = I + Σ_a u_a e_c ⊗ Grad N_a (total Lagrangian: gradients with respect to
      // the reference configuration)
      Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
      for (unsigned i = 0; i < n; ++i) F.row(comp[i]) += cell_u[i] * gradN[i].transpose();
      const double JxW = geo.JxW[c_index * geo.points + q];
      // The residual-only assemblies of the line search need P = F S alone (the same bits).
      StressTangent st;
      if (with_matrix) {
        Eigen::Matrix3d S;
        Tensor4 C4;
        law.second_piola_and_tangent(F, S, C4);
        st = first_piola_and_tangent(F, S, C4);
      } else {
        st.first_piola = F * law.second_piola(F);
      }
      if (damped) {
        // Ḟ = Grad v = Σ_a v_a e_c ⊗ Grad N_a; P += P_v(F, Ḟ), 𝔸 += ∂P_v/∂F with ∂Ḟ/∂F = γ/(βh) = 2/h.
        Eigen::Matrix3d F_rate = Eigen::Matrix3d::Zero();
        for (unsigned i = 0; i < n; ++i) F_rate.row(comp[i]) += velocity[i] * gradN[i].transpose();
        const StressTangent sv = kelvin_voigt_stress(damping[cell->material_id()], F, F_rate, 2.0 / dynamics->step);
        st.first_piola += sv.first_piola;
        if (with_matrix) st.tangent += sv.tangent;
      }
      // f_int,a = ∫ P : (e_c ⊗ Grad N_a) dV
      for (unsigned i = 0; i < n; ++i) cell_int(i) += st.first_piola.row(comp[i]).dot(gradN[i]) * JxW;
      if (!with_matrix) continue;
      // K_ab = ∫ (e_ca ⊗ Grad N_a) : 𝔸 : (e_cb ⊗ Grad N_b) dV; 𝔸 of a hyperelastic law has the
      // major symmetry 𝔸_iJkL = 𝔸_kLiJ, so K is symmetric: its upper triangle here, the lower one
      // mirrored below (the Kelvin–Voigt tangent has no such symmetry: then every entry).
      for (unsigned j = 0; j < n; ++j) AgradN[j] = st.tangent.middleCols<3>(3 * comp[j]) * gradN[j];
      for (unsigned i = 0; i < n; ++i)
        for (unsigned j = damped ? 0 : i; j < n; ++j)
          cell_K(i, j) += gradN[i].dot(AgradN[j].segment<3>(3 * comp[i])) * JxW;
    }
    if (with_matrix && !damped)
      for (unsigned i = 0; i < n; ++i)
        for (unsigned j = 0; j < i; ++j) cell_K(i, j) = cell_K(j, i);

    // Tractions and contact on boundary faces.
    for (const unsigned f : cell->face_indices()) {
      if (!cell->face(f)->at_boundary()) continue;
      const auto id = cell->face(f)->boundary_id();
      Eigen::Vector3d traction_sum = Eigen::Vector3d::Zero();
      const Eigen::Vector3d* traction = nullptr;
      for (const auto& [group, t] : tractions)
        if (in_group(id, group)) {
          traction_sum += t;
          traction = &traction_sum;
        }
      if (traction == nullptr && !tool) continue;
      ffv.reinit(cell, f);
      if (tool) ffv[disp].get_function_values(state, face_u);
      const Eigen::Vector3d side = crack_side(cell, f);
      for (unsigned q = 0; q < ffv.n_quadrature_points; ++q) {
        const double JxW = ffv.JxW(q);
        Eigen::Vector3d t = Eigen::Vector3d::Zero();
        if (traction != nullptr) {
          t += load.load_factor * *traction;
          out.traction_on_body += load.load_factor * *traction * JxW;
        }
        Eigen::Matrix3d dt_dx = Eigen::Matrix3d::Zero();
        if (tool) {
          const Eigen::Vector3d x = to_eigen(ffv.quadrature_point(q)) + Eigen::Vector3d(face_u[q][0], face_u[q][1], face_u[q][2]);
          const ToolContactPoint c = tool_contact(*tool, load.tool_position, x, side);
          if (c.inside) {
            // t_c = ε_N p n (per unit reference area), p = −g
            const Eigen::Vector3d tc = penalty * c.penetration * c.normal;
            t += tc;
            out.contact_on_body += tc * JxW;
            ++out.contact_points;
            out.contact_area += JxW;
            out.max_pressure = std::max(out.max_pressure, penalty * c.penetration);
            // Penalty energy ½ ε_N p² per reference area (its derivative is the traction above).
            out.contact_energy += 0.5 * penalty * c.penetration * c.penetration * JxW;
            // ∂t_c/∂x = ε_N (−n⊗n + p ∂n/∂x)
            dt_dx = penalty * (-c.normal * c.normal.transpose() + c.penetration * c.normal_derivative);
          }
        }
        for (unsigned i = 0; i < n; ++i) {
          const double Ni = ffv.shape_value_component(i, q, comp[i]);
          if (Ni == 0.0) continue;
          cell_ext(i) += Ni * t[comp[i]] * JxW;
          if (with_matrix && tool)
            for (unsigned j = 0; j < n; ++j)
              cell_K(i, j) -= Ni * dt_dx(comp[i], comp[j]) * ffv.shape_value_component(j, q, comp[j]) * JxW;
        }
      }
    }
    f_int.add(local, cell_int);
    f_ext.add(local, cell_ext);
    if (with_matrix) {
      for (unsigned i = 0; i < n; ++i) cell_rhs(i) = cell_ext(i) - cell_int(i);
      constraints->distribute_local_to_global(cell_K, cell_rhs, local, K, *rhs);
    }
  }
  if (cohesive_law) assemble_cohesive(state, load, with_matrix, constraints, K, rhs, f_int);
}

void FiniteStrainSolver::Impl::build_cell_geometry() {
  const dealii::FE_SimplexP<3> scalar(static_cast<unsigned>(settings.degree));
  CellGeometry& g = geometry;
  g.nodes = scalar.n_dofs_per_cell();
  g.points = cell_quadrature->size();
  const unsigned n = fe->n_dofs_per_cell();
  g.node_of_dof.resize(n);
  for (unsigned i = 0; i < n; ++i) g.node_of_dof[i] = fe->system_to_component_index(i).second;
  const std::size_t cells = dof.get_triangulation().n_active_cells();
  g.gradients.assign(cells * g.points * g.nodes * 3, 0.0);
  g.JxW.assign(cells * g.points, 0.0);
  dealii::FEValues<3> fv(*mapping, scalar, *cell_quadrature, dealii::update_gradients | dealii::update_JxW_values);
  for (const auto& cell : dof.get_triangulation().active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    fv.reinit(cell);
    const std::size_t c = cell->active_cell_index();
    for (unsigned q = 0; q < g.points; ++q) {
      g.JxW[c * g.points + q] = fv.JxW(q);
      for (unsigned a = 0; a < g.nodes; ++a)
        for (unsigned d = 0; d < 3; ++d) g.gradients[((c * g.points + q) * g.nodes + a) * 3 + d] = fv.shape_grad(a, q)[d];
    }
  }
}

void FiniteStrainSolver::Impl::build_dynamics() {
  Dynamics d;
  const dealii::FE_SimplexP<3> scalar(static_cast<unsigned>(settings.degree));
  d.nodes = scalar.n_dofs_per_cell();
  const unsigned n = fe->n_dofs_per_cell();
  d.node_of_dof.resize(n);
  for (unsigned i = 0; i < n; ++i) d.node_of_dof[i] = fe->system_to_component_index(i).second;
  // m_ij = ∫ ρ N_i N_j dV with the cell quadrature (degree + 1 points per direction: exact for
  // N_i N_j of P1; of P2 (degree 4) QGaussSimplex(3) is exact to degree 5).
  dealii::FEValues<3> fv(*mapping, scalar, *cell_quadrature, dealii::update_values | dealii::update_JxW_values);
  d.cell_mass.resize(tria.n_active_cells());
  for (const auto& cell : tria.active_cell_iterators()) {
    fv.reinit(cell);
    const double rho = densities[cell->material_id()];
    std::vector<double> m(static_cast<std::size_t>(d.nodes) * d.nodes, 0.0);
    for (unsigned q = 0; q < fv.n_quadrature_points; ++q)
      for (unsigned i = 0; i < d.nodes; ++i)
        for (unsigned j = 0; j < d.nodes; ++j) m[i * d.nodes + j] += rho * fv.shape_value(i, q) * fv.shape_value(j, q) * fv.JxW(q);
    d.cell_mass[cell->active_cell_index()] = std::move(m);
  }
  d.u.reinit(dof.n_dofs());
  d.v.reinit(dof.n_dofs());
  d.a.reinit(dof.n_dofs());
  d.damped = std::any_of(damping.begin(), damping.end(), [](const KelvinVoigtDamping& k) { return k.retardation_time > 0.0; });
  if (d.damped) d.viscous_force.reinit(dof.n_dofs());
  dynamics = std::move(d);
}

double FiniteStrainSolver::Impl::commit_dynamics(const dealii::Vector<double>& u) {
  Dynamics& d = *dynamics;
  if (d.step > 0.0)
    for (dealii::types::global_dof_index i = 0; i < u.size(); ++i) {
      // a_{n+1} (Newmark β = 1/4), then v_{n+1} = v_n + h/2 (a_n + a_{n+1}) (γ = 1/2)
      const double a_next = newmark_acceleration(i, u[i]);
      d.v[i] += 0.5 * d.step * (d.a[i] + a_next);
      d.a[i] = a_next;
    }
  if (d.damped) {
    // The viscous forces at (u_{n+1}, v_{n+1}); a step (h > 0) dissipates their trapezoid work
    // ½ (f_v,n + f_v,n+1)·(u_{n+1} − u_n), the term the Newmark energy identity books for them.
    dealii::Vector<double> f_next(u.size());
    assemble_viscous_force(u, d.v, f_next);
    if (d.step > 0.0)
      for (dealii::types::global_dof_index i = 0; i < u.size(); ++i)
        d.damping_dissipation += 0.5 * (d.viscous_force[i] + f_next[i]) * (u[i] - d.u[i]);
    d.viscous_force = std::move(f_next);
  }
  d.u = u;
  // ½ vᵀ M v, cell by cell (M_ab = m_ij δ(c_a, c_b)).
  const unsigned n = fe->n_dofs_per_cell();
  std::vector<dealii::types::global_dof_index> local(n);
  double kinetic = 0.0;
  for (const auto& cell : dof.active_cell_iterators()) {
    cell->get_dof_indices(local);
    const std::vector<double>& m = d.cell_mass[cell->active_cell_index()];
    for (unsigned i = 0; i < n; ++i)
      for (unsigned j = 0; j < n; ++j)
        if (fe->system_to_component_index(i).first == fe->system_to_component_index(j).first)
          kinetic += 0.5 * d.v[local[i]] * m[d.node_of_dof[i] * d.nodes + d.node_of_dof[j]] * d.v[local[j]];
  }
  d.kinetic_energy = kinetic;
  return kinetic;
}

void FiniteStrainSolver::Impl::assemble_viscous_force(const dealii::Vector<double>& u, const dealii::Vector<double>& v,
                                                      dealii::Vector<double>& out) const {
  out = 0.0;
  const unsigned n = fe->n_dofs_per_cell();
  dealii::FEValues<3> fv(*mapping, *fe, *cell_quadrature, dealii::update_gradients | dealii::update_JxW_values);
  const dealii::FEValuesExtractors::Vector disp(0);
  std::vector<dealii::Tensor<2, 3>> grads(cell_quadrature->size()), rates(cell_quadrature->size());
  std::vector<dealii::types::global_dof_index> local(n);
  dealii::Vector<double> cell_f(n);
  for (const auto& cell : dof.active_cell_iterators()) {
    const KelvinVoigtDamping& kv = damping[cell->material_id()];
    if (kv.retardation_time == 0.0) continue;
    fv.reinit(cell);
    cell->get_dof_indices(local);
    fv[disp].get_function_gradients(u, grads);
    fv[disp].get_function_gradients(v, rates);
    cell_f = 0.0;
    for (unsigned q = 0; q < fv.n_quadrature_points; ++q) {
      const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + to_eigen(grads[q]);
      const Eigen::Matrix3d P_v = kelvin_voigt_stress(kv, F, to_eigen(rates[q]), 0.0).first_piola;
      for (unsigned i = 0; i < n; ++i) {
        const unsigned c = fe->system_to_component_index(i).first;
        const auto g = fv.shape_grad_component(i, q, c);
        cell_f(i) += P_v.row(c).dot(Eigen::Vector3d(g[0], g[1], g[2])) * fv.JxW(q);
      }
    }
    out.add(local, cell_f);
  }
}

void FiniteStrainSolver::Impl::build_blade_edge() {
  // This process's boundary facets, each as three global node numbers k (DOFs 3k + c, checked
  // node-major in build), outward: (X1 − X0) × (X2 − X0) points away from the cell's centre.
  std::vector<double> facets_here; // 3 nodes per facet
  std::map<dealii::types::global_dof_index, Eigen::Vector3d> nodes_here;
  auto node = [](dealii::types::global_dof_index i) { return i / 3; };
  for (const auto& cell : dof.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    for (const unsigned f : cell->face_indices()) {
      if (!cell->face(f)->at_boundary()) continue;
      const auto face = cell->face(f);
      std::array<dealii::types::global_dof_index, 3> v{};
      std::array<unsigned, 3> vi{};
      for (unsigned a = 0; a < 3; ++a) {
        v[a] = node(face->vertex_dof_index(a, 0));
        vi[a] = face->vertex_index(a);
        nodes_here[v[a]] = to_eigen(face->vertex(a));
      }
      const Eigen::Vector3d X0 = nodes_here[v[0]];
      const Eigen::Vector3d n = (nodes_here[v[1]] - X0).cross(nodes_here[v[2]] - X0);
      if (n.dot(X0 - to_eigen(cell->center())) < 0.0) {
        std::swap(v[1], v[2]);
        std::swap(vi[1], vi[2]);
      }
      auto add = [&](dealii::types::global_dof_index a, dealii::types::global_dof_index b,
                     dealii::types::global_dof_index c) {
        for (const auto k : {a, b, c}) facets_here.push_back(static_cast<double>(k));
      };
      if (settings.degree == 1) {
        add(v[0], v[1], v[2]);
        continue;
      }
      // P2: m[a] is the midpoint node of the edge (vi[a], vi[a+1]); four flat sub-facets, each
      // oriented as the face.
      std::array<dealii::types::global_dof_index, 3> m{};
      std::array<bool, 3> found{false, false, false};
      for (unsigned l = 0; l < 3; ++l) {
        const auto line = face->line(l);
        for (std::size_t a = 0; a < 3; ++a) {
          const unsigned p = vi[a], q = vi[(a + 1) % 3];
          if ((line->vertex_index(0) == p && line->vertex_index(1) == q) ||
              (line->vertex_index(0) == q && line->vertex_index(1) == p)) {
            m[a] = node(line->dof_index(0));
            nodes_here[m[a]] = to_eigen(line->center()); // straight-sided cells (MappingFE of P1)
            found[a] = true;
          }
        }
      }
      if (!(found[0] && found[1] && found[2]))
        throw std::logic_error("finite strain solver: a P2 boundary face without its edge midpoint nodes");
      add(v[0], m[0], m[2]);
      add(m[0], v[1], m[1]);
      add(m[2], m[1], v[2]);
      add(m[0], m[1], m[2]);
    }
  }
  // Every process's facets and nodes (rank order): 3 numbers per facet; 4 per node (k, X).
  std::vector<double> my_nodes;
  for (const auto& [k, X] : nodes_here) my_nodes.insert(my_nodes.end(), {static_cast<double>(k), X.x(), X.y(), X.z()});
  std::vector<std::vector<double>> all_facets{facets_here}, all_nodes{my_nodes};
  if (distributed) {
    all_facets = all_gather(parallel->comm, facets_here);
    all_nodes = all_gather(parallel->comm, my_nodes);
  }
  const int here = distributed ? rank : 0;
  BladeEdgeBoundary b;
  std::map<dealii::types::global_dof_index, int> compact;
  for (std::size_t r = 0; r < all_nodes.size(); ++r)
    for (std::size_t i = 0; i + 3 < all_nodes[r].size(); i += 4) {
      const auto k = static_cast<dealii::types::global_dof_index>(all_nodes[r][i]);
      if (compact.count(k) != 0) continue; // the first process holding a node supplies it
      compact.emplace(k, static_cast<int>(b.node_of.size()));
      b.node_of.push_back(k);
      b.positions.emplace_back(all_nodes[r][i + 1], all_nodes[r][i + 2], all_nodes[r][i + 3]);
      b.node_here.push_back(static_cast<int>(r) == here ? 1 : 0);
    }
  double longest = 0.0;
  for (std::size_t r = 0; r < all_facets.size(); ++r)
    for (std::size_t i = 0; i + 2 < all_facets[r].size(); i += 3) {
      BoundaryFacet facet{};
      for (std::size_t a = 0; a < 3; ++a)
        facet[a] = compact.at(static_cast<dealii::types::global_dof_index>(all_facets[r][i + a]));
      for (std::size_t a = 0; a < 3; ++a)
        longest = std::max(longest, (b.positions[static_cast<std::size_t>(facet[a])] -
                                     b.positions[static_cast<std::size_t>(facet[(a + 1) % 3])]).norm());
      b.facets.push_back(facet);
      b.facet_here.push_back(static_cast<int>(r) == here ? 1 : 0);
    }
  // ε_L = ε_N h_min (a line load E h_min costs a penetration h_min / 50 with the automatic ε_N)
  b.settings.line_penalty = settings.edge_line_penalty > 0.0 ? settings.edge_line_penalty : penalty * h_min;
  b.settings.point_spacing = settings.edge_point_spacing > 0.0 ? settings.edge_point_spacing : 0.25 * h_min;
  // Facets farther than two boundary edges from an edge point cannot hold its closest point once
  // the edge has entered the body by less than that in one load increment.
  b.settings.search_distance = 2.0 * longest;
  b.displacement.assign(3 * b.node_of.size(), 0.0);
  blade_edge = std::move(b);
}

template <class VectorType, class MatrixType, class Tally>
void FiniteStrainSolver::Impl::assemble_blade_edge(const VectorType& state, const LoadState& load, bool with_matrix,
                                                   Tally& out, const dealii::AffineConstraints<double>* constraints,
                                                   MatrixType& K, VectorType* rhs, VectorType& f_ext) const {
  const BladeEdgeBoundary& b = *blade_edge;
  // The boundary nodes' displacements, each supplied by one process (collective when distributed).
  std::fill(b.displacement.begin(), b.displacement.end(), 0.0);
  for (std::size_t k = 0; k < b.node_of.size(); ++k)
    if (b.node_here[k] != 0)
      for (unsigned c = 0; c < 3; ++c) b.displacement[3 * k + c] = state[3 * b.node_of[k] + c];
  sum(b.displacement);
  const BladeEdgeContact contact =
      blade_edge_contact(*tool, load.tool_position, b.facets, b.positions, b.displacement, b.settings);
  dealii::FullMatrix<double> term_K(9, 9);
  dealii::Vector<double> term_f(9);
  std::vector<dealii::types::global_dof_index> term_dofs(9);
  for (const EdgeContactTerm& t : contact.terms) {
    if (b.facet_here[t.facet] == 0) continue; // another process's facet
    for (unsigned i = 0; i < 9; ++i) {
      term_dofs[i] = 3 * b.node_of[static_cast<std::size_t>(t.nodes[i / 3])] + i % 3;
      term_f(i) = t.force_on_body(i);
      for (unsigned j = 0; j < 9; ++j) term_K(i, j) = t.stiffness(i, j);
    }
    f_ext.add(term_dofs, term_f);
    // K += ∂²W/∂x², rhs += f (rhs = f_ext − f_int)
    if (with_matrix) constraints->distribute_local_to_global(term_K, term_f, term_dofs, K, *rhs);
    for (int i = 0; i < 3; ++i) out.contact_on_body += t.force_on_body.template segment<3>(3 * i);
    ++out.edge_points;
    out.edge_length += t.weight;
    out.max_line_load = std::max(out.max_line_load, t.line_load);
    // W = ½ ε_L w d² = ½ w q² / ε_L with the line load q = ε_L d (blade_edge_contact.hpp).
    out.contact_energy += 0.5 * t.weight * t.line_load * t.line_load / b.settings.line_penalty;
  }
}

void FiniteStrainSolver::Impl::build_cohesive(const CohesiveInterfaceSpec& spec, int plus_group, int minus_group) {
  validate(spec.law);
  if (spec.plus_surface == spec.minus_surface)
    throw std::invalid_argument("finite strain solver: cohesive plus and minus surfaces are the same group '" + spec.plus_surface + "'");
  const unsigned n = fe->n_dofs_per_cell();
  cell_components.resize(n);
  for (unsigned i = 0; i < n; ++i) cell_components[i] = fe->system_to_component_index(i).first;

  // Coincident faces are found by their vertex positions, rounded on a grid far finer than any
  // element (the copies made by the crack split, and their refinements, coincide exactly).
  const double grid = 1e-6 * h_min;
  using Key = std::array<long long, 9>;
  auto key_of = [&](const auto& face) {
    std::array<std::array<long long, 3>, 3> v{};
    for (unsigned k = 0; k < 3; ++k)
      for (unsigned c = 0; c < 3; ++c) v[k][c] = std::llround(face->vertex(k)[c] / grid);
    std::sort(v.begin(), v.end());
    Key key{};
    for (unsigned k = 0; k < 3; ++k)
      for (unsigned c = 0; c < 3; ++c) key[3 * k + c] = v[k][c];
    return key;
  };
  std::map<Key, std::pair<dealii::DoFHandler<3>::active_cell_iterator, unsigned>> minus_faces;
  for (const auto& cell : dof.active_cell_iterators())
    for (const unsigned f : cell->face_indices())
      if (cell->face(f)->at_boundary() && in_group(cell->face(f)->boundary_id(), minus_group))
        minus_faces[key_of(cell->face(f))] = {cell, f};

  dealii::FEFaceValues<3> ffv(*mapping, *fe, *face_quadrature,
                              dealii::update_values | dealii::update_quadrature_points | dealii::update_JxW_values |
                                  dealii::update_normal_vectors);
  std::vector<dealii::types::global_dof_index> plus_dofs(n), minus_dofs(n);
  for (const auto& cell : dof.active_cell_iterators())
    for (const unsigned f : cell->face_indices()) {
      if (!cell->face(f)->at_boundary() || !in_group(cell->face(f)->boundary_id(), plus_group)) continue;
      const auto match = minus_faces.find(key_of(cell->face(f)));
      if (match == minus_faces.end())
        throw std::invalid_argument("finite strain solver: a face of cohesive surface '" + spec.plus_surface + "' at (" +
                                    std::to_string(cell->face(f)->center()[0]) + ", " + std::to_string(cell->face(f)->center()[1]) +
                                    ", " + std::to_string(cell->face(f)->center()[2]) + ") m has no coincident face in '" +
                                    spec.minus_surface + "' (was the mesh split along the crack path?)");
      const auto minus_cell = match->second.first;
      ffv.reinit(cell, f);
      CohesivePair pair;
      cell->get_dof_indices(plus_dofs);
      minus_cell->get_dof_indices(minus_dofs);
      pair.dofs = plus_dofs;
      pair.dofs.insert(pair.dofs.end(), minus_dofs.begin(), minus_dofs.end());
      // The + cell's outward normal points into the − side; n points from − into +.
      pair.normal = -Eigen::Vector3d(ffv.normal_vector(0)[0], ffv.normal_vector(0)[1], ffv.normal_vector(0)[2]);
      crack_face_sides[4 * cell->active_cell_index() + f] = pair.normal;
      crack_face_sides[4 * minus_cell->active_cell_index() + match->second.second] = -pair.normal;
      for (unsigned k = 0; k < 3; ++k) pair.vertices[k] = to_eigen(cell->face(f)->vertex(k));
      // The − cell's unit coordinates of each quadrature point (affine P1 geometry: ξ = A⁻¹ (x − v₀),
      // the unit tetrahedron's vertices 1, 2, 3 being e_x, e_y, e_z).
      Eigen::Matrix3d A;
      const Eigen::Vector3d v0 = to_eigen(minus_cell->vertex(0));
      for (unsigned k = 1; k < 4; ++k) A.col(k - 1) = to_eigen(minus_cell->vertex(k)) - v0;
      const Eigen::Matrix3d A_inv = A.inverse();
      for (unsigned q = 0; q < ffv.n_quadrature_points; ++q) {
        const Eigen::Vector3d x = to_eigen(ffv.quadrature_point(q));
        const Eigen::Vector3d xi = A_inv * (x - v0);
        const dealii::Point<3> unit(xi[0], xi[1], xi[2]);
        std::vector<double> plus(n), minus(n);
        for (unsigned i = 0; i < n; ++i) {
          plus[i] = ffv.shape_value_component(i, q, cell_components[i]);
          minus[i] = fe->shape_value_component(i, unit, cell_components[i]);
        }
        pair.plus_values.push_back(std::move(plus));
        pair.minus_values.push_back(std::move(minus));
        pair.weights.push_back(ffv.JxW(q));
        pair.points.push_back(x);
      }
      cohesive_pairs.push_back(std::move(pair));
    }
  if (cohesive_pairs.empty())
    throw std::invalid_argument("finite strain solver: cohesive surface '" + spec.plus_surface + "' has no boundary faces");
  if (cohesive_pairs.size() != minus_faces.size())
    throw std::invalid_argument("finite strain solver: cohesive surfaces '" + spec.plus_surface + "' and '" + spec.minus_surface +
                                "' have different face counts (" + std::to_string(cohesive_pairs.size()) + " and " +
                                std::to_string(minus_faces.size()) + ")");
  cohesive_law = spec.law;
  cohesive_states.assign(cohesive_pairs.size() * face_quadrature->size(), CohesiveState{});
}

template <class VectorType>
Eigen::Vector3d FiniteStrainSolver::Impl::cohesive_opening(const CohesivePair& pair, std::size_t q,
                                                          const VectorType& state) const {
  // Δ = x⁺ − x⁻ = u⁺ − u⁻ at a point where the two faces coincide in the reference configuration.
  const std::size_t n = cell_components.size();
  Eigen::Vector3d opening = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    opening[cell_components[i]] += pair.plus_values[q][i] * state(pair.dofs[i]);
    opening[cell_components[i]] -= pair.minus_values[q][i] * state(pair.dofs[n + i]);
  }
  return opening;
}

template <class VectorType, class MatrixType>
void FiniteStrainSolver::Impl::assemble_cohesive(const VectorType& state, const LoadState& load, bool with_matrix,
                                                 const dealii::AffineConstraints<double>* constraints, MatrixType& K,
                                                 VectorType* rhs, VectorType& f_int) const {
  // Interface potential Π = ∫ φ(Δ) dA with Δ = Σ N⁺ u⁺ − Σ N⁻ u⁻: f_int,a = ∫ s_a N_a t dA and
  // K_ab = ∫ s_a N_a (∂t/∂Δ) s_b N_b dA, s = +1 on the + side and −1 on the − side.
  const std::size_t n = cell_components.size(), nq = face_quadrature->size();
  const double dt = load.time - committed_time;
  dealii::FullMatrix<double> local_K(2 * n, 2 * n);
  dealii::Vector<double> local_rhs(2 * n), local_f(2 * n);
  std::vector<double> a(2 * n);
  std::vector<unsigned> comp(2 * n);
  for (std::size_t i = 0; i < 2 * n; ++i) comp[i] = cell_components[i % n];
  for (std::size_t p = 0; p < cohesive_pairs.size(); ++p) {
    const CohesivePair& pair = cohesive_pairs[p];
    local_K = 0.0;
    local_rhs = 0.0;
    local_f = 0.0;
    for (std::size_t q = 0; q < nq; ++q) {
      const CohesiveResponse r =
          cohesive_response(*cohesive_law, cohesive_states[p * nq + q], cohesive_opening(pair, q, state), pair.normal, dt,
                            cohesive_secant);
      const double w = pair.weights[q];
      for (std::size_t i = 0; i < n; ++i) {
        a[i] = pair.plus_values[q][i];
        a[n + i] = -pair.minus_values[q][i];
      }
      for (std::size_t i = 0; i < 2 * n; ++i) {
        if (a[i] == 0.0) continue;
        const double f = a[i] * r.traction[comp[i]] * w;
        local_f(static_cast<unsigned>(i)) += f;
        local_rhs(static_cast<unsigned>(i)) -= f;
        if (with_matrix)
          for (std::size_t j = 0; j < 2 * n; ++j)
            local_K(static_cast<unsigned>(i), static_cast<unsigned>(j)) += a[i] * a[j] * r.tangent(comp[i], comp[j]) * w;
      }
    }
    f_int.add(pair.dofs, local_f);
    if (with_matrix) constraints->distribute_local_to_global(local_K, local_rhs, pair.dofs, K, *rhs);
  }
}

CohesiveSummary FiniteStrainSolver::Impl::commit_cohesive(const LoadState& load) {
  const std::size_t nq = face_quadrature->size();
  const double dt = load.time - committed_time;
  const double d0 = cohesive_law->peak_opening();
  CohesiveSummary summary;
  for (std::size_t p = 0; p < cohesive_pairs.size(); ++p)
    for (std::size_t q = 0; q < nq; ++q) {
      CohesiveState& state = cohesive_states[p * nq + q];
      const Eigen::Vector3d opening = cohesive_opening(cohesive_pairs[p], q, serial.u);
      const CohesiveResponse r = cohesive_response(*cohesive_law, state, opening, cohesive_pairs[p].normal, dt);
      const double w = cohesive_pairs[p].weights[q];
      if (dt > 0.0) cohesive_viscous_dissipation += r.viscous_power_density * dt * w;
      if (dynamics) {
        // ½ (t_n + t_{n+1})·(Δ_{n+1} − Δ_n) without the viscous part (dt = 0): t_n is the traction at
        // the last converged opening Δ_n with the damage κ_n reached there.
        const Eigen::Vector3d& n = cohesive_pairs[p].normal;
        const CohesiveResponse before = cohesive_response(*cohesive_law, state, state.previous_opening, n, 0.0);
        const CohesiveResponse after = cohesive_law->viscosity > 0.0 ? cohesive_response(*cohesive_law, state, opening, n, 0.0) : r;
        const double trapezoid = 0.5 * (before.traction + after.traction).dot(opening - state.previous_opening) * w;
        cohesive_trapezoid_work += trapezoid;
        // The step's kinks error: the trapezoid work minus Δ(φ_e + φ_d) at this point.
        summary.step_time_integration_error +=
            trapezoid - (after.stored_energy + after.dissipated_energy - before.stored_energy - before.dissipated_energy) * w;
        summary.step_dissipation += (after.dissipated_energy - before.dissipated_energy) * w;
      }
      state.max_opening = r.damage_opening;
      state.previous_opening = opening;
      if (r.failed) summary.failed_area += w;
      if (r.damage_opening > d0) summary.damaged_area += w;
      summary.stored_energy += r.stored_energy * w;
      summary.dissipated_energy += r.dissipated_energy * w;
      summary.max_damage = std::max(summary.max_damage, r.damage);
    }
  committed_time = load.time;
  summary.viscous_dissipation = cohesive_viscous_dissipation;
  summary.trapezoid_work = cohesive_trapezoid_work;
  return summary;
}

FiniteStrainSolver::FiniteStrainSolver(const FiniteStrainProblem& problem, const SolverSettings& settings)
    : m_impl(std::make_unique<Impl>()) {
  m_impl->settings = settings;
  m_impl->build(problem);
}

FiniteStrainSolver::~FiniteStrainSolver() = default;

EquilibriumReport FiniteStrainSolver::solve(const LoadState& load) {
  return m_impl->with_algebra([&](auto& la) { return m_impl->solve(la, load); });
}

double FiniteStrainSolver::Impl::extrapolation_factor(const LoadState& load) const {
  if (history < 2) return 0.0;
  const LoadState& l1 = load_last;
  const LoadState& l0 = load_before;
  // The load's parameter along the trajectory: the tool's travel, else the load factor; the time
  // when only time moves the problem (inertia, a viscous interface). A dwell (same load) keeps u₁.
  const bool same_load = load.load_factor == l1.load_factor && load.tool_position == l1.tool_position;
  const bool rate_dependent = dynamics.has_value() || (cohesive_law && cohesive_law->viscosity > 0.0);
  double s = 0.0;
  const Eigen::Vector3d d = l1.tool_position - l0.tool_position;
  if (same_load && !rate_dependent) {
    s = 0.0;
  } else if (d.squaredNorm() > 0.0) {
    s = (load.tool_position - l1.tool_position).dot(d) / d.squaredNorm();
  } else if (l1.load_factor != l0.load_factor) {
    s = (load.load_factor - l1.load_factor) / (l1.load_factor - l0.load_factor);
  } else if (rate_dependent && l1.time != l0.time) {
    s = (load.time - l1.time) / (l1.time - l0.time);
  }
  // Forward only, and at most twice the last increment: a start guess, never a leap.
  return std::isfinite(s) ? std::clamp(s, 0.0, 2.0) : 0.0;
}

template <class Algebra> EquilibriumReport FiniteStrainSolver::Impl::solve(Algebra& la, const LoadState& load) {
  using VectorType = typename Algebra::VectorType;
  Impl& m = *this;
  const VectorType start = la.u;
  // Dynamic step: h from the last converged time (0: a quasi-static solve, no inertia).
  if (m.dynamics) m.dynamics->step = std::max(0.0, load.time - m.committed_time);
  m.fault_fired = false;
  // The predictor: the last two converged states extrapolated linearly along the trajectory,
  // u = u₁ + s (u₁ − u₀). Only Newton's start changes; the equilibrium it converges to is the same
  // (to the Newton tolerance). Should Newton fail from there, it starts again from u₁.
  const double s = m.settings.extrapolate_initial_guess ? m.extrapolation_factor(load) : 0.0;
  EquilibriumReport report;
  if (s > 0.0) {
    la.u *= 1.0 + s;
    la.u.add(-s, la.u_previous);
    report = m.newton(la, load, start);
    if (!report.converged && !m.fault_fired) {
      EquilibriumReport again = m.newton(la, load, start);
      again.newton_iterations += report.newton_iterations;
      again.assembly_seconds += report.assembly_seconds;
      again.linear_solve_seconds += report.linear_solve_seconds;
      again.linear_iterations += report.linear_iterations;
      again.factorizations += report.factorizations;
      report = std::move(again);
    }
  } else {
    report = m.newton(la, load, start);
  }
  if (!report.converged) return report;
  la.u_previous = start;
  m.load_before = m.load_last;
  m.load_last = load;
  m.history = std::min(2, m.history + 1);
  return report;
}

template <class Algebra>
double FiniteStrainSolver::Impl::dirichlet_constraints(const Algebra& la, const typename Algebra::VectorType& u,
                                                      const LoadState& load,
                                                      dealii::AffineConstraints<double>& c) const {
  c.clear();
  la.prepare(c);
  const auto& u_relevant = la.ghosted(u);
  double mismatch = 0.0;
  for (const auto& d : dirichlet) {
    const double g = dirichlet_target(d, load.load_factor) - u_relevant[d.index];
    mismatch = std::max(mismatch, std::abs(g));
    c.add_line(d.index);
    c.set_inhomogeneity(d.index, g);
  }
  c.close();
  return max(mismatch);
}

template <class Algebra>
EquilibriumReport FiniteStrainSolver::Impl::newton(Algebra& la, const LoadState& load,
                                                   const typename Algebra::VectorType& start) {
  using VectorType = typename Algebra::VectorType;
  constexpr bool serial_algebra = std::is_same_v<VectorType, dealii::Vector<double>>;
  Impl& m = *this;
  EquilibriumReport report;
  // `assembly` (with la.K, `rhs` and `constraints` when `with_tangent`) is the assembly of the
  // current state la.u when `assembled`. A Newton step assembles its full step (α = 1) with the
  // tangent, so that when it is accepted the next Newton step starts from it.
  Impl::Assembly<VectorType> assembly, full, trial;
  VectorType rhs, full_rhs, du;
  la.reinit(rhs);
  la.reinit(full_rhs);
  la.reinit(du);
  dealii::AffineConstraints<double> constraints, full_constraints;
  double mismatch = 0.0;
  bool assembled = false, with_tangent = false;
  // Quasi-Newton (SolverSettings::quasi_newton; serial direct solver): steps with the last
  // factorised tangent K₀ corrected by the BFGS updates of the steps since (limited memory, the
  // two-loop recursion with H₀ = K₀⁻¹; Matthies & Strang 1979, Nocedal 1980). A full Newton step
  // (tangent assembled and factorised) is taken when a Dirichlet increment is pending, when no
  // factorisation exists, and after a quasi-Newton step that reduced |R| by less than half, did
  // not reduce it, or used up the updates.
  // Contact and a cohesive interface change the tangent abruptly (points enter and leave the
  // contact set, the interface softens): there the updates converge slowly, and full Newton is used.
  // Every solve starts with a Newton step (FEBio's "reform each time step"), so that a solve
  // depends on its start state alone (a run resumed from a checkpoint repeats it bit for bit).
  const bool quasi_newton_allowed = serial_algebra && m.settings.quasi_newton && !m.tool && !m.cohesive_law &&
                                    m.linear->kind() == TangentSolver::Kind::direct;
  bool newton_next = true;
  std::vector<VectorType> S, Y; // the steps s = Δu and residual changes y = ΔR of the updates
  std::vector<double> rho;      // 1 / (yᵀ s)
  constexpr std::size_t max_updates = 10;
  // Fault injection: asked once per iteration (the full step's assembly asks for the next one).
  int fault_asked = -1;
  bool fault_answer = false;
  auto fault = [&](int it) {
    if (!m.settings.residual_fault) return false;
    if (fault_asked != it) {
      fault_asked = it;
      fault_answer = m.settings.residual_fault(load, it);
    }
    m.fault_fired = m.fault_fired || fault_answer;
    return fault_answer;
  };
  // A cohesive interface whose points switch between loading and unloading can make the
  // consistent Newton iteration cycle; after a third of the allowed iterations the secant
  // interface tangent takes over (slower, but it does not cycle). It changes the tangent only.
  auto secant = [&](int it) { return m.cohesive_law.has_value() && it >= m.settings.max_newton_iterations / 3; };
  auto fail = [&](std::string why) {
    la.u = start;
    report.converged = false;
    report.failure = std::move(why);
    return report;
  };
  try {
    for (int it = 0;; ++it) {
      auto t0 = Clock::now();
      if (!assembled) {
        mismatch = m.dirichlet_constraints(la, la.u, load, constraints);
        m.cohesive_secant = secant(it);
        m.poison_residual = fault(it);
        with_tangent = newton_next || mismatch > 0.0;
        m.assemble(la, la.u, load, with_tangent, assembly, with_tangent ? &constraints : nullptr,
                   with_tangent ? &rhs : nullptr);
        m.poison_residual = false;
        report.assembly_seconds += seconds_since(t0);
      }
      assembled = false;
      const double r = m.free_norm(assembly.residual, la.free_mask);
      report.residual_history.push_back(r);
      const double scale = assembly.internal_norm + assembly.external_norm;
      const double tol = m.settings.relative_tolerance * scale + m.settings.absolute_tolerance;
      const double u_scale = std::max(la.u.linfty_norm(), 1e-300);
      if (r <= tol && mismatch <= 1e-12 * u_scale + 1e-300) {
        report.converged = true;
        break;
      }
      if (it >= m.settings.max_newton_iterations)
        return fail("no convergence in " + std::to_string(m.settings.max_newton_iterations) + " Newton iterations");
      const bool newton_step = newton_next || mismatch > 0.0 || !quasi_newton_allowed;
      if (newton_step && !with_tangent) {
        // The state's residual came from a line search: its tangent is assembled now.
        t0 = Clock::now();
        m.cohesive_secant = secant(it);
        m.assemble(la, la.u, load, true, assembly, &constraints, &rhs);
        report.assembly_seconds += seconds_since(t0);
      }
      t0 = Clock::now();
      if (newton_step) {
        report.linear_iterations += m.linear->solve(la.K, du, rhs);
        constraints.distribute(du);
        ++report.factorizations;
        S.clear();
        Y.clear();
        rho.clear();
      } else if constexpr (serial_algebra) {
        // du = −H R over the free DOFs: the two-loop recursion around K₀⁻¹.
        VectorType q = assembly.residual;
        q.scale(la.free_mask);
        q *= -1.0;
        std::vector<double> alpha_k(S.size());
        for (std::size_t k = S.size(); k-- > 0;) {
          alpha_k[k] = rho[k] * (S[k] * q);
          q.add(-alpha_k[k], Y[k]);
        }
        m.linear->solve_factorized(du, q);
        du.scale(la.free_mask);
        for (std::size_t k = 0; k < S.size(); ++k) {
          const double beta = rho[k] * (Y[k] * du);
          du.add(alpha_k[k] - beta, S[k]);
        }
      }
      report.linear_solve_seconds += seconds_since(t0);
      ++report.newton_iterations;
      // Backtracking line search on the free residual: the first α in 1, ½, … (6 tries) that keeps
      // every element valid and reduces |R|, else the valid α with the smallest |R|. While a
      // Dirichlet increment is pending the residual is no merit function (it starts at zero and
      // must grow with the imposed displacement): then the largest valid α is taken.
      const VectorType base = la.u;
      double best_alpha = 0.0, best_r = std::numeric_limits<double>::infinity();
      bool full_valid = false, full_tangent = false;
      double full_mismatch = 0.0;
      for (double alpha = 1.0; alpha > 1.0 / 64.0; alpha *= 0.5) {
        la.u = base;
        la.u.add(alpha, du);
        Impl::Assembly<VectorType>& a = alpha == 1.0 ? full : trial;
        t0 = Clock::now();
        if (alpha == 1.0) {
          // The full step, assembled as the next iteration would (its constraints, fault; the
          // tangent when this step is a Newton step, whose successor is likely one too).
          full_mismatch = m.dirichlet_constraints(la, la.u, load, full_constraints);
          m.cohesive_secant = secant(it + 1);
          const bool poisoned = fault(it + 1);
          m.poison_residual = poisoned;
          full_tangent = newton_step || !quasi_newton_allowed;
          try {
            m.assemble(la, la.u, load, full_tangent, full, full_tangent ? &full_constraints : nullptr,
                       full_tangent ? &full_rhs : nullptr);
          } catch (const FiniteStrainError&) {
            m.poison_residual = false;
            report.assembly_seconds += seconds_since(t0);
            if (poisoned) throw FiniteStrainError("finite strain: non-finite residual");
            continue;
          }
          m.poison_residual = false;
          full_valid = true;
        } else {
          m.cohesive_secant = secant(it);
          try {
            m.assemble(la, la.u, load, false, trial, nullptr, nullptr);
          } catch (const FiniteStrainError&) {
            report.assembly_seconds += seconds_since(t0);
            continue;
          }
        }
        report.assembly_seconds += seconds_since(t0);
        const double rt = m.free_norm(a.residual, la.free_mask);
        if (rt < best_r) {
          best_r = rt;
          best_alpha = alpha;
        }
        if (mismatch > 0.0 || rt <= (1.0 - 1e-4 * alpha) * r || rt <= tol) {
          best_alpha = alpha;
          break;
        }
      }
      if (!newton_step && !(best_r < r)) {
        // The quasi-Newton direction does not reduce |R|: back to the state, a Newton step next.
        la.u = base;
        newton_next = true;
        assembled = true; // the residual is still the state's (its tangent is assembled above)
        with_tangent = false;
        continue;
      }
      if (best_alpha == 0.0) return fail("every line-search step inverts an element");
      la.u = base;
      la.u.add(best_alpha, du);
      if constexpr (serial_algebra) {
        if (quasi_newton_allowed) {
          // The BFGS update of this step, when the accepted state's residual is at hand: s = Δu,
          // y = ΔR over the free DOFs, kept while yᵀ s > 0 (the curvature condition).
          const Impl::Assembly<VectorType>* accepted =
              best_alpha == 1.0 ? (full_valid ? &full : nullptr) : &trial;
          const bool last_trial_is_best = best_alpha == 1.0 || best_r == m.free_norm(trial.residual, la.free_mask);
          if (accepted != nullptr && last_trial_is_best) {
            VectorType s = du;
            s *= best_alpha;
            s.scale(la.free_mask);
            VectorType y = accepted->residual;
            y -= assembly.residual;
            y.scale(la.free_mask);
            const double ys = y * s;
            if (ys > 0.0) {
              S.push_back(std::move(s));
              Y.push_back(std::move(y));
              rho.push_back(1.0 / ys);
            }
          }
          newton_next = !(best_r <= 0.5 * r) || S.size() >= max_updates;
        }
      }
      if (best_alpha == 1.0 && full_valid) {
        std::swap(assembly, full);
        if (full_tangent) {
          rhs.swap(full_rhs);
          std::swap(constraints, full_constraints);
        } else {
          constraints.clear(); // residual only: constraints are rebuilt if a Newton step follows
          full_mismatch = m.dirichlet_constraints(la, la.u, load, constraints);
        }
        mismatch = full_mismatch;
        with_tangent = full_tangent;
        assembled = true;
      } else if (!newton_step || quasi_newton_allowed) {
        // A shortened step: the last trial is the accepted state's residual when it was the best.
        if (best_alpha < 1.0 && best_r == m.free_norm(trial.residual, la.free_mask)) {
          std::swap(assembly, trial);
          mismatch = m.dirichlet_constraints(la, la.u, load, constraints);
          with_tangent = false; // a Newton step next assembles the tangent at the loop's top
          assembled = true;
        }
      }
    }
  } catch (const FiniteStrainError& e) {
    m.poison_residual = false;
    return fail(e.what());
  } catch (const std::exception& e) { // PETSc/UMFPACK errors (deal.II exceptions are std::exception)
    return fail(std::string("linear solver: ") + e.what());
  }
  // Reactions: the residual R on the Dirichlet DOFs is the force the supports put on the body;
  // the reaction of boundary b (body on support) is −Σ R over the Dirichlet DOFs assigned to b.
  report.boundary_reactions.resize(m.boundaries.size());
  for (std::size_t b = 0; b < m.boundaries.size(); ++b) report.boundary_reactions[b].surface = m.boundaries[b].surface;
  for (const auto& d : m.dirichlet)
    if (la.owns(d.index))
      report.boundary_reactions[static_cast<std::size_t>(d.boundary)].force[d.component] -= assembly.residual[d.index];
  for (BoundaryReaction& b : report.boundary_reactions) {
    m.sum(std::span<double>(b.force.data(), 3));
    report.support_reaction += b.force;
  }
  if (m.cohesive_law) report.cohesive = m.commit_cohesive(load);
  if (m.dynamics) {
    if constexpr (std::is_same_v<VectorType, dealii::Vector<double>>) report.kinetic_energy = m.commit_dynamics(la.u);
    report.damping_dissipation = m.dynamics->damping_dissipation;
  }
  m.committed_time = load.time;
  report.tool_force = -assembly.contact_on_body;
  report.traction_resultant = assembly.traction_on_body;
  report.force_imbalance = report.traction_resultant - report.tool_force - report.support_reaction;
  report.edge_contact_points = assembly.edge_points;
  report.edge_contact_length = assembly.edge_length;
  report.max_edge_line_load = assembly.max_line_load;
  report.contact_points = assembly.contact_points;
  report.contact_area = assembly.contact_area;
  report.max_contact_pressure = assembly.max_pressure;
  report.contact_energy = assembly.contact_energy;
  return report;
}

std::size_t FiniteStrainSolver::dof_count() const { return m_impl->dof.n_dofs(); }
std::size_t FiniteStrainSolver::cell_count() const { return m_impl->tria.n_active_cells(); }
std::string FiniteStrainSolver::linear_solver_name() const { return m_impl->linear->name(); }
double FiniteStrainSolver::contact_penalty() const { return m_impl->penalty; }
std::size_t FiniteStrainSolver::cohesive_point_count() const { return m_impl->cohesive_states.size(); }
double FiniteStrainSolver::crack_extent(const Eigen::Vector3d& direction) const {
  const Impl& m = *m_impl;
  if (!m.cohesive_law) return 0.0;
  const std::size_t nq = m.face_quadrature->size();
  const double df = m.cohesive_law->failure_opening();
  double first = std::numeric_limits<double>::infinity(), reach = -std::numeric_limits<double>::infinity();
  for (std::size_t p = 0; p < m.cohesive_pairs.size(); ++p) {
    for (const Eigen::Vector3d& v : m.cohesive_pairs[p].vertices) first = std::min(first, v.dot(direction));
    for (std::size_t q = 0; q < nq; ++q)
      if (m.cohesive_states[p * nq + q].max_opening >= df) reach = std::max(reach, m.cohesive_pairs[p].points[q].dot(direction));
  }
  return reach > first ? reach - first : 0.0;
}
double FiniteStrainSolver::max_displacement() const {
  double best = 0.0;
  const std::vector<double> u = state();
  for (std::size_t k = 0; k + 2 < u.size(); k += 3)
    best = std::max(best, std::sqrt(u[k] * u[k] + u[k + 1] * u[k + 1] + u[k + 2] * u[k + 2]));
  return best;
}

double FiniteStrainSolver::kinetic_energy() const { return m_impl->dynamics ? m_impl->dynamics->kinetic_energy : 0.0; }
double FiniteStrainSolver::damping_dissipation() const {
  return m_impl->dynamics ? m_impl->dynamics->damping_dissipation : 0.0;
}

int FiniteStrainSolver::process_count() const { return m_impl->distributed ? m_impl->process_count : 1; }

Eigen::Vector3d FiniteStrainSolver::displacement_at(const Eigen::Vector3d& X) const {
  const Impl& m = *m_impl;
  std::optional<Eigen::Vector3d> found;
  m.with_algebra([&](const auto& la) {
    const auto& u = la.ghosted(la.u);
    // The cell whose barycentric coordinates of X are all >= −tol (straight-sided tetrahedra).
    for (const auto& cell : m.dof.active_cell_iterators()) {
      if (!cell->is_locally_owned()) continue;
      Eigen::Matrix3d A;
      const Eigen::Vector3d v0 = to_eigen(cell->vertex(0));
      for (unsigned k = 1; k < 4; ++k) A.col(k - 1) = to_eigen(cell->vertex(k)) - v0;
      const Eigen::Vector3d xi = A.lu().solve(X - v0);
      const double tol = 1e-10;
      if (xi.minCoeff() < -tol || xi.sum() > 1.0 + tol) continue;
      // The unit tetrahedron's vertices 1, 2, 3 are e_x, e_y, e_z: the unit point is ξ itself.
      const dealii::Quadrature<3> point(dealii::Point<3>(xi[0], xi[1], xi[2]));
      dealii::FEValues<3> fv(*m.mapping, *m.fe, point, dealii::update_values);
      fv.reinit(cell);
      std::vector<dealii::Vector<double>> value(1, dealii::Vector<double>(3));
      fv.get_function_values(u, value);
      found = Eigen::Vector3d(value[0][0], value[0][1], value[0][2]);
      return;
    }
  });
  // Distributed: the lowest rank whose cells hold X answers.
  const double owner = -m.max(found ? -static_cast<double>(m.rank) : -static_cast<double>(INT_MAX));
  if (owner == static_cast<double>(INT_MAX))
    throw std::out_of_range("displacement_at: the point lies outside the mesh");
  Eigen::Vector3d value = found && owner == static_cast<double>(m.rank) ? *found : Eigen::Vector3d::Zero();
  m.sum(std::span<double>(value.data(), 3));
  return value;
}

std::vector<Eigen::Matrix3d> FiniteStrainSolver::quadrature_cauchy_stresses() const {
  const Impl& m = *m_impl;
  std::vector<Eigen::Matrix3d> out;
  dealii::FEValues<3> fv(*m.mapping, *m.fe, *m.cell_quadrature, dealii::update_gradients);
  std::vector<dealii::Tensor<2, 3>> grads(m.cell_quadrature->size());
  m.with_algebra([&](const auto& la) {
    const auto& u = la.ghosted(la.u);
    for (const auto& cell : m.dof.active_cell_iterators()) {
      if (!cell->is_locally_owned()) continue;
      fv.reinit(cell);
      fv[dealii::FEValuesExtractors::Vector(0)].get_function_gradients(u, grads);
      for (const auto& g : grads) {
        const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + to_eigen(g);
        out.push_back(cauchy_stress(F, m.laws[cell->material_id()]->stress_and_tangent(F).first_piola));
      }
    }
  });
  return out;
}

double FiniteStrainSolver::strain_energy() const {
  const Impl& m = *m_impl;
  return m.with_algebra([&](const auto& la) {
    const auto& u = la.ghosted(la.u);
    dealii::FEValues<3> fv(*m.mapping, *m.fe, *m.cell_quadrature, dealii::update_gradients | dealii::update_JxW_values);
    std::vector<dealii::Tensor<2, 3>> grads(m.cell_quadrature->size());
    double energy = 0.0;
    for (const auto& cell : m.dof.active_cell_iterators()) {
      if (!cell->is_locally_owned()) continue;
      fv.reinit(cell);
      fv[dealii::FEValuesExtractors::Vector(0)].get_function_gradients(u, grads);
      for (unsigned q = 0; q < fv.n_quadrature_points; ++q)
        energy += m.laws[cell->material_id()]->energy(Eigen::Matrix3d::Identity() + to_eigen(grads[q])) * fv.JxW(q);
    }
    return m.sum(energy);
  });
}

std::vector<double> FiniteStrainSolver::state() const {
  const Impl& m = *m_impl;
  std::vector<double> values;
  if (!m.distributed) {
    values.assign(m.serial.u.begin(), m.serial.u.end());
  } else {
    // Every process's locally owned values in place, summed over the processes.
    const DistributedAlgebra& la = *m.parallel;
    std::vector<dealii::types::global_dof_index> indices(la.owned.begin(), la.owned.end());
    std::vector<double> owned(indices.size());
    la.u.extract_subvector_to(indices, owned);
    values.assign(m.dof.n_dofs(), 0.0);
    for (std::size_t k = 0; k < indices.size(); ++k) values[indices[k]] = owned[k];
    m.sum(values);
  }
  if (m.cohesive_law) { // serial only (build refuses a distributed cohesive interface)
    for (const CohesiveState& s : m.cohesive_states)
      values.insert(values.end(), {s.max_opening, s.previous_opening[0], s.previous_opening[1], s.previous_opening[2]});
    values.push_back(m.committed_time);
    values.push_back(m.cohesive_viscous_dissipation);
  }
  if (m.dynamics) { // serial only (build refuses a distributed dynamic step)
    values.insert(values.end(), m.dynamics->v.begin(), m.dynamics->v.end());
    values.insert(values.end(), m.dynamics->a.begin(), m.dynamics->a.end());
    values.push_back(m.committed_time);
    values.push_back(m.cohesive_trapezoid_work);
    if (m.dynamics->damped) values.push_back(m.dynamics->damping_dissipation);
  }
  return values;
}

void FiniteStrainSolver::set_state(const std::vector<double>& values) {
  Impl& m = *m_impl;
  m.history = 0; // the predictor starts over from the restored state
  const std::size_t n_dofs = m.dof.n_dofs();
  const std::size_t damped = m.dynamics && m.dynamics->damped ? 1 : 0;
  const std::size_t expected = n_dofs + (m.cohesive_law ? 4 * m.cohesive_states.size() + 2 : 0) +
                               (m.dynamics ? 2 * n_dofs + 2 + damped : 0);
  if (values.size() != expected)
    throw std::invalid_argument("set_state: " + std::to_string(values.size()) + " values, expected " + std::to_string(expected) +
                                " (" + std::to_string(n_dofs) + " DOFs" +
                                (m.cohesive_law ? " + 4 per cohesive point + 2" : std::string()) +
                                (m.dynamics ? " + velocity and acceleration per DOF + 2 (dynamic step)" : std::string()) +
                                (damped ? " + 1 (Kelvin-Voigt damping)" : "") + ")");
  if (m.cohesive_law) {
    auto it = values.begin() + static_cast<std::ptrdiff_t>(n_dofs);
    for (CohesiveState& s : m.cohesive_states) {
      s.max_opening = *it++;
      for (int c = 0; c < 3; ++c) s.previous_opening[c] = *it++;
    }
    m.committed_time = *it++;
    m.cohesive_viscous_dissipation = *it++;
  }
  if (!m.distributed) {
    std::copy(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(n_dofs), m.serial.u.begin());
    if (m.dynamics) {
      const auto tail = values.end() - static_cast<std::ptrdiff_t>(damped);
      auto it = tail - static_cast<std::ptrdiff_t>(2 * n_dofs + 2);
      std::copy(it, it + static_cast<std::ptrdiff_t>(n_dofs), m.dynamics->v.begin());
      std::copy(it + static_cast<std::ptrdiff_t>(n_dofs), it + static_cast<std::ptrdiff_t>(2 * n_dofs), m.dynamics->a.begin());
      m.committed_time = tail[-2];
      m.cohesive_trapezoid_work = tail[-1];
      if (damped) m.dynamics->damping_dissipation = values.back();
      m.dynamics->step = 0.0;
      (void)m.commit_dynamics(m.serial.u); // u_n = u; the kinetic energy and viscous forces of the restored v
    }
    return;
  }
  DistributedAlgebra& la = *m.parallel;
  std::vector<dealii::types::global_dof_index> indices(la.owned.begin(), la.owned.end());
  std::vector<double> owned(indices.size());
  for (std::size_t k = 0; k < indices.size(); ++k) owned[k] = values[indices[k]];
  la.u.set(indices, owned);
  la.u.compress(dealii::VectorOperation::insert);
}

namespace {

// Pointwise J, von Mises and Cauchy stress components from the displacement gradient.
class StressPostprocessor final : public dealii::DataPostprocessor<3> {
public:
  explicit StressPostprocessor(const std::vector<std::unique_ptr<HyperelasticLaw>>& laws) : m_laws(laws) {}
  void evaluate_vector_field(const dealii::DataPostprocessorInputs::Vector<3>& in,
                             std::vector<dealii::Vector<double>>& out) const override {
    const auto cell = in.template get_cell<3>();
    const HyperelasticLaw& law = *m_laws[cell->material_id()];
    for (std::size_t q = 0; q < in.solution_gradients.size(); ++q) {
      Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
      for (unsigned c = 0; c < 3; ++c)
        for (unsigned d = 0; d < 3; ++d) F(c, d) += in.solution_gradients[q][c][d];
      const double J = F.determinant();
      out[q] = 0.0;
      out[q][0] = J;
      if (!(J > 0.0)) continue;
      const Eigen::Matrix3d sigma = cauchy_stress(F, law.stress_and_tangent(F).first_piola);
      out[q][1] = von_mises(sigma);
      const int idx[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};
      for (int k = 0; k < 6; ++k) out[q][2 + static_cast<unsigned>(k)] = sigma(idx[k][0], idx[k][1]);
    }
  }
  std::vector<std::string> get_names() const override {
    return {"J", "von_mises", "sigma_xx", "sigma_yy", "sigma_zz", "sigma_xy", "sigma_yz", "sigma_xz"};
  }
  dealii::UpdateFlags get_needed_update_flags() const override { return dealii::update_gradients; }

private:
  const std::vector<std::unique_ptr<HyperelasticLaw>>& m_laws;
};

} // namespace

void FiniteStrainSolver::write_fields(const std::filesystem::path& file, const LoadState& load) const {
  const Impl& m = *m_impl;
  m.with_algebra([&](const auto& la) { m.write_fields(la.ghosted(la.u), file, load); });
}

template <class VectorType>
void FiniteStrainSolver::Impl::write_fields(const VectorType& u, const std::filesystem::path& file,
                                            const LoadState& load) const {
  const Impl& m = *this;
  const unsigned cells = m.dof.get_triangulation().n_active_cells(); // distributed: this process's view
  // Contact pressure per cell: the largest ε_N p over the cell's boundary quadrature points.
  dealii::Vector<float> pressure(cells), material(cells);
  if (m.tool) {
    dealii::FEFaceValues<3> ffv(*m.mapping, *m.fe, *m.face_quadrature,
                                dealii::update_values | dealii::update_quadrature_points);
    std::vector<dealii::Tensor<1, 3>> face_u(m.face_quadrature->size());
    for (const auto& cell : m.dof.active_cell_iterators())
      for (const unsigned f : cell->face_indices()) {
        if (!cell->is_locally_owned() || !cell->face(f)->at_boundary()) continue;
        ffv.reinit(cell, f);
        ffv[dealii::FEValuesExtractors::Vector(0)].get_function_values(u, face_u);
        for (unsigned q = 0; q < ffv.n_quadrature_points; ++q) {
          const Eigen::Vector3d x =
              to_eigen(ffv.quadrature_point(q)) + Eigen::Vector3d(face_u[q][0], face_u[q][1], face_u[q][2]);
          const ToolContactPoint c = tool_contact(*m.tool, load.tool_position, x, m.crack_side(cell, f));
          if (c.inside)
            pressure[cell->active_cell_index()] =
                std::max(pressure[cell->active_cell_index()], static_cast<float>(m.penalty * c.penetration));
        }
      }
  }
  for (const auto& cell : m.dof.active_cell_iterators())
    material[cell->active_cell_index()] = static_cast<float>(cell->material_id());
  StressPostprocessor stress(m.laws);
  dealii::DataOut<3> out;
  out.attach_dof_handler(m.dof);
  const std::vector<std::string> names(3, "displacement");
  const std::vector<dealii::DataComponentInterpretation::DataComponentInterpretation> kinds(
      3, dealii::DataComponentInterpretation::component_is_part_of_vector);
  out.add_data_vector(u, names, dealii::DataOut<3>::type_dof_data, kinds);
  out.add_data_vector(u, stress);
  out.add_data_vector(pressure, "contact_pressure", dealii::DataOut<3>::type_cell_data);
  out.add_data_vector(material, "material_id", dealii::DataOut<3>::type_cell_data);
  // Quadratic output cells without write_higher_order_cells (dealii-on-debian12.md, "output").
  // (Distributed: DataOut takes this process's locally owned cells.)
  out.build_patches(*m.mapping, static_cast<unsigned>(m.settings.degree));
  // deal.II reports a failed stream write (a full disk, a file-size limit) as an assertion that
  // names its own source line, not the file: the message gets the file's name here.
  auto write_or_name = [](const std::filesystem::path& target, std::ostream& stream,
                          const std::function<void(std::ostream&)>& body) {
    try {
      body(stream);
      stream.flush();
    } catch (const std::exception& e) {
      // deal.II's message: a rule of dashes, then lines; one line of single spaces here.
      std::string why;
      for (const char c : std::string(e.what())) {
        const char d = c == '\n' || c == '\t' ? ' ' : c;
        if ((d == ' ' || d == '-') && (why.empty() || why.back() == ' ')) continue;
        why.push_back(d);
      }
      throw std::runtime_error("write_fields: writing " + target.string() +
                               " failed (disk full or file-size limit?): " + why.substr(0, 400));
    }
    if (!stream) throw std::runtime_error("write_fields: writing " + target.string() + " failed (disk full or file-size limit?)");
  };
  if (!m.distributed) {
    std::ofstream stream(file);
    if (!stream) throw std::runtime_error("write_fields: cannot open " + file.string());
    write_or_name(file, stream, [&](std::ostream& s) { out.write_vtu(s); });
    return;
  }
  // One .vtu piece per process beside the .pvtu record that lists them (written by rank 0 after
  // every piece is in place), each atomically.
  auto piece = [&](int rank) { return file.stem().string() + "." + std::to_string(rank) + ".vtu"; };
  auto write = [&](const std::filesystem::path& target, const std::function<void(std::ostream&)>& body) {
    write_atomically(target, [&](const std::filesystem::path& tmp) {
      std::ofstream stream(tmp);
      if (!stream) throw std::runtime_error("write_fields: cannot open " + tmp.string());
      write_or_name(tmp, stream, body);
    });
  };
  write(file.parent_path() / piece(rank), [&](std::ostream& stream) { out.write_vtu(stream); });
  MPI_Barrier(parallel->comm);
  if (rank != 0) return;
  std::vector<std::string> pieces;
  for (int r = 0; r < process_count; ++r) pieces.push_back(piece(r));
  write(file, [&](std::ostream& stream) { out.write_pvtu_record(stream, pieces); });
}

} // namespace kerf::reference
