// Cost of one VoxelSurfaceCuttingModel::step (paper 002) on the sponge scenes, along each
// scene's own trajectory (approach, plunge or diagonal cut, cut along x, retreat), so contact
// detection, grid placement and re-centring, depth and cutting advances and the no-contact steps
// are all in the mix. The argument is the scene's element size in micrometres: a finer mesh
// means more polygon triangles around the contact for the grid's ray casts. Also the grid
// placement alone (the costliest single operation of a step). The potato scenes cut with a blade,
// which the voxel model (a cutting stick) does not represent: `kerf run` refuses them.
//
//   ./build/experiments/benchmarks/bench_voxel_step

#include "experiments/benchmarks/model_on_scene.hpp"
#include "meshes/surface_mesh.hpp"
#include "realtime/voxel/local_voxel_grid.hpp"

#include <benchmark/benchmark.h>

using namespace kerf;

namespace {

void step_along_trajectory(benchmark::State& state, const std::string& scene) {
  bench::ModelOnScene f = bench::model_on_scene("voxel", scene, static_cast<double>(state.range(0)) * 1e-6); // µm
  bench::step_along_trajectory(state, f);
  state.counters["surface_triangles"] = static_cast<double>(boundary_surface(f.mesh).triangles.rows());
}

void BM_VoxelStep_SpongeConstant(benchmark::State& state) { step_along_trajectory(state, "sponge_cut_constant"); }
void BM_VoxelStep_SpongeProportional(benchmark::State& state) { step_along_trajectory(state, "sponge_cut_proportional"); }

/// Placing the 10 x 20 x 20 grid on the sponge's top face (the ray cast of all 400 columns).
void BM_VoxelGridPlacement_Sponge(benchmark::State& state) {
  bench::ModelOnScene f = bench::model_on_scene("voxel", "sponge_cut_constant", static_cast<double>(state.range(0)) * 1e-6);
  const SurfaceMesh surface = boundary_surface(f.mesh);
  std::vector<Eigen::AlignedBox3d> boxes(static_cast<std::size_t>(surface.triangles.rows()));
  for (Eigen::Index t = 0; t < surface.triangles.rows(); ++t)
    for (int c = 0; c < 3; ++c) boxes[static_cast<std::size_t>(t)].extend(surface.vertices.row(surface.triangles(t, c)).transpose());
  const AabbTree tree(boxes);
  LocalVoxelGrid grid(f.scene.voxel->grid, f.scene.voxel->advance_length, 8192);
  VoxelFrame frame;
  frame.origin = {0.5e-3, 0.0, 1e-3};
  frame.depth_axis = -Eigen::Vector3d::UnitZ();
  frame.u_axis = Eigen::Vector3d::UnitX();
  frame.v_axis = frame.depth_axis.cross(frame.u_axis);
  for (auto _ : state) {
    grid.place(frame, -10, -10, -5, surface.vertices, surface.triangles, tree, 0.0, false);
    benchmark::DoNotOptimize(grid.surface_depth(10, 10));
  }
  state.counters["surface_triangles"] = static_cast<double>(surface.triangles.rows());
}

} // namespace

BENCHMARK(BM_VoxelStep_SpongeConstant)->Arg(100)->Arg(50)->Arg(25)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_VoxelStep_SpongeProportional)->Arg(100)->Arg(50)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_VoxelGridPlacement_Sponge)->Arg(100)->Arg(50)->Arg(25)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
