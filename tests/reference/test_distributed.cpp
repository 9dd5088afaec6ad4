// The distributed reference: `mpirun -np N …` gives the same profile as the serial run to solver
// tolerance. ctest runs this program as `mpirun -np 2`: on every process the same
// problem is solved twice, serially on this process alone (SolverSettings::distribute = false:
// deal.II vectors, UMFPACK) and distributed over both processes (fully distributed
// triangulation, PETSc MPI vectors, MUMPS or CG + GAMG); the second method must reproduce the
// first.
//
// Tolerance: both solves stop when |R_free| <= 1e-9 (|f_int| + |f_ext|) (SolverSettings'
// relative_tolerance); they differ only in round-off (summation order over the processes, another
// factorisation), so they agree to a small multiple of that tolerance. The comparisons use 1e-7
// relative (direct solvers) — far above round-off, far below any modelling difference (a missing
// ghost cell or a contact point counted twice changes the force at the 1e-2 level). CG + GAMG
// stops at a true residual of 1e-10 |b| per Newton step; it is compared at 1e-6.

#include "experiments/reference_run/reference_run.hpp"
#include "formats/scene/scene_reader.hpp"
#include "experiments/study/study_runner.hpp"
#include "formats/trajectory/trajectory.hpp"
#include "meshes/box_tet_mesh.hpp"
#include "meshes/crack_split.hpp"
#include "tests/experiments/run/grasp_on_box.hpp"
#include "reference/finite_strain_solver.hpp"
#include "reference/mpi_processes.hpp"
#include "tests/reference/reference_test_meshes.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

namespace kerf::reference {
namespace {

namespace fs = std::filesystem;

/// A 20 × 20 × 10 mm block bonded at its base, sliding on x = min, pressed by a 4 mm sphere.
FiniteStrainProblem pressed_block() {
  const double L = 0.02, R = 4e-3;
  FiniteStrainProblem p;
  p.mesh = test::named_box(Eigen::Vector3d(-L / 2, -L / 2, 0), Eigen::Vector3d(L / 2, L / 2, L / 2), 4, 4, 2);
  p.materials.push_back({"body", LawKind::neo_hookean, 1e5, 0.3});
  p.displacement_boundaries.push_back({"zmin", DisplacementBoundary::Kind::bonded, {}, {}});
  p.displacement_boundaries.push_back({"xmin", DisplacementBoundary::Kind::sliding, {}, {}});
  RigidToolShape sphere;
  sphere.radius = R;
  p.tool = sphere;
  return p;
}

LoadState press(double depth) { return {0.0, Eigen::Vector3d(0.001, 0.0005, 0.01 + 4e-3 - depth)}; }

/// The block pressed by a thin blade (15° wedge, 0.1 mm thick, a 30 mm edge along y across the
/// whole block) instead of the sphere: the edge pass (blade_edge_contact.hpp) carries the load.
/// Its facets are spread over the processes and its contact must be counted once.
FiniteStrainProblem bladed_block() {
  FiniteStrainProblem p = pressed_block();
  RigidToolShape blade;
  blade.kind = RigidToolShape::Kind::wedge;
  blade.blade.edge_direction = Eigen::Vector3d::UnitY();
  blade.blade.cutting_direction = -Eigen::Vector3d::UnitZ();
  blade.blade.wedge_angle = 15.0 * std::numbers::pi / 180.0;
  blade.blade.thickness = 1e-4;
  blade.blade.edge_length = 0.03;
  p.tool = blade;
  return p;
}

LoadState cut(double depth) { return {0.0, Eigen::Vector3d(0.0007, 0.0, 0.01 - depth)}; }

/// The same block without the tool, bonded at its base and loaded on its top by a dead-load
/// traction of resultant load × (0.5, 0.2, −2) N (a 5% compression with shear): a symmetric
/// positive definite tangent, for CG. (With the sphere the penalty term ε_N p ∂n/∂x makes the
/// tangent indefinite and CG breaks down, serial as well as distributed: contact takes GMRES.)
FiniteStrainProblem loaded_block() {
  FiniteStrainProblem p = pressed_block();
  p.tool.reset();
  p.displacement_boundaries.pop_back(); // no sliding side: the traction has a shear part
  p.tractions.push_back({"zmax", Eigen::Vector3d(0.5, 0.2, -2.0)});
  return p;
}

/// Serial and distributed solves of `problem` under the two loads, compared.
void compare(const FiniteStrainProblem& problem, const std::array<LoadState, 2>& loads, int degree, int refinements,
             LinearSolverChoice linear, double tolerance) {
  ASSERT_EQ(mpi_processes().count, 2) << "run under mpirun -np 2";
  SolverSettings serial_settings;
  serial_settings.degree = degree;
  serial_settings.refinements = refinements;
  serial_settings.distribute = false;
  serial_settings.linear_solver = linear;
  SolverSettings distributed_settings = serial_settings;
  distributed_settings.distribute = true;
  FiniteStrainSolver serial(problem, serial_settings);
  FiniteStrainSolver distributed(problem, distributed_settings);
  ASSERT_EQ(serial.process_count(), 1);
  ASSERT_EQ(distributed.process_count(), 2);
  ASSERT_EQ(distributed.dof_count(), serial.dof_count());
  for (const LoadState& load : loads) {
    const EquilibriumReport s = serial.solve(load);
    const EquilibriumReport d = distributed.solve(load);
    ASSERT_TRUE(s.converged) << s.failure;
    ASSERT_TRUE(d.converged) << d.failure;
    EXPECT_GT(s.support_reaction.norm(), 0.0);
    EXPECT_LT((d.support_reaction - s.support_reaction).norm(), tolerance * s.support_reaction.norm());
    EXPECT_LT((d.traction_resultant - s.traction_resultant).norm(), 1e-12 * (1.0 + s.traction_resultant.norm()));
    if (problem.tool && problem.tool->kind == RigidToolShape::Kind::wedge) {
      EXPECT_EQ(d.edge_contact_points, s.edge_contact_points); // each edge point counted once
      EXPECT_GT(s.edge_contact_points, 0);
      EXPECT_NEAR(d.edge_contact_length, s.edge_contact_length, 1e-12 * s.edge_contact_length);
      EXPECT_NEAR(d.max_edge_line_load, s.max_edge_line_load, tolerance * s.max_edge_line_load);
      EXPECT_LT((d.tool_force - s.tool_force).norm(), tolerance * s.tool_force.norm());
      EXPECT_LT(d.force_imbalance.norm(), tolerance * s.tool_force.norm());
    } else if (problem.tool) {
      EXPECT_EQ(d.contact_points, s.contact_points); // each boundary point counted once
      EXPECT_GT(s.contact_points, 0);
      EXPECT_LT((d.tool_force - s.tool_force).norm(), tolerance * s.tool_force.norm());
      EXPECT_NEAR(d.contact_area, s.contact_area, 1e-12 * s.contact_area);
      EXPECT_NEAR(d.max_contact_pressure, s.max_contact_pressure, tolerance * s.max_contact_pressure);
    }
    // The state, gathered in global DOF order; the numbering differs between the two meshes, so
    // compare it through displacement_at at the nodes of the top face.
    for (double x : {-0.01, -0.005, 0.0, 0.005, 0.01})
      for (double y : {-0.01, 0.0, 0.01}) {
        const Eigen::Vector3d X(x, y, 0.01);
        EXPECT_LT((distributed.displacement_at(X) - serial.displacement_at(X)).norm(),
                  tolerance * serial.max_displacement())
            << "at (" << x << ", " << y << ")";
      }
    EXPECT_NEAR(distributed.max_displacement(), serial.max_displacement(), tolerance * serial.max_displacement());
  }
  // A state gathered and restored (what a checkpoint does) gives back the same forces.
  const std::vector<double> state = distributed.state();
  ASSERT_EQ(state.size(), distributed.dof_count());
  const EquilibriumReport again = distributed.solve(loads[1]);
  distributed.set_state(state);
  EXPECT_EQ(distributed.state(), state);
  const EquilibriumReport restored = distributed.solve(loads[1]);
  ASSERT_TRUE(restored.converged);
  EXPECT_EQ(restored.newton_iterations, 0); // already in equilibrium
  EXPECT_LT((restored.support_reaction - again.support_reaction).norm(), 1e-12 * again.support_reaction.norm());
}

TEST(Distributed, ContactP1MumpsMatchesSerial) {
  compare(pressed_block(), {press(0.3e-3), press(0.6e-3)}, 1, 0, LinearSolverChoice::direct, 1e-7);
}
TEST(Distributed, ContactP2MumpsMatchesSerial) {
  compare(pressed_block(), {press(0.3e-3), press(0.6e-3)}, 2, 0, LinearSolverChoice::direct, 1e-7);
}
TEST(Distributed, BladeEdgeP1MumpsMatchesSerial) {
  compare(bladed_block(), {cut(0.2e-3), cut(0.4e-3)}, 1, 0, LinearSolverChoice::direct, 1e-7);
}
TEST(Distributed, BladeEdgeP2MumpsMatchesSerial) {
  compare(bladed_block(), {cut(0.2e-3), cut(0.4e-3)}, 2, 0, LinearSolverChoice::direct, 1e-7);
}
// Contact makes the tangent indefinite (CG broke down on it): the iterative solver is then GMRES
// + GAMG (tangent_solver.hpp), serially and distributed.
TEST(Distributed, ContactRefinedP1GmresGamgMatchesSerial) {
  compare(pressed_block(), {press(0.3e-3), press(0.6e-3)}, 1, 1, LinearSolverChoice::iterative, 1e-6);
}
TEST(Distributed, TractionRefinedP1CgGamgMatchesSerial) {
  compare(loaded_block(), {LoadState{0.5, Eigen::Vector3d::Zero()}, LoadState{1.0, Eigen::Vector3d::Zero()}}, 1, 1,
          LinearSolverChoice::iterative, 1e-6);
}

/// A bar 4 × 2 × 2 mm (4 × 2 × 2 cells) split across the plane x = 2 mm into a cohesive interface
/// (CohesiveInterface.BarPulledApartDissipatesToughnessTimesArea's bar: σ_c = 0.1 MPa, J_c = 50 J/m²,
/// δ_f = 1 mm), bonded at x = 0 and pulled at x = 4 mm by up to 1.2 mm (past δ_f). The split leaves
/// the two halves joined by the interface alone, so the partition (by face neighbours) puts them
/// on different processes and every face pair straddles the two: the − cells are neither owned
/// nor ghosts of the process that owns the pair. Density 1000 kg/m³ and a Kelvin–Voigt η for the
/// dynamic step.
FiniteStrainProblem cohesive_bar(double damping) {
  const double L = 4e-3, W = 2e-3;
  TetMesh mesh = test::named_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(L, W, W), 4, 2, 2);
  test::add_interior_face_group(mesh, "cut_plane", [&](const Eigen::Vector3d& x) { return std::abs(x.x() - L / 2) < 1e-12; });
  FiniteStrainProblem p;
  p.mesh = split_along_surface(mesh, "cut_plane").mesh;
  p.materials = {{"body", LawKind::neo_hookean, 10e6, 0.0, 1000.0, damping}};
  p.displacement_boundaries.push_back({"xmin", DisplacementBoundary::Kind::bonded, {}, {true, true, true}});
  p.displacement_boundaries.push_back({"xmax", DisplacementBoundary::Kind::prescribed,
                                       [](const Eigen::Vector3d&, double load) { return Eigen::Vector3d(load * 1.2e-3, 0, 0); },
                                       {true, true, true}});
  CohesiveInterfaceSpec spec{"cut_plane+", "cut_plane-", {}};
  spec.law.cohesive_strength = 0.1e6;
  spec.law.fracture_toughness = 50.0;
  p.cohesive = spec;
  return p;
}

/// The bar pulled apart serially and distributed, step by step: the pull, the interface's summary
/// (failed area, stored energy, dissipation) and, dynamic, the kinetic energy, the damping
/// dissipation and the interface's trapezoid work agree to 1e-7 of their scale (both solves stop
/// at |R_free| <= 1e-9 (|f_int| + |f_ext|) and differ in round-off; a pair counted twice or
/// missing, or a history lost across the partition, would show at the 1e-2 level). The history
/// of every interface point, in the whole interface's order, is the same in both states.
void compare_cohesive_bar(int degree, bool dynamic, double damping) {
  ASSERT_EQ(mpi_processes().count, 2) << "run under mpirun -np 2";
  const FiniteStrainProblem problem = cohesive_bar(damping);
  SolverSettings settings;
  settings.degree = degree;
  settings.dynamic = dynamic;
  settings.distribute = false;
  FiniteStrainSolver serial(problem, settings);
  settings.distribute = true;
  FiniteStrainSolver distributed(problem, settings);
  ASSERT_EQ(distributed.process_count(), 2);
  ASSERT_EQ(distributed.cohesive_point_count(), serial.cohesive_point_count());
  const double area = 4e-6, toughness = 50.0, strength = 0.1e6;
  const double F = strength * area, D = toughness * area; // force and energy scales
  const int steps = 16;
  double failed = 0.0;
  for (int k = 1; k <= steps; ++k) {
    const LoadState load{static_cast<double>(k) / steps, Eigen::Vector3d::Zero(), 1e-3 * k};
    const EquilibriumReport s = serial.solve(load);
    const EquilibriumReport d = distributed.solve(load);
    ASSERT_TRUE(s.converged) << "step " << k << ": " << s.failure;
    ASSERT_TRUE(d.converged) << "step " << k << ": " << d.failure;
    EXPECT_LT((d.boundary_reactions[1].force - s.boundary_reactions[1].force).norm(), 1e-7 * F) << "step " << k;
    const CohesiveSummary& a = s.cohesive;
    const CohesiveSummary& b = d.cohesive;
    EXPECT_NEAR(b.failed_area, a.failed_area, 1e-12 * area) << "step " << k;
    EXPECT_NEAR(b.damaged_area, a.damaged_area, 1e-12 * area) << "step " << k;
    EXPECT_NEAR(b.stored_energy, a.stored_energy, 1e-7 * D) << "step " << k;
    EXPECT_NEAR(b.dissipated_energy, a.dissipated_energy, 1e-7 * D) << "step " << k;
    EXPECT_NEAR(b.max_damage, a.max_damage, 1e-7) << "step " << k;
    EXPECT_NEAR(distributed.crack_extent(Eigen::Vector3d::UnitY()), serial.crack_extent(Eigen::Vector3d::UnitY()), 1e-12)
        << "step " << k;
    if (dynamic) {
      EXPECT_NEAR(d.kinetic_energy, s.kinetic_energy, 1e-7 * D) << "step " << k;
      EXPECT_NEAR(d.damping_dissipation, s.damping_dissipation, 1e-7 * D) << "step " << k;
      EXPECT_NEAR(b.trapezoid_work, a.trapezoid_work, 1e-7 * D) << "step " << k;
      EXPECT_NEAR(b.step_time_integration_error, a.step_time_integration_error, 1e-7 * D) << "step " << k;
    }
    failed = a.failed_area;
  }
  EXPECT_NEAR(failed, area, 1e-12 * area); // the pull separated the bar: every point has failed
  // The interface's history (after the DOFs) is in the whole interface's order in both states.
  const std::vector<double> s_state = serial.state(), d_state = distributed.state();
  ASSERT_EQ(d_state.size(), s_state.size());
  const std::size_t n = serial.dof_count(), points = serial.cohesive_point_count();
  for (std::size_t i = n; i < n + 4 * points + 2; ++i) EXPECT_NEAR(d_state[i], s_state[i], 1e-7 * 1e-3) << i;
  // A state gathered and restored (a checkpoint) gives back the same forces with no Newton step.
  const LoadState hold{1.0, Eigen::Vector3d::Zero(), 1e-3 * steps};
  distributed.set_state(d_state);
  EXPECT_EQ(distributed.state(), d_state);
  if (!dynamic) {
    const EquilibriumReport again = distributed.solve(hold);
    ASSERT_TRUE(again.converged);
    EXPECT_EQ(again.newton_iterations, 0);
    EXPECT_NEAR(again.cohesive.dissipated_energy, D, 0.02 * D);
  }
}

TEST(Distributed, CohesiveBarP1MatchesSerial) { compare_cohesive_bar(1, false, 0.0); }
TEST(Distributed, CohesiveBarP2MatchesSerial) { compare_cohesive_bar(2, false, 0.0); }
TEST(Distributed, DynamicCohesiveBarP1MatchesSerial) { compare_cohesive_bar(1, true, 0.0); }
TEST(Distributed, DampedDynamicCohesiveBarP1MatchesSerial) { compare_cohesive_bar(1, true, 20.0); }

TEST(Distributed, FieldsArePiecesPerProcess) {
  SolverSettings settings;
  FiniteStrainSolver solver(pressed_block(), settings);
  ASSERT_TRUE(solver.solve(press(0.3e-3)).converged);
  const fs::path dir = fs::temp_directory_path() / "kerf_test_distributed_fields";
  if (mpi_processes().rank == 0) fs::remove_all(dir);
  wait_for_processes();
  solver.write_fields(dir / "step.pvtu", press(0.3e-3));
  wait_for_processes();
  for (const char* f : {"step.pvtu", "step.0.vtu", "step.1.vtu"}) EXPECT_TRUE(fs::exists(dir / f)) << f;
  std::ifstream record(dir / "step.pvtu");
  const std::string text((std::istreambuf_iterator<char>(record)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("step.1.vtu"), std::string::npos);
  EXPECT_NE(text.find("von_mises"), std::string::npos);
}

/// The scene run (experiments/reference_run/reference_run): clay_pull on a coarse box, tied stylus, 4
/// samples: the profile of 2 processes is the serial one; rank 0 wrote the files.
TEST(Distributed, ClayPullProfileMatchesSerial) {
  const Scene scene = read_scene(fs::path(KERF_SCENES_DIR) / "clay_pull.toml");
  TetMesh mesh = box_tet_mesh(Eigen::Vector3d(0, -0.02, 0), Eigen::Vector3d(0.04, 0.02, 0.02), 4, 4, 2);
  kerf::test::add_grasp_groups_to_box(scene, mesh);
  ReferenceRunSettings settings;
  settings.sample_indices = reference_sample_indices(sample(scene.tools.front().trajectory).samples.size(), 4);
  settings.write_fields = true;
  const fs::path root = fs::temp_directory_path() / "kerf_test_distributed_clay_pull";
  settings.distribute = false;
  const ForceProfile serial = run_reference(scene, mesh, settings, root / ("serial_" + std::to_string(mpi_processes().rank))).profile;
  settings.distribute = true;
  const ForceProfile distributed = run_reference(scene, mesh, settings, root / "distributed").profile;
  ASSERT_EQ(distributed.rows.size(), serial.rows.size());
  for (std::size_t k = 0; k < serial.rows.size(); ++k) {
    EXPECT_EQ(distributed.rows[k].mode, serial.rows[k].mode) << k;
    EXPECT_LE((distributed.rows[k].force - serial.rows[k].force).norm(), 1e-7 * serial.rows.back().force.norm()) << k;
  }
  EXPECT_GT(serial.rows.back().force.norm(), 0.0);
  for (const char* f : {"profile.csv", "manifest.json", "fields.pvd", "fields/step_0003.pvtu", "fields/step_0003.1.vtu"})
    EXPECT_TRUE(fs::exists(root / "distributed" / f)) << f;
  std::ifstream in(root / "distributed" / "manifest.json");
  EXPECT_EQ(nlohmann::json::parse(in).at("solver").at("mpi_processes"), 2);
}

} // namespace
} // namespace kerf::reference
