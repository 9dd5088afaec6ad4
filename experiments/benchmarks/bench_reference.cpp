// Costs of the finite-strain reference (docs/reference.md): time per Newton iteration and per load step
// against the number of DOFs (P1 and P2 at three sizes with equal DOF counts, UMFPACK against
// PETSc CG + GAMG), peak memory; Cook's membrane in 10 load steps at ~4.6k and ~16.7k DOFs (to
// compare with FEBio 4.11 on the same problem: experiments/benchmarks/febio_cook.sh); the deformation phase of
// potato_rect_cut at the scene's default resolution (the blade pressed 1.5 mm in).
//
//   ./build/experiments/benchmarks/bench_reference
//   ./build/experiments/benchmarks/bench_reference --benchmark_filter=cook
//
// Counters: dofs; newton_its per load step; s_per_newton = load-step time / Newton iterations;
// assembly_s and linear_s per load step; peak_rss_MB = the process's maximum resident set so far
// (getrusage; it only grows, so read it per benchmark in the order they run).

#include "experiments/reference_run/reference_run.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"
#include "formats/trajectory/trajectory.hpp"
#include "meshes/box_tet_mesh.hpp"
#include "reference/finite_strain_solver.hpp"
#include "tests/reference/reference_test_meshes.hpp"

#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <chrono>
#include <filesystem>
#include <stdexcept>
#include <unistd.h>

using namespace kerf;
using namespace kerf::reference;

namespace {

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0; // ru_maxrss is in kB on Linux
}

// A 10 mm cube of n³ cells × 6 tetrahedra, neo-Hookean (E = 1 MPa, ν = 0.3), base bonded, top
// pushed down 1 mm (10% compression) in one load step from the undeformed state.
void load_step(benchmark::State& state) {
  const int degree = static_cast<int>(state.range(0));
  const int n = static_cast<int>(state.range(1));
  const bool iterative = state.range(2) != 0;
  FiniteStrainProblem p;
  p.mesh = box_tet_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(0.01), n, n, n);
  p.materials.push_back({"body", LawKind::neo_hookean, 1e6, 0.3});
  p.displacement_boundaries.push_back({"support", DisplacementBoundary::Kind::bonded, {}, {}});
  DisplacementBoundary top;
  top.surface = "top";
  top.kind = DisplacementBoundary::Kind::prescribed;
  top.displacement = [](const Eigen::Vector3d&, double load) -> Eigen::Vector3d { return {0.0, 0.0, -1e-3 * load}; };
  top.components = {false, false, true};
  p.displacement_boundaries.push_back(top);
  SolverSettings settings;
  settings.degree = degree;
  settings.linear_solver = iterative ? LinearSolverChoice::iterative : LinearSolverChoice::direct;
  FiniteStrainSolver solver(p, settings);
  const std::vector<double> zero(solver.dof_count(), 0.0);
  double its = 0.0, assembly = 0.0, linear = 0.0, seconds = 0.0;
  for (auto _ : state) {
    solver.set_state(zero);
    const auto begin = std::chrono::steady_clock::now();
    const EquilibriumReport r = solver.solve({1.0, Eigen::Vector3d::Zero()});
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    if (!r.converged) throw std::runtime_error("bench_reference: load step did not converge: " + r.failure);
    its += r.newton_iterations;
    assembly += r.assembly_seconds;
    linear += r.linear_solve_seconds;
  }
  const auto runs = static_cast<double>(state.iterations());
  state.counters["dofs"] = static_cast<double>(solver.dof_count());
  state.counters["newton_its"] = its / runs;
  state.counters["s_per_newton"] = seconds / its;
  state.counters["assembly_s"] = assembly / runs;
  state.counters["linear_s"] = linear / runs;
  state.counters["peak_rss_MB"] = peak_rss_mb();
  state.SetLabel(solver.linear_solver_name());
}
// (degree, cells per side, iterative): P1 at n = 8, 16, 24 and P2 at n = 4, 8, 12 have equal DOF
// counts (2187, 14739, 46875).
BENCHMARK(load_step)
    ->ArgsProduct({{1}, {8, 16, 24}, {0, 1}})
    ->ArgsProduct({{2}, {4, 8, 12}, {0, 1}})
    ->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()
    ->Iterations(2);

// Cook's membrane (tests/reference/test_cook_membrane.cpp): P2, 10 load steps; n = 11 gives 4761
// DOFs (FEBio: 4.6k DOFs, 0.72 s, 14.731 mm), n = 21 gives 16641 (FEBio: 16.7k, ~6 s, 14.737 mm).
void cook(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  double tip = 0.0, its = 0.0;
  std::size_t dofs = 0;
  for (auto _ : state) {
    const FiniteStrainProblem p = test::cook_membrane_problem(test::cook_membrane(n));
    SolverSettings settings;
    settings.degree = 2;
    FiniteStrainSolver solver(p, settings);
    dofs = solver.dof_count();
    for (int step = 1; step <= 10; ++step) {
      const EquilibriumReport r = solver.solve({step / 10.0, Eigen::Vector3d::Zero()});
      if (!r.converged) throw std::runtime_error("bench_reference: Cook step did not converge: " + r.failure);
      its += r.newton_iterations;
    }
    tip = solver.displacement_at(Eigen::Vector3d(48e-3, 52e-3, 0.5e-3)).y();
  }
  state.counters["dofs"] = static_cast<double>(dofs);
  state.counters["tip_mm"] = tip * 1e3;
  state.counters["newton_its"] = its / static_cast<double>(state.iterations());
  state.counters["peak_rss_MB"] = peak_rss_mb();
}
BENCHMARK(cook)->Arg(4)->Arg(8)->Arg(11)->Arg(12)->Arg(21)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->Iterations(1);

// potato_rect_cut's deformation phase at the scene's default mesh (2 mm, P1): the samples
// t = 0, 0.25, … 2.5 s (blade from 1 mm above the top face to 1.5 mm deep, the scene's rupture
// deflection estimate), meshing included.
void potato_deformation_phase(benchmark::State& state) {
  namespace fs = std::filesystem;
  const Scene scene = read_scene(fs::path(KERF_SOURCE_DIR) / "experiments/scenes/potato_rect_cut.toml");
  ReferenceRunSettings settings;
  for (std::size_t k = 0; k <= 2500; k += 250) settings.sample_indices.push_back(k); // 1 kHz samples
  settings.write_fields = false;
  const fs::path dir = fs::temp_directory_path() / ("kerf_bench_reference_" + std::to_string(::getpid()));
  double peak = 0.0;
  for (auto _ : state) {
    const TetMesh mesh = scene_mesh(scene);
    const ForceProfile profile = run_reference(scene, mesh, settings, dir).profile;
    peak = profile.rows.back().force.norm();
  }
  fs::remove_all(dir);
  state.counters["force_at_1.5mm_N"] = peak;
  state.counters["peak_rss_MB"] = peak_rss_mb();
}
BENCHMARK(potato_deformation_phase)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->Iterations(1);

} // namespace

BENCHMARK_MAIN();
