// Cost of one FractureCuttingModel::step on potato_wedge_cut (paper 001 §5.1 triangular prism),
// with the contact length l(x) measured on the gmsh mesh at every step, along the scene's own
// trajectory (approach, cut 12 mm, hold, retreat) — so every mode is in the mix. The mesh is
// refined by the benchmark argument (element size in micrometres) to show how the cost grows
// with the mesh (the AABB tree keeps it near the number of tetrahedra the edge crosses).
//
//   ./build/experiments/benchmarks/bench_fracture_step

#include "experiments/models/model_catalogue.hpp"
#include "experiments/models/run_model.hpp"
#include "experiments/scene/scene_mesh.hpp"
#include "experiments/scene/scene_reader.hpp"
#include "realtime/fracture/contact_length.hpp"

#include <benchmark/benchmark.h>

using namespace kerf;

namespace {

struct Fixture {
  Scene scene;
  TetMesh mesh;
  BuiltModel model;
  std::vector<ToolState> samples;
};

Fixture make_fixture(const std::string& name, double element_size) {
  Fixture f;
  f.scene = read_scene(std::filesystem::path(KERF_SOURCE_DIR) / "experiments/scenes" / (name + ".toml"));
  if (element_size > 0.0) f.scene.geometry.element_size = element_size;
  f.mesh = scene_mesh(f.scene);
  f.model = make_model("fracture", f.scene, f.mesh);
  f.samples = sample(f.scene.tools.front().trajectory).samples;
  return f;
}

void step_along_trajectory(benchmark::State& state, const std::string& scene) {
  Fixture f = make_fixture(scene, static_cast<double>(state.range(0)) * 1e-6);
  ForceSample out;
  std::size_t k = 0;
  for (auto _ : state) {
    if (k == f.samples.size()) {
      k = 0;
      f.model.model->reset();
    }
    f.model.model->step({&f.samples[k++], 1}, 1e-3, {&out, 1});
    benchmark::DoNotOptimize(out);
  }
  state.counters["tets"] = static_cast<double>(f.mesh.tets.rows());
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_FractureStep_PotatoWedge(benchmark::State& state) { step_along_trajectory(state, "potato_wedge_cut"); }
void BM_FractureStep_PotatoRect(benchmark::State& state) { step_along_trajectory(state, "potato_rect_cut"); }

/// The contact-length query alone, with the edge 6 mm below the wedge's apex.
void BM_ContactLength_PotatoWedge(benchmark::State& state) {
  Fixture f = make_fixture("potato_wedge_cut", static_cast<double>(state.range(0)) * 1e-6);
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
