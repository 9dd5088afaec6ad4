// Paper 000 §3 costs: one DiscreteEdgeCuttingModel::step along the potato scenes' own
// trajectories (approach, cut, hold, retreat: every mode in the mix; the trajectory recording for
// the geometric cut included, the cut itself on its worker thread), and the geometric cut of
// §3.2 — a 6000-tetrahedron cube against an 18-triangle swept surface (paper 000: about 4 s) —
// with the cube refined to show the cost following the cut tetrahedra, not the mesh; a cut that
// ends inside the cube (progressive splitting); and one step of paper 000 §4's edge+springs
// model (edge with a stylus) on clay_form while the stylus pulls the cut piece.
//
//   ./build/experiments/benchmarks/bench_edge

#include "experiments/models/model_catalogue.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"
#include "formats/trajectory/trajectory.hpp"
#include "meshes/box_tet_mesh.hpp"
#include "realtime/edge/geometric_cut.hpp"

#include <benchmark/benchmark.h>

#include <array>

using namespace kerf;

namespace {

void edge_step(benchmark::State& state, const std::string& name) {
  Scene scene = read_scene(std::filesystem::path(KERF_SOURCE_DIR) / "experiments/scenes" / (name + ".toml"));
  const TetMesh mesh = scene_mesh(scene);
  BuiltModel model = make_model("edge", scene, mesh);
  const std::vector<ToolState> samples = sample(scene.tools.front().trajectory).samples;
  ForceSample out;
  std::size_t k = 0;
  for (auto _ : state) {
    if (k == samples.size()) { model.model->reset(); k = 0; }
    model.model->step({&samples[k++], 1}, 1e-3, {&out, 1});
    benchmark::DoNotOptimize(out);
  }
  state.counters["points"] = static_cast<double>(model.parameters["point_count"].get<int>());
}
BENCHMARK_CAPTURE(edge_step, potato_rect_cut, std::string("potato_rect_cut"));
BENCHMARK_CAPTURE(edge_step, potato_wedge_cut, std::string("potato_wedge_cut"));

/// The unit cube in n^3 cells of 6 tetrahedra, positively oriented.
TetMesh cube(int n) {
  TetMesh m = box_tet_mesh({0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, n, n, n);
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t) {
    auto p = [&](int k) { return Eigen::Vector3d(m.nodes.row(m.tets(t, k))); };
    if (signed_volume(p(0), p(1), p(2), p(3)) < 0.0) std::swap(m.tets(t, 2), m.tets(t, 3));
  }
  return m;
}

/// Times `original.cut(surface)` on a fresh copy of the body each iteration (the copy untimed);
/// returns the last cut's report.
GeometricCutReport time_cuts(benchmark::State& state, const CuttableBody& original, const SweptSurface& surface) {
  GeometricCutReport report;
  for (auto _ : state) {
    state.PauseTiming();
    CuttableBody body = original;
    state.ResumeTiming();
    report = body.cut(surface);
    benchmark::DoNotOptimize(report);
  }
  return report;
}

// Argument: cells per side (10 -> 6000 tetrahedra, paper 000's size; 20 -> 48000).
void geometric_cut(benchmark::State& state) {
  const CuttableBody original(cube(static_cast<int>(state.range(0))));
  const Eigen::Vector3d normal = Eigen::Vector3d(1.0, 0.3, 0.2).normalized();
  const Eigen::Vector3d origin = 0.6 / Eigen::Vector3d(1.0, 0.3, 0.2).norm() * normal;
  const Eigen::Vector3d a = normal.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d b = normal.cross(a);
  std::vector<Eigen::Vector3d> centres;
  for (int k = 0; k < 10; ++k) centres.push_back(origin + (-2.0 + 4.0 * k / 9.0) * b);
  const SweptSurface surface = sweep_edge(centres, a, 4.0); // 18 triangles
  const GeometricCutReport report = time_cuts(state, original, surface);
  state.counters["tets"] = static_cast<double>(original.mesh().tets.rows());
  state.counters["cut_tets"] = report.cut_tets;
  state.counters["fragments"] = report.fragments;
}
BENCHMARK(geometric_cut)->Arg(10)->Arg(20)->Arg(30)->Unit(benchmark::kMillisecond);

// The 6000-tet cube cut by the plane x = 0.55 from its top down to z = 0.4 only (a slit).
void geometric_cut_partial(benchmark::State& state) {
  const CuttableBody original(cube(10));
  std::vector<Eigen::Vector3d> centres;
  for (int k = 0; k < 10; ++k) centres.push_back(Eigen::Vector3d(0.55, 0.5, 0.4 + 1.6 * k / 9.0));
  const SweptSurface surface = sweep_edge(centres, Eigen::Vector3d::UnitY(), 4.0);
  const GeometricCutReport report = time_cuts(state, original, surface);
  state.counters["cut_tets"] = report.cut_tets;
  state.counters["fragments"] = report.fragments;
}
BENCHMARK(geometric_cut_partial)->Unit(benchmark::kMillisecond);

// clay_form: the blade's cut and the stylus's wait are stepped before timing; then the stylus's
// pull and hold are stepped forth and back (the spring network on the cut piece, explicit).
void shape_forming_step(benchmark::State& state) {
  Scene scene = read_scene(std::filesystem::path(KERF_SOURCE_DIR) / "experiments/scenes/clay_form.toml");
  const TetMesh mesh = scene_mesh(scene);
  BuiltModel model = make_model("edge", scene, mesh);
  const std::vector<ToolState> blade = sample(scene.tools[0].trajectory).samples;
  const std::vector<ToolState> stylus = sample(scene.tools[1].trajectory).samples;
  const std::size_t n = std::min(blade.size(), stylus.size());
  std::size_t pull = 0;
  while (pull < n && stylus[pull].velocity.norm() == 0.0) ++pull;
  std::array<ToolState, 2> tools;
  std::array<ForceSample, 2> out;
  for (std::size_t k = 0; k < pull; ++k) {
    tools = {blade[k], stylus[k]};
    model.model->step(tools, 1e-3, out);
  }
  std::size_t k = pull;
  int direction = 1;
  for (auto _ : state) {
    tools = {blade[k], stylus[k]};
    model.model->step(tools, 1e-3, out);
    benchmark::DoNotOptimize(out);
    if ((direction > 0 && k + 1 == n) || (direction < 0 && k == pull)) direction = -direction;
    k = static_cast<std::size_t>(static_cast<long>(k) + direction);
  }
  state.counters["tets"] = static_cast<double>(mesh.tets.rows());
}
BENCHMARK(shape_forming_step)->Unit(benchmark::kMicrosecond);

} // namespace

BENCHMARK_MAIN();
