// Cost of one FractureCuttingModel::step on potato_wedge_cut (paper 001 §5.1 triangular prism),
// with the contact length l(x) measured on the gmsh mesh at every step, along the scene's own
// trajectory (approach, cut 12 mm, hold, retreat) — so every mode is in the mix. The mesh is
// refined by the benchmark argument (element size in micrometres) to show how the cost grows
// with the mesh (the AABB tree keeps it near the number of tetrahedra the edge crosses).
//
//   ./build/experiments/benchmarks/bench_fracture_step

#include "experiments/benchmarks/model_on_scene.hpp"
#include "realtime/fracture/contact_length.hpp"

#include <benchmark/benchmark.h>

using namespace kerf;

namespace {

void step_along_trajectory(benchmark::State& state, const std::string& scene) {
  bench::ModelOnScene f = bench::model_on_scene("fracture", scene, static_cast<double>(state.range(0)) * 1e-6); // µm
  bench::step_along_trajectory(state, f);
  state.counters["tets"] = static_cast<double>(f.mesh.tets.rows());
}

void BM_FractureStep_PotatoWedge(benchmark::State& state) { step_along_trajectory(state, "potato_wedge_cut"); }
void BM_FractureStep_PotatoRect(benchmark::State& state) { step_along_trajectory(state, "potato_rect_cut"); }

/// The contact-length query alone, with the edge 6 mm below the wedge's apex.
void BM_ContactLength_PotatoWedge(benchmark::State& state) {
  bench::ModelOnScene f = bench::model_on_scene("fracture", "potato_wedge_cut", static_cast<double>(state.range(0)) * 1e-6);
  SegmentLengthInBody length(f.mesh);
  const BladeShape& blade = f.scene.tools.front().blade;
  const Eigen::Vector3d mid(0.025, 0.0, 0.011), half = 0.5 * blade.edge_length * blade.edge_direction;
  for (auto _ : state) benchmark::DoNotOptimize(length.length(mid - half, mid + half));
  state.counters["tets"] = static_cast<double>(f.mesh.tets.rows());
}

} // namespace

BENCHMARK(BM_FractureStep_PotatoWedge)->Arg(2000)->Arg(1000)->Arg(500)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FractureStep_PotatoRect)->Arg(2000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ContactLength_PotatoWedge)->Arg(2000)->Arg(1000)->Arg(500)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
