// The discrete problem (step-44's make_grid, system_setup and make_constraints): the triangulation
// from the TetMesh (volume groups -> material_id, surface groups -> boundary_id), optionally
// refined and distributed over the MPI processes; the vector FE_SimplexP space with MappingFE and
// QGaussSimplex; the reference geometry of every cell; the Dirichlet DOFs of the supports; the
// dead-load tractions; the tool's contact penalty; the sparsity pattern and the linear solver.
// And, at every Newton iteration, the Dirichlet constraints of the remaining increment.

#include "reference/solver/finite_strain_impl.hpp"

#include "reference/material/decoupled_neo_hookean.hpp"
#include "reference/material/neo_hookean.hpp"
#include "reference/material/st_venant_kirchhoff.hpp"
#include "reference/mpi_processes.hpp"

#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria_description.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/sparsity_tools.h>

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace kerf::reference {

namespace {

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

/// The components a sliding support fixes: u·n = 0 with n = ±e_k, so every triangle of its group
/// must have the same axis normal.
std::array<bool, 3> sliding_components(const TetMesh& mesh, const std::string& surface) {
  const SurfaceGroup* group = mesh.find_surface_group(surface);
  int axis = -1;
  for (Eigen::Index f = 0; f < group->triangles.rows(); ++f) {
    const Eigen::Vector3d a = mesh.nodes.row(group->triangles(f, 0));
    const Eigen::Vector3d n = (Eigen::Vector3d(mesh.nodes.row(group->triangles(f, 1))) - a)
                                  .cross(Eigen::Vector3d(mesh.nodes.row(group->triangles(f, 2))) - a)
                                  .normalized();
    Eigen::Index k = 0;
    n.cwiseAbs().maxCoeff(&k);
    if (std::abs(std::abs(n[k]) - 1.0) > 1e-8 || (axis >= 0 && axis != k))
      throw std::invalid_argument("finite strain solver: sliding support '" + surface +
                                  "' must be a plane normal to a coordinate axis");
    axis = static_cast<int>(k);
  }
  return {axis == 0, axis == 1, axis == 2};
}

/// The linear solver SolverSettings::linear_solver asks for on `n_dofs` DOFs, before a factor is
/// predicted. Automatic: direct up to direct_dof_limit DOFs; above it direct while CHOLMOD's
/// analysis of the tangent's pattern (serial, or gathered from the processes) predicts a factor
/// that fits direct_factor_limit (`predict`), else the iterative solver, which falls back to the
/// direct one on a system it cannot solve (tangent_solver.hpp).
struct SolverChoice {
  bool predict = false; // automatic above direct_dof_limit: the predicted factor decides
  TangentSolver::Kind kind = TangentSolver::Kind::direct;
  std::string reason; // why, for the run's record
};

SolverChoice choose_linear_solver(const SolverSettings& settings, std::size_t n_dofs) {
  if (!(settings.direct_factor_limit >= 0.0) || !std::isfinite(settings.direct_factor_limit))
    throw std::invalid_argument("finite strain solver: direct_factor_limit must be a finite number of entries >= 0, got " +
                                std::to_string(settings.direct_factor_limit));
  const bool automatic = settings.linear_solver == LinearSolverChoice::automatic;
  SolverChoice choice;
  choice.predict = automatic && n_dofs > settings.direct_dof_limit && settings.direct_factor_limit > 0.0;
  const bool direct = settings.linear_solver == LinearSolverChoice::direct ||
                      (automatic && (n_dofs <= settings.direct_dof_limit || choice.predict));
  choice.kind = direct ? TangentSolver::Kind::direct : TangentSolver::Kind::iterative;
  const std::string dofs = std::to_string(n_dofs) + " DOFs";
  choice.reason = !automatic ? std::string(direct ? "direct" : "iterative") + ": requested"
                  : direct   ? "direct: " + dofs + " <= direct_dof_limit " + std::to_string(settings.direct_dof_limit)
                             : "iterative: " + dofs + " > direct_dof_limit " +
                                 std::to_string(settings.direct_dof_limit) + " and direct_factor_limit 0";
  return choice;
}

/// The automatic choice above direct_dof_limit, given CHOLMOD's predicted factor: why.
std::string predicted_reason(const SolverSettings& settings, std::size_t n_dofs, double entries) {
  const bool fits = entries <= settings.direct_factor_limit;
  const std::string dofs = std::to_string(n_dofs) + " DOFs";
  char text[200];
  std::snprintf(text, sizeof text, "%s: %s > direct_dof_limit %zu; predicted Cholesky factor %.3g entries %s direct_factor_limit %.3g",
                fits ? "direct" : "iterative", dofs.c_str(), settings.direct_dof_limit, entries, fits ? "<=" : ">",
                settings.direct_factor_limit);
  return std::string(text);
}

} // namespace

void FiniteStrainSolver::Impl::build(const FiniteStrainProblem& problem) {
  const TetMesh& mesh = problem.mesh;
  if (settings.degree != 1 && settings.degree != 2)
    throw std::invalid_argument("finite strain solver: degree must be 1 or 2, got " + std::to_string(settings.degree));
  if (settings.refinements < 0 || settings.refinements > 4)
    throw std::invalid_argument("finite strain solver: refinements must lie in [0, 4], got " +
                                std::to_string(settings.refinements));
  if (mesh.tets.rows() == 0) throw std::invalid_argument("finite strain solver: the mesh has no tetrahedra");
  if (problem.materials.empty()) throw std::invalid_argument("finite strain solver: no material region given");

  make_grid(mesh, make_materials(problem));
  set_boundary_ids(mesh);
  if (settings.refinements > 0) tria.refine_global(static_cast<unsigned>(settings.refinements));
  // `tria` is the whole (refined) mesh on every process, so every process finds the same h_min
  // (the partition's cohesive face matching uses it already).
  h_min = std::numeric_limits<double>::infinity();
  for (const auto& cell : tria.active_cell_iterators())
    for (unsigned l = 0; l < cell->n_lines(); ++l) h_min = std::min(h_min, cell->line(l)->diameter());
  distribute_grid(problem);
  setup_finite_element();
  std::vector<dealii::Point<3>> support = support_points();
  make_dirichlet_dofs(problem, support);
  setup_loads(problem);

  if (settings.dynamic) {
    for (std::size_t r = 0; r < problem.materials.size(); ++r)
      if (!(problem.materials[r].density > 0.0) || !std::isfinite(problem.materials[r].density))
        throw std::invalid_argument("finite strain solver: the dynamic step needs a density > 0 for material region '" +
                                    problem.materials[r].volume_group + "', got " +
                                    std::to_string(problem.materials[r].density) + " kg/m^3");
    build_dynamics();
  }
  if (problem.cohesive) {
    build_cohesive(*problem.cohesive, surface_group(problem.cohesive->plus_surface, "cohesive"),
                   surface_group(problem.cohesive->minus_surface, "cohesive"));
  }
  if (distributed)
    setup_distributed_system(support);
  else
    setup_serial_system(std::move(support));
}

std::vector<int> FiniteStrainSolver::Impl::make_materials(const FiniteStrainProblem& problem) {
  // material_id = index of the first region containing the tet.
  std::vector<int> material(static_cast<std::size_t>(problem.mesh.tets.rows()), -1);
  for (std::size_t r = 0; r < problem.materials.size(); ++r) {
    const VolumeGroup* group = problem.mesh.find_volume_group(problem.materials[r].volume_group);
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
  return material;
}

void FiniteStrainSolver::Impl::make_grid(const TetMesh& mesh, const std::vector<int>& material) {
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
}

void FiniteStrainSolver::Impl::set_boundary_ids(const TetMesh& mesh) {
  // A face may lie in several surface groups (e.g. `xmin` and `boundary`), so the id numbers the
  // distinct sets of groups ("face classes"); 0 = in no group. Refinement passes the id on to the
  // child faces.
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
}

void FiniteStrainSolver::Impl::distribute_grid(const FiniteStrainProblem& problem) {
  // Under mpirun with N > 1 processes: METIS splits the (refined) mesh into N parts and each
  // process keeps its part plus a layer of ghost cells (deal.II's tests/simplex/step-40 way;
  // a fully distributed triangulation cannot be refined afterwards).
  if (settings.distribute) {
    const MpiProcesses processes = mpi_processes();
    distributed = processes.count > 1;
    process_count = processes.count;
    rank = processes.rank;
  }
  if (!distributed) return;
  parallel = std::make_unique<DistributedAlgebra>();
  if (problem.cohesive) {
    // The mesh is split along the crack path (its two faces are copies): on the cells' face graph
    // alone it is two bodies, and METIS cuts it there — where the crack-path grading puts most of
    // the nodes, so that each process's rows reached over half of the other's DOFs through the
    // cohesive pairs (docs/reference.md, "Strong scaling of the cut"). Joined by the pairs, the
    // graph is the body the interface holds together, and the cut falls elsewhere.
    dealii::DynamicSparsityPattern graph;
    dealii::GridTools::get_face_connectivity_of_cells(tria, graph);
    for (const auto& [plus, minus] : cohesive_cell_pairs(*problem.cohesive, surface_group(problem.cohesive->plus_surface, "cohesive"),
                                                         surface_group(problem.cohesive->minus_surface, "cohesive"))) {
      graph.add(plus, minus);
      graph.add(minus, plus);
    }
    dealii::SparsityPattern cell_graph;
    cell_graph.copy_from(graph);
    dealii::GridTools::partition_triangulation(static_cast<unsigned>(process_count), cell_graph, tria);
  } else {
    dealii::GridTools::partition_triangulation(static_cast<unsigned>(process_count), tria);
  }
  const auto description =
      dealii::TriangulationDescription::Utilities::create_description_from_triangulation(tria, parallel->comm);
  distributed_tria = std::make_unique<dealii::parallel::fullydistributed::Triangulation<3>>(parallel->comm);
  distributed_tria->create_triangulation(description);
}

int FiniteStrainSolver::Impl::surface_group(const std::string& name, const char* what) const {
  for (std::size_t g = 0; g < surface_names.size(); ++g)
    if (surface_names[g] == name) return static_cast<int>(g);
  throw std::invalid_argument(std::string("finite strain solver: ") + what + " surface '" + name +
                              "' is not a surface group of the mesh");
}

void FiniteStrainSolver::Impl::setup_finite_element() {
  fe = std::make_unique<dealii::FESystem<3>>(dealii::FE_SimplexP<3>(static_cast<unsigned>(settings.degree)), 3);
  mapping = std::make_unique<dealii::MappingFE<3>>(dealii::FE_SimplexP<3>(1));
  // The cell integrals of the stresses and the tangent. P1: the gradients are constant on a straight
  // cell, so one point is exact (build_cell_geometry keeps one). P2: the gradients are linear and the
  // linear-elastic tangent's integrand Grad N_a · ℂ Grad N_b is of degree 2; the symmetric 8-point
  // rule of Witherden & Vincent (2015), exact to degree 3 with positive weights, integrates it with
  // one degree to spare for the finite-strain integrand — the class of FEBio's default tet10 rule
  // (8 Gauss points). Against the 14-point rule (degree 5) Cook's tip moves by 5e-6 of itself on
  // the 8 mm mesh and 7e-7 on the 1 mm mesh, towards FEBio's (docs/reference.md, "Quadrature of
  // quadratic tetrahedra"), for 8/14 of the work per cell.
  if (settings.degree == 2)
    cell_quadrature = std::make_unique<dealii::QWitherdenVincentSimplex<3>>(2);
  else
    cell_quadrature = std::make_unique<dealii::QGaussSimplex<3>>(static_cast<unsigned>(settings.degree + 1));
  // m_ij = ∫ ρ N_i N_j dV is of degree 2·degree: QGaussSimplex(degree + 1) is exact for it.
  mass_quadrature = std::make_unique<dealii::QGaussSimplex<3>>(static_cast<unsigned>(settings.degree + 1));
  face_quadrature = std::make_unique<dealii::QGaussSimplex<2>>(static_cast<unsigned>(settings.degree + 1));
  if (distributed)
    dof.reinit(*distributed_tria);
  else
    dof.reinit(tria);
  dof.distribute_dofs(*fe);
  build_cell_geometry();
}

std::vector<dealii::Point<3>> FiniteStrainSolver::Impl::support_points() {
  // The node-major layout (3k + component) the AMG's block size relies on.
  std::vector<dealii::Point<3>> support(dof.n_dofs());
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
  // DOF 3k + c holds coordinate c of node k's reference position (the contact search's bound).
  reference_coordinate.resize(dof.n_dofs());
  for (std::size_t i = 0; i < support.size(); ++i) reference_coordinate[i] = support[i][static_cast<unsigned>(i % 3)];
  return support;
}

void FiniteStrainSolver::Impl::make_dirichlet_dofs(const FiniteStrainProblem& problem,
                                                   const std::vector<dealii::Point<3>>& support) {
  // Bonded and prescribed supports first (they win over sliding ones on shared edges).
  boundaries = problem.displacement_boundaries;
  std::map<dealii::types::global_dof_index, DirichletDof> fixed;
  std::vector<dealii::types::global_dof_index> local(fe->n_dofs_per_face());
  for (int pass = 0; pass < 2; ++pass)
    for (std::size_t b = 0; b < boundaries.size(); ++b) {
      const DisplacementBoundary& bc = boundaries[b];
      const bool sliding = bc.kind == DisplacementBoundary::Kind::sliding;
      if (sliding != (pass == 1)) continue;
      const int group = surface_group(bc.surface, "support");
      std::array<bool, 3> comps{true, true, true};
      if (bc.kind == DisplacementBoundary::Kind::prescribed) {
        if (!bc.displacement)
          throw std::invalid_argument("finite strain solver: prescribed surface '" + bc.surface + "' has no displacement");
        comps = bc.components;
      }
      if (sliding) comps = sliding_components(problem.mesh, bc.surface);
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
}

void FiniteStrainSolver::Impl::setup_loads(const FiniteStrainProblem& problem) {
  // Dead-load tractions: the total force spread uniformly over the surface's area.
  for (const TractionBoundary& t : problem.tractions) {
    const int group = surface_group(t.surface, "traction");
    const double area = surface_area(group);
    if (!(area > 0.0)) throw std::invalid_argument("finite strain solver: traction surface '" + t.surface + "' has no area");
    tractions.emplace_back(group, t.total_force / area);
  }
  build_foundations(problem);

  tool = problem.tool;
  if (tool) {
    validate(*tool);
    penalty = settings.contact_penalty;
    // ε_N = 50 E_max / h_min: a pressure E costs a penetration of h_min / 50.
    if (penalty <= 0.0) penalty = 50.0 * *std::max_element(youngs.begin(), youngs.end()) / h_min;
    if (tool->kind == RigidToolShape::Kind::wedge) build_blade_edge();
  }
}

void FiniteStrainSolver::Impl::setup_serial_system(std::vector<dealii::Point<3>> support) {
  const SolverChoice choice = choose_linear_solver(settings, dof.n_dofs());
  // Contact and a softening cohesive interface make the tangent indefinite: GMRES instead of CG.
  const bool spd = !tool && !cohesive_law;
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
  cell_scatter.build(dof, serial.pattern);
  serial.u.reinit(dof.n_dofs());
  serial.u_previous.reinit(dof.n_dofs());
  serial.free_mask.reinit(dof.n_dofs());
  serial.free_mask = 1.0;
  for (const auto& d : dirichlet) serial.free_mask[d.index] = 0.0;
  // Automatic above direct_dof_limit: direct while CHOLMOD's analysis predicts a Cholesky
  // factor of at most direct_factor_limit entries (memory), else the iterative solver.
  if (choice.predict) {
    auto candidate = std::make_unique<TangentSolver>(choice.kind, support, settings.iterative_tolerance, false, spd);
    const double entries = candidate->cholesky_factor_entries(serial.pattern);
    if (entries <= settings.direct_factor_limit) {
      linear = std::move(candidate); // keeps the analysis
    } else {
      linear = std::make_unique<TangentSolver>(TangentSolver::Kind::iterative, std::move(support),
                                               settings.iterative_tolerance, false, spd);
      linear->fall_back_to_direct_on_failure(true);
    }
    linear->set_choice_reason(predicted_reason(settings, dof.n_dofs(), entries));
    return;
  }
  linear = std::make_unique<TangentSolver>(choice.kind, std::move(support), settings.iterative_tolerance, false, spd);
  linear->set_choice_reason(choice.reason);
}

void FiniteStrainSolver::Impl::setup_distributed_system(const std::vector<dealii::Point<3>>& support) {
  const SolverChoice choice = choose_linear_solver(settings, dof.n_dofs());
  const bool spd = !tool && !cohesive_law; // as setup_serial_system
  // This process's rows (locally owned DOFs) and the DOFs its cells touch (locally relevant:
  // owned and ghost cells); the sparsity rows other processes contribute to are sent to their
  // owners. The cohesive pairs of this process couple the DOFs of their two cells, of which the −
  // one may be another process's: those DOFs are locally relevant too (their values imported with
  // the ghosts, their Dirichlet constraints known here, their rows sent to their owners).
  DistributedAlgebra& la = *parallel;
  la.owned = dof.locally_owned_dofs();
  dealii::DoFTools::extract_locally_relevant_dofs(dof, la.relevant);
  la.relevant.add_indices(cohesive_dofs.begin(), cohesive_dofs.end());
  la.relevant.compress();
  if (!la.owned.is_contiguous())
    throw std::logic_error("finite strain solver: the locally owned DOFs are not one contiguous range");
  complete_distributed_dirichlet();
  dealii::AffineConstraints<double> structure(la.relevant);
  for (const auto& d : dirichlet) structure.add_line(d.index);
  structure.close();
  dealii::DynamicSparsityPattern dsp(la.relevant);
  dealii::DoFTools::make_sparsity_pattern(dof, dsp, structure, false);
  for (const CohesivePair& pair : cohesive_pairs)
    for (const auto i : pair.dofs)
      for (const auto j : pair.dofs)
        if (!structure.is_constrained(i) && !structure.is_constrained(j)) dsp.add(i, j);
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
  if (choice.predict) {
    // As the serial choice: CHOLMOD's analysis of the whole pattern, gathered to rank 0.
    const double entries = distributed_cholesky_factor_entries(dsp, la.owned, la.comm, settings.direct_factor_limit);
    const bool fits = entries <= settings.direct_factor_limit;
    linear = std::make_unique<TangentSolver>(fits ? TangentSolver::Kind::direct : TangentSolver::Kind::iterative,
                                             std::move(owned_support), settings.iterative_tolerance, true, spd);
    linear->fall_back_to_direct_on_failure(!fits);
    linear->set_choice_reason(predicted_reason(settings, dof.n_dofs(), entries));
    return;
  }
  linear = std::make_unique<TangentSolver>(choice.kind, std::move(owned_support), settings.iterative_tolerance, true, spd);
  linear->set_choice_reason(choice.reason);
}

void FiniteStrainSolver::Impl::complete_distributed_dirichlet() {
  // Every process's Dirichlet DOFs (those of its own and ghost cells' faces), gathered: a DOF on
  // faces of several supports is assigned as on one process, to the first bonded or prescribed
  // support in the problem's order, else the first sliding one (build). Kept: those among
  // la.relevant. Per DOF: index, component, support, position (6 numbers).
  std::vector<double> mine;
  for (const DirichletDof& d : dirichlet)
    mine.insert(mine.end(), {static_cast<double>(d.index), static_cast<double>(d.component), static_cast<double>(d.boundary),
                             d.X.x(), d.X.y(), d.X.z()});
  auto rank_of = [&](int b) { // the order of build's two passes
    const bool sliding = boundaries[static_cast<std::size_t>(b)].kind == DisplacementBoundary::Kind::sliding;
    return (sliding ? 1 : 0) * static_cast<long>(boundaries.size()) + b;
  };
  std::map<dealii::types::global_dof_index, DirichletDof> all;
  for (const std::vector<double>& from : dealii::Utilities::MPI::all_gather(parallel->comm, mine))
    for (std::size_t k = 0; k + 6 <= from.size(); k += 6) {
      const DirichletDof d{static_cast<dealii::types::global_dof_index>(from[k]), static_cast<unsigned>(from[k + 1]),
                           static_cast<int>(from[k + 2]), Eigen::Vector3d(from[k + 3], from[k + 4], from[k + 5])};
      if (!parallel->relevant.is_element(d.index)) continue;
      const auto [it, inserted] = all.emplace(d.index, d);
      if (!inserted && rank_of(d.boundary) < rank_of(it->second.boundary)) it->second = d;
    }
  dirichlet.clear();
  for (const auto& [index, d] : all) dirichlet.push_back(d);
}

double FiniteStrainSolver::Impl::surface_area(int group) const {
  double area = 0.0;
  dealii::FEFaceValues<3> fv(*mapping, *fe, *face_quadrature, dealii::update_JxW_values);
  for (const auto& cell : dof.active_cell_iterators())
    for (const unsigned f : cell->face_indices())
      if (cell->is_locally_owned() && cell->face(f)->at_boundary() && in_group(cell->face(f)->boundary_id(), group)) {
        fv.reinit(cell, f);
        for (unsigned q = 0; q < fv.n_quadrature_points; ++q) area += fv.JxW(q);
      }
  return sum(area);
}

void FiniteStrainSolver::Impl::build_cell_geometry() {
  const dealii::FE_SimplexP<3> scalar(static_cast<unsigned>(settings.degree));
  CellGeometry& g = geometry;
  g.nodes = scalar.n_dofs_per_cell();
  const unsigned points = cell_quadrature->size();
  // Linear tetrahedra on straight (affine) cells have constant shape gradients, so F, the stress
  // and the tangent are the same at every quadrature point: the cell integrals are the integrand
  // at one point times the cell's volume Σ_q JxW_q. One point is kept per cell then (checked:
  // every point's gradients equal the first's to round-off, else all points are kept).
  g.points = settings.degree == 1 ? 1 : points;
  const unsigned n = fe->n_dofs_per_cell();
  g.node_of_dof.resize(n);
  for (unsigned i = 0; i < n; ++i) g.node_of_dof[i] = fe->system_to_component_index(i).second;
  const std::size_t cells = dof.get_triangulation().n_active_cells();
  dealii::FEValues<3> fv(*mapping, scalar, *cell_quadrature, dealii::update_gradients | dealii::update_JxW_values);
  for (int attempt = 0; attempt < 2; ++attempt) {
    g.gradients.assign(cells * g.points * g.nodes * 3, 0.0);
    g.JxW.assign(cells * g.points, 0.0);
    bool constant = true;
    for (const auto& cell : dof.get_triangulation().active_cell_iterators()) {
      if (!cell->is_locally_owned()) continue;
      fv.reinit(cell);
      const std::size_t c = cell->active_cell_index();
      for (unsigned q = 0; q < points; ++q) {
        const unsigned k = g.points == 1 ? 0 : q;
        g.JxW[c * g.points + k] += fv.JxW(q);
        for (unsigned a = 0; a < g.nodes; ++a) {
          const dealii::Tensor<1, 3> grad = fv.shape_grad(a, q);
          if (g.points == 1 && (grad - fv.shape_grad(a, 0)).norm() > 1e-12 * fv.shape_grad(a, 0).norm()) constant = false;
          if (q == k)
            for (unsigned d = 0; d < 3; ++d) g.gradients[((c * g.points + k) * g.nodes + a) * 3 + d] = grad[d];
        }
      }
    }
    if (constant || g.points == points) return;
    g.points = points; // curved or non-affine cells: every quadrature point
  }
}

template <class Algebra>
double FiniteStrainSolver::Impl::dirichlet_constraints(const Algebra& la, const typename Algebra::VectorType& u,
                                                      const LoadState& load,
                                                      dealii::AffineConstraints<double>& c) const {
  c.clear();
  la.prepare(c);
  const dealii::Vector<double>& u_relevant = la.readable(u);
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

// For the two algebras (algebra.hpp); Newton calls them (newton_raphson.cpp).
template double FiniteStrainSolver::Impl::dirichlet_constraints<SerialAlgebra>(const SerialAlgebra&, const SerialAlgebra::VectorType&,
                                                                       const LoadState&,
                                                                       dealii::AffineConstraints<double>&) const;
template double FiniteStrainSolver::Impl::dirichlet_constraints<DistributedAlgebra>(const DistributedAlgebra&, const DistributedAlgebra::VectorType&,
                                                                       const LoadState&,
                                                                       dealii::AffineConstraints<double>&) const;

} // namespace kerf::reference
