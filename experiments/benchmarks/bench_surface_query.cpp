// Cost of the realtime side's surface queries (meshes/surface_mesh.hpp): closest point with
// signed distance, and point-in-volume, on the boundary of potato_rect_cut's mesh refined by the
// benchmark argument (element size in micrometres), for points spread in and around the body.
//
//   ./build/experiments/benchmarks/bench_surface_query

#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"
#include "meshes/surface_mesh.hpp"

#include <benchmark/benchmark.h>

#include <random>

using namespace kerf;

namespace {

struct Fixture {
  SurfaceQuery query;
  std::vector<Eigen::Vector3d> points;
  long triangles = 0;
};

Fixture make_fixture(double element_size) {
  Scene scene = read_scene(std::filesystem::path(KERF_SOURCE_DIR) / "experiments/scenes/potato_rect_cut.toml");
  scene.geometry.element_size = element_size;
  SurfaceMesh surface = boundary_surface(scene_mesh(scene));
  Fixture f;
  f.triangles = surface.triangles.rows();
  f.query = SurfaceQuery(std::move(surface));
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> x(-0.005, 0.045), y(-0.015, 0.015), z(-0.005, 0.020);
  for (int i = 0; i < 4096; ++i) f.points.emplace_back(x(rng), y(rng), z(rng));
  return f;
}

void BM_SurfaceClosestPoint(benchmark::State& state) {
  const Fixture f = make_fixture(static_cast<double>(state.range(0)) * 1e-6);
  std::size_t k = 0;
  for (auto _ : state) benchmark::DoNotOptimize(f.query.closest_point(f.points[k++ & 4095]));
  state.counters["triangles"] = static_cast<double>(f.triangles);
}

void BM_SurfaceContains(benchmark::State& state) {
  const Fixture f = make_fixture(static_cast<double>(state.range(0)) * 1e-6);
  std::size_t k = 0;
  for (auto _ : state) benchmark::DoNotOptimize(f.query.contains(f.points[k++ & 4095]));
  state.counters["triangles"] = static_cast<double>(f.triangles);
}

} // namespace

BENCHMARK(BM_SurfaceClosestPoint)->Arg(2000)->Arg(1000)->Arg(500)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SurfaceContains)->Arg(2000)->Arg(1000)->Arg(500)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
