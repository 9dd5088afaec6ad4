// Cost of the spring network (paper 000 §2): one servo sample against N (N^3 cells) for each
// integrator at 1 kHz (clay, and at 8^3 the peer setting for the explicit, implicit and
// linearly implicit integrators) and at 10 kHz — explicit (its
// force loops in single precision; `explicit_double` in double), implicit (converged Newton),
// linear_implicit (one solve per sample) and static; the pieces of a
// sample (one force evaluation: the spring loop against the lattice loops; one pair of triangular
// solves and one factorisation of the implicit system; the explicit integrator's Gershgorin
// bound); a tear storm on clay_tear per integrator; potato_rect_cut's blade press; and the embedding of 10^4 .. 10^6 fine nodes
// (trilinear and Coons). Prefer the CPU-time column: the machine is shared.
// Run: build/experiments/benchmarks/bench_springs --benchmark_min_time=0.3
// (docs/spring-network.md §6 has the numbers and the load they were taken at.)

#include "meshes/blade_shape.hpp"
#include "meshes/box_tet_mesh.hpp"
#include "realtime/haptics/realtime_scheduling.hpp"
#include "realtime/springs/lattice_forces.hpp"
#include "realtime/springs/network_embedding.hpp"
#include "realtime/springs/network_system.hpp"
#include "realtime/springs/symplectic_euler.hpp"
#include "realtime/springs/spring_network_model.hpp"
#include "tests/realtime/springs/model_fixtures.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <random>

namespace {

using namespace kerf;

/// The material and cell size of a benchmark block.
struct BlockMaterial {
  double youngs_modulus, poisson_ratio, density, damping, cell_size;
};
/// The clay scenes (experiments/scenes/clay_pull.toml): E = 0.5 MPa, ν = 0.45, ρ = 1700 kg/m³,
/// η = 10 Pa s, 2.5 mm cells.
constexpr BlockMaterial clay{0.5e6, 0.45, 1700.0, 10.0, 2.5e-3};
/// The peer setting (Vega FEM's 28-spring cubes): 2 mm cells, E = 50 kPa; ν = 0.45 and
/// ρ = 1000 kg/m³ are our choice (the peer setting gives neither), η = 1 Pa s keeps the clay's
/// retardation time τ = η/E = 20 µs.
constexpr BlockMaterial peer{50e3, 0.45, 1000.0, 1.0, 2e-3};

/// A cube of side N cells whose whole volume is the network (cells = N), base bonded, a 2 mm
/// stylus on the top centre moved up and down by 0.1 mm (period 0.2 s), samples of `dt` [s]
/// (1 ms: a 1 kHz servo; 0.1 ms: 10 kHz).
void step_cost(benchmark::State& state, SpringIntegrator integrator, BlockMaterial material, double dt = 1e-3,
               bool single_precision_forces = true) {
  const int n = static_cast<int>(state.range(0));
  const double side = material.cell_size * n;
  const TetMesh mesh = box_tet_mesh({0.0, 0.0, 0.0}, {side, side, side}, n, n, n);
  SpringNetworkSetup s;
  s.youngs_modulus = material.youngs_modulus;
  s.poisson_ratio = material.poisson_ratio;
  s.density = material.density;
  s.damping = material.damping;
  s.cells = n;
  s.integrator = integrator;
  s.single_precision_forces = single_precision_forces;
  s.supports = {{"support", false}};
  s.styluses = {{Eigen::Vector3d(side / 2, side / 2, side + 2e-3), 2e-3}};
  SpringNetworkModel model(mesh, s);
  std::array<ToolState, 1> tool;
  std::array<ForceSample, 1> force;
  long k = 0;
  const long period = std::lround(0.2 / dt);
  for (auto _ : state) {
    const double phase = static_cast<double>(k++ % period) / static_cast<double>(period);
    tool[0].position = s.styluses[0].start + Eigen::Vector3d(0, 0, 1e-4 * std::sin(6.283185307179586 * phase));
    model.step(tool, dt, force);
    benchmark::DoNotOptimize(force[0].force.data());
  }
  state.counters["cells"] = model.network().cell_count();
  state.counters["substeps_or_iterations"] = model.last_substeps();
  state.counters["factorisations_per_step"] = static_cast<double>(model.factorisations()) / static_cast<double>(std::max(k, 1L));
}

/// A full N^3 clay block, nothing fixed: 2.5 mm cells, E = 0.5 MPa, ν = 0.45 with the volume
/// term, ρ = 1700 kg/m³, τ = 20 µs.
SpringNetwork clay_cube(int n) {
  const double h = 2.5e-3;
  NetworkBlock block;
  block.cell_size = h;
  block.cells = Eigen::Vector3i::Constant(n);
  return build_spring_network(block, std::vector<bool>(static_cast<std::size_t>(n * n * n), true),
                              identify_cell_stiffness(0.5e6, 0.45, h, true).stiffness, 1700.0, 2e-5);
}

/// Every node of `net` displaced along z and moving along y by smooth waves (x, v: 3 x capacity).
void displaced_state(const SpringNetwork& net, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v) {
  x = net.rest;
  v = Eigen::Matrix3Xd::Zero(3, net.node_capacity());
  for (int q = 0; q < net.node_count; ++q) x(2, q) += 1e-4 * std::sin(x(0, q) * 400.0), v(1, q) = 1e-3 * std::cos(x(2, q) * 300.0);
}

/// One evaluation of the network's internal forces on a full N^3 block (clay, damped, every node
/// displaced): the per-spring loop over the merged flat arrays (network_forces) against the
/// vectorised lattice loops (LatticeForces) that both integrators use while the network is untorn.
void force_cost(benchmark::State& state, bool lattice) {
  const SpringNetwork net = clay_cube(static_cast<int>(state.range(0)));
  Eigen::Matrix3Xd x, v, f(3, net.node_capacity());
  displaced_state(net, x, v);
  LatticeForces forces(net);
  for (auto _ : state) {
    benchmark::DoNotOptimize(lattice ? forces.evaluate(net, x, v, f) : network_forces(net, x, v, f));
    benchmark::DoNotOptimize(f.data());
  }
  state.counters["springs"] = net.springs.count;
}

/// force_cost after a tear: the full N^3 block cracked through at x = h floor(N/2) (every node of
/// that plane split, the cells on the +x side moved to the copies, N^2 of them), evaluated by
/// the lattice built before the tear (its cells at copies as exceptions) or over the merged
/// flat arrays (network_forces, what the torn network used before).
void torn_force_cost(benchmark::State& state, bool lattice) {
  const int n = static_cast<int>(state.range(0));
  SpringNetwork net = clay_cube(n);
  const double h = net.block.cell_size;
  LatticeForces forces(net);
  const int plane = n / 2;
  const int nodes = net.node_count;
  for (int p = 0; p < nodes && net.node_count < net.node_capacity(); ++p) {
    if (std::abs(net.rest(0, p) - h * plane) > 1e-3 * h) continue;
    const int copy = net.node_count++;
    net.rest.col(copy) = net.rest.col(p);
    net.mass[static_cast<std::size_t>(copy)] = net.mass[static_cast<std::size_t>(p)];
    for (int c = 0; c < net.cell_count(); ++c)
      if (net.cell_index[static_cast<std::size_t>(c)].x() == plane)
        for (int& id : net.cell_nodes[static_cast<std::size_t>(c)]) id = id == p ? copy : id;
  }
  merge_springs(net);
  Eigen::Matrix3Xd x, v, f(3, net.node_capacity());
  displaced_state(net, x, v);
  for (auto _ : state) {
    benchmark::DoNotOptimize(lattice ? forces.evaluate(net, x, v, f) : network_forces(net, x, v, f));
    benchmark::DoNotOptimize(f.data());
  }
  state.counters["exceptions"] = forces.exception_count();
  state.counters["copies"] = net.node_count - nodes;
}

/// A full N^3 clay block (2.5 mm cells, damped) with its base (z = 0) fixed: the implicit step's
/// system without the stylus.
SpringNetwork clay_block(int n) {
  SpringNetwork net = clay_cube(n);
  for (int q = 0; q < net.node_count; ++q)
    if (net.rest(2, q) < 1e-9) net.constraint[static_cast<std::size_t>(q)] = fix_all;
  return net;
}

/// The pieces of one implicit Euler step (1 ms) on a full N^3 clay block: `solve` one pair of
/// triangular solves with the kept factor (single precision, as the implicit integrator reads
/// it; `solve_double` the double-precision factor the quasi-static integrator reads),
/// `factorize` one assembly and numeric factorisation.
void system_cost(benchmark::State& state, bool factorize, NetworkSystem::SolvePrecision precision) {
  const SpringNetwork net = clay_block(static_cast<int>(state.range(0)));
  NetworkSystem system(precision);
  system.rebuild(net);
  const double dt = 1e-3;
  system.assemble(net, net.rest, 1.0 / (dt * dt), 1.0 + net.damping_time / dt);
  if (!system.factorize()) state.SkipWithError("factorisation failed");
  Eigen::VectorXd rhs(system.dof_count()), out(system.dof_count());
  for (int k = 0; k < rhs.size(); ++k) rhs[k] = std::sin(0.37 * k);
  for (auto _ : state) {
    if (factorize) {
      system.assemble(net, net.rest, 1.0 / (dt * dt), 1.0 + net.damping_time / dt);
      benchmark::DoNotOptimize(system.factorize());
    } else {
      system.solve(rhs, out);
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["dofs"] = system.dof_count();
  state.counters["factor_entries"] = system.factor_entries();
}

/// The explicit integrator's per-sample Gershgorin bound on the deformed tangent (the sub-step
/// shortening of SpringNetworkModel) on a full N^3 clay block: over the merged flat spring
/// arrays and per cell (gershgorin_frequency_bound, used after a tear) or on the lattice.
void gershgorin_cost(benchmark::State& state, bool lattice) {
  const SpringNetwork net = clay_block(static_cast<int>(state.range(0)));
  Eigen::Matrix3Xd x = net.rest;
  for (int q = 0; q < net.node_count; ++q) x(2, q) += 1e-4 * std::sin(x(0, q) * 400.0);
  std::vector<double> work(static_cast<std::size_t>(net.node_capacity()));
  LatticeForces forces(net);
  for (auto _ : state) benchmark::DoNotOptimize(lattice ? forces.gershgorin_bound(net, x) : gershgorin_frequency_bound(net, x, work));
}

/// A tear storm: clay_tear (experiments/scenes/clay_tear.toml) on a 24 x 8 x 8 box mesh of the
/// 60 x 20 x 20 mm bar, test::clay_tear_setup (tests/realtime/springs/model_fixtures.hpp; 12 cells along it,
/// h = 5 mm, styluses grasping the nodes within 7.5 mm, pulled apart at 5 mm/s each, tensile
/// limit 50 kPa), 1 ms samples until 50 samples past the rupture (the vertex splits come one per
/// sample, many in consecutive samples). Each sample's CPU time is taken alone; counters: the
/// splits, the samples, the median, p99 and largest sample cost, the largest cost of a sample
/// that split a vertex and of the sample after one (where the implicit and quasi-static
/// integrators refactorise on the kept tear-ready pattern), and the samples over 1 ms.
void tear_storm(benchmark::State& state, SpringIntegrator integrator) {
  const TetMesh mesh = test::clay_tear_mesh();
  SpringNetworkSetup s = test::clay_tear_setup(integrator);
  SpringNetworkModel model(mesh, s);
  std::vector<double> cost, wall, tearing, after;
  cost.reserve(2200);
  wall.reserve(2200);
  int unconverged = 0;
  for (auto _ : state) {
    model.reset();
    cost.clear(), wall.clear(), tearing.clear(), after.clear();
    unconverged = 0;
    std::array<ToolState, 2> tools;
    std::array<ForceSample, 2> forces;
    int rupture = -1;
    bool split_before = false;
    for (int k = 0; k <= 2000 && (rupture < 0 || k <= rupture + 50); ++k) {
      const double d = 5e-6 * k;
      tools[0].position = {0.015 - d, 0.0, 0.022};
      tools[1].position = {0.045 + d, 0.0, 0.022};
      const int tears = model.tears();
      const double t0 = thread_cpu_seconds();
      const auto w0 = std::chrono::steady_clock::now();
      model.step(tools, 1e-3, forces);
      const double c = thread_cpu_seconds() - t0;
      wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count());
      cost.push_back(c);
      unconverged += forces[0].over_budget ? 1 : 0;
      if (split_before) after.push_back(c);
      split_before = model.tears() > tears;
      if (split_before) tearing.push_back(c);
      if (rupture < 0 && forces[0].mode == InteractionMode::rupture) rupture = k;
    }
    state.counters["rupture_sample"] = rupture;
  }
  const auto largest = [](const std::vector<double>& v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); };
  std::vector<double> sorted = cost;
  std::sort(sorted.begin(), sorted.end());
  state.counters["splits"] = model.tears();
  state.counters["samples"] = static_cast<double>(cost.size());
  state.counters["median_us"] = 1e6 * sorted[sorted.size() / 2];
  state.counters["p99_us"] = 1e6 * sorted[std::min(sorted.size() - 1, sorted.size() * 99 / 100)];
  state.counters["max_us"] = 1e6 * sorted.back();
  state.counters["max_splitting_sample_us"] = 1e6 * largest(tearing);
  state.counters["max_sample_after_split_us"] = 1e6 * largest(after);
  state.counters["samples_over_1ms"] = static_cast<double>(std::count_if(cost.begin(), cost.end(), [](double c) { return c > 1e-3; }));
  // Wall time includes waiting for the factor refresh's worker when it is late (a deterministic
  // run adopts each fresh factor a fixed number of samples after asking) and any preemption.
  std::sort(wall.begin(), wall.end());
  state.counters["wall_p99_us"] = 1e6 * wall[std::min(wall.size() - 1, wall.size() * 99 / 100)];
  state.counters["wall_max_us"] = 1e6 * wall.back();
  state.counters["unconverged"] = unconverged;
  state.counters["refreshes"] = static_cast<double>(model.refreshes());
  state.counters["held"] = static_cast<double>(model.held_samples());
  state.counters["stepping_thread_factorisations"] = static_cast<double>(model.factorisations());
}

/// potato_rect_cut's springs run (experiments/scenes/potato_rect_cut.toml, N = 8): a 40 x 20 x
/// 15 mm prism of E = 3 MPa, ν = 0.45, ρ = 1080 kg/m³, η = 1 Pa s bonded at its base, a 30 mm
/// blade edge along y pressed down along −z from 1 mm above the top face at 1 mm/s to 10 mm
/// deep, held 0.5 s and drawn back (22 501 samples at 1 kHz), on a box mesh of the prism (the
/// same network as on the scene's gmsh mesh); implicit Euler, per-sample CPU time of `step`.
void blade_press(benchmark::State& state) {
  const TetMesh mesh = box_tet_mesh({0.0, -0.01, 0.0}, {0.04, 0.01, 0.015}, 16, 8, 6);
  SpringNetworkSetup s;
  s.youngs_modulus = 3e6;
  s.poisson_ratio = 0.45;
  s.density = 1080.0;
  s.damping = 1.0;
  s.integrator = SpringIntegrator::implicit_euler;
  s.supports = {{"support", false}};
  BladeShape blade;
  blade.edge_direction = Eigen::Vector3d::UnitY();
  blade.cutting_direction = -Eigen::Vector3d::UnitZ();
  blade.edge_length = 0.03;
  blade.wedge_angle = 15.0 * M_PI / 180.0;
  blade.thickness = 5e-4;
  const Eigen::Vector3d start(0.02, 0.0, 0.016);
  s.styluses = {{start, 0.0, blade}};
  SpringNetworkModel model(mesh, s);
  // The trajectory: 1 mm approach, 10 mm cut, 0.5 s hold, 11 mm retreat, at 1 mm/s.
  std::vector<double> z;
  for (int k = 0; k <= 11000; ++k) z.push_back(0.016 - 1e-6 * k);
  for (int k = 1; k <= 500; ++k) z.push_back(0.005);
  for (int k = 1; k <= 11000; ++k) z.push_back(0.005 + 1e-6 * k);
  std::vector<double> cost;
  cost.reserve(z.size());
  int unconverged = 0;
  for (auto _ : state) {
    model.reset();
    cost.clear();
    unconverged = 0;
    ToolState tool;
    ForceSample force;
    for (const double zk : z) {
      tool.position = {0.02, 0.0, zk};
      const double t0 = thread_cpu_seconds();
      model.step({&tool, 1}, 1e-3, {&force, 1});
      cost.push_back(thread_cpu_seconds() - t0);
      unconverged += force.over_budget ? 1 : 0;
    }
  }
  std::sort(cost.begin(), cost.end());
  state.counters["samples"] = static_cast<double>(cost.size());
  state.counters["median_us"] = 1e6 * cost[cost.size() / 2];
  state.counters["p99_us"] = 1e6 * cost[cost.size() * 99 / 100];
  state.counters["max_us"] = 1e6 * cost.back();
  state.counters["samples_over_1ms"] = static_cast<double>(std::count_if(cost.begin(), cost.end(), [](double c) { return c > 1e-3; }));
  state.counters["unconverged"] = unconverged;
  state.counters["refreshes"] = static_cast<double>(model.refreshes());
  state.counters["held"] = static_cast<double>(model.held_samples());
  state.counters["stepping_thread_factorisations"] = static_cast<double>(model.factorisations());
}

void embedding_cost(benchmark::State& state, EmbeddingScheme scheme) {
  const int n = 8;
  const double h = 2.5e-3;
  NetworkBlock block;
  block.cell_size = h;
  block.cells = Eigen::Vector3i::Constant(n);
  const SpringNetwork net = build_spring_network(block, std::vector<bool>(n * n * n, true),
                                                 identify_cell_stiffness(0.5e6, 0.45, h, true).stiffness, 1700.0, 0.0);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0.0, n * h);
  Eigen::MatrixXd points(state.range(0), 3);
  for (Eigen::Index p = 0; p < points.rows(); ++p) points.row(p) << u(rng), u(rng), u(rng);
  const NetworkEmbedding embedding(net, points, scheme);
  Eigen::Matrix3Xd x = net.rest;
  for (int q = 0; q < net.node_count; ++q) x(2, q) += 1e-4 * std::sin(x(0, q) * 400.0);
  Eigen::MatrixXd out(points.rows(), 3);
  for (auto _ : state) {
    embedding.apply(net, x, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["nodes_per_s"] = benchmark::Counter(static_cast<double>(points.rows()), benchmark::Counter::kIsIterationInvariantRate);
}

} // namespace

BENCHMARK_CAPTURE(step_cost, explicit, SpringIntegrator::symplectic_euler, clay)->DenseRange(4, 16, 4)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(step_cost, explicit_double, SpringIntegrator::symplectic_euler, clay, 1e-3, false)->DenseRange(4, 16, 4)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(step_cost, implicit, SpringIntegrator::implicit_euler, clay)->DenseRange(4, 16, 4)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(step_cost, linear_implicit, SpringIntegrator::linearly_implicit_euler, clay)->DenseRange(4, 16, 4)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(step_cost, static, SpringIntegrator::quasi_static, clay)->DenseRange(4, 16, 4)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(step_cost, explicit_10kHz, SpringIntegrator::symplectic_euler, clay, 1e-4)->DenseRange(4, 8, 2)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(step_cost, explicit_double_10kHz, SpringIntegrator::symplectic_euler, clay, 1e-4, false)->DenseRange(4, 8, 2)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(step_cost, implicit_10kHz, SpringIntegrator::implicit_euler, clay, 1e-4)->DenseRange(4, 8, 2)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(step_cost, linear_implicit_10kHz, SpringIntegrator::linearly_implicit_euler, clay, 1e-4)->DenseRange(4, 8, 2)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(step_cost, explicit_peer, SpringIntegrator::symplectic_euler, peer)->Arg(8)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(step_cost, implicit_peer, SpringIntegrator::implicit_euler, peer)->Arg(8)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(step_cost, linear_implicit_peer, SpringIntegrator::linearly_implicit_euler, peer)->Arg(8)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(force_cost, springs_loop, false)->DenseRange(4, 16, 4)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(force_cost, lattice, true)->DenseRange(4, 16, 4)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(torn_force_cost, springs_loop, false)->DenseRange(4, 16, 4)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(torn_force_cost, lattice, true)->DenseRange(4, 16, 4)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(system_cost, solve, false, NetworkSystem::SolvePrecision::single_precision)->DenseRange(4, 16, 4)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(system_cost, solve_double, false, NetworkSystem::SolvePrecision::double_precision)->Arg(8)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(system_cost, factorize, true, NetworkSystem::SolvePrecision::single_precision)->DenseRange(4, 16, 4)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(gershgorin_cost, springs_loop, false)->DenseRange(4, 16, 4)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(gershgorin_cost, lattice, true)->DenseRange(4, 16, 4)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(tear_storm, implicit, SpringIntegrator::implicit_euler)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(tear_storm, linear_implicit, SpringIntegrator::linearly_implicit_euler)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(tear_storm, static, SpringIntegrator::quasi_static)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(tear_storm, explicit, SpringIntegrator::symplectic_euler)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(blade_press)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(embedding_cost, trilinear, EmbeddingScheme::trilinear)->RangeMultiplier(10)->Range(10000, 1000000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(embedding_cost, coons, EmbeddingScheme::coons)->RangeMultiplier(10)->Range(10000, 1000000)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
